#include "problems/contact_bar/solver/tdbem.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iterator>
#include <limits>

#include "core/errors.hpp"

namespace backbone::contact_bar {

using core::InputError;

const char* to_string(ContactMethod m) {
  return m == ContactMethod::projection ? "projection" : "event";
}

ContactMethod parse_contact_method(const std::string& key, const std::string& value) {
  if (value == "projection") return ContactMethod::projection;
  if (value == "event") return ContactMethod::event;
  throw InputError(key, fmt::format("must be one of projection, event (got '{}')", value));
}

namespace {

// F(t, a) = int_0^t min(c s, a) ds and its partial derivatives in t and a.
double body_integral(double c, double t, double a) {
  return c * t <= a ? 0.5 * c * t * t : a * t - 0.5 * a * a / c;
}
double body_rate(double c, double t, double a) {
  return std::min(c * t, a);
}
double body_slope(double c, double t, double a) {
  return c * t <= a ? 0.0 : t - a / c;
}

// A contact instant (closing, release) closer than this to a sub-step end (in steps) is put
// there (solve_open says how, without changing the energy), and a step that would end this
// short of a grid point runs on to it: no sliver sub-steps, whose force and velocity would be
// round-off over a round-off.
constexpr double root_snap_steps = 1e-9;

}  // namespace

TdbemMarch::GridTime TdbemMarch::normalized(std::int64_t step, double frac) {
  GridTime t;
  if (frac >= 0 && frac < 0x1p52) {
    // The general branch below without library calls (every retarded time and sub-step comes
    // here): truncation is the floor, frac - whole is exact, and a half rounds up as in
    // llround.
    const auto whole = static_cast<std::int64_t>(frac);
    const double ticks = (frac - static_cast<double>(whole)) * static_cast<double>(ticks_per_step);
    const auto tick = static_cast<std::int64_t>(ticks);
    t = {step + whole, ticks - static_cast<double>(tick) >= 0.5 ? tick + 1 : tick};
  } else {
    const double whole = std::floor(frac);
    t = {step + static_cast<std::int64_t>(whole),
         std::llround((frac - whole) * static_cast<double>(ticks_per_step))};
  }
  if (t.tick >= ticks_per_step) {  // rounded up to a whole step
    t.tick -= ticks_per_step;
    t.step += 1;
  }
  return t;
}

TdbemMarch::GridTime TdbemMarch::grid_time(double t) const {
  const double steps = t / step_;
  GridTime g = normalized(0, steps);
  // A target on a grid point k dt is known to its round-off only (k dt as a double, then
  // divided by the step): within a few ulps of `steps` it is that point.
  const double snap = 8 * std::numeric_limits<double>::epsilon() * std::max(1.0, steps);
  if (fraction(g) <= snap) {
    g.tick = 0;
  } else if (1 - fraction(g) <= snap) {
    g.step += 1;
    g.tick = 0;
  }
  return g;
}

TdbemMarch::TdbemMarch(const bar::BarSetup& setup, double dt, ContactMethod method)
    : setup_(setup), method_(method), dt_(dt) {
  setup_.validate();
  L_ = setup_.material.length;
  c_ = setup_.material.wave_speed();
  tau_ = L_ / c_;
  ea_ = setup_.material.axial_stiffness();
  body_coef_ = setup_.body_force / setup_.material.density / (2 * c_);
  v0_total_ = setup_.v0.integral(0, L_);
  // v0 = +0 everywhere (a shooting state): every integral of it is +0, so r_end adds +0.
  v0_is_zero_ = std::all_of(setup_.v0.values().begin(), setup_.v0.values().end(),
                            [](double v) { return v == 0 && !std::signbit(v); });
  if (!std::isfinite(dt) || !(dt > 0))
    throw InputError("dt", fmt::format("must be > 0 (got {})", dt));
  if (dt > tau_ * (1 + 1e-12))
    throw InputError("dt", fmt::format("must be <= length / wave_speed = {} (got {}): one step "
                                       "may not cross the bar",
                                       tau_, dt));
  // The grid: tau = m dt + r with the remainder r computed exactly (fma). When r is round-off
  // (dt = L / (m c) as a double), the grid step is tau / m, so that a retarded time or an echo
  // of a grid point is a grid point, exactly, for ever; else the step is dt and tau is carried
  // as m steps plus the fraction r / dt.
  double whole = std::floor(tau_ / dt);
  double rest = std::fma(-whole, dt, tau_);
  if (rest < 0) {
    whole -= 1;
    rest += dt;
  }
  if (std::abs(rest) <= 2 * std::numeric_limits<double>::epsilon() * tau_ ||
      std::abs(rest - dt) <= 2 * std::numeric_limits<double>::epsilon() * tau_) {
    const double m = std::round(tau_ / dt);
    step_ = tau_ / m;
    tau_grid_ = {static_cast<std::int64_t>(m), 0};
  } else {
    step_ = dt;
    tau_grid_ = normalized(static_cast<std::int64_t>(whole), rest / dt);
  }
  // Kinks of R closer than merge_steps_ are one. Echo times are exact (fixed-point fractions),
  // so kinks that coincide in exact arithmetic coincide here up to the round-off of a contact
  // instant they came from (a root of a displacement of size u over a step: eps u / (v dt)
  // steps, u / v ~ L / c). Kinks further apart stay apart: joining two kinks d steps apart
  // loses energy in proportion to d.
  merge_steps_ = 4 * std::numeric_limits<double>::epsilon() * std::max(1.0, tau_ / dt);
  for (const auto* f : {&setup_.u0, &setup_.v0})
    for (double v : f->values())
      gauge_scale_ = std::max(gauge_scale_, std::abs(v) * (f == &setup_.u0 ? 1.0 : tau_));
  gauge_scale_ = std::max({gauge_scale_, setup_.left.gap, setup_.right.gap, setup_.left.gap_back,
                           setup_.right.gap_back, std::abs(body_coef_) * c_ * tau_ * tau_});
  const bar::End* end_of[2] = {&setup_.left, &setup_.right};
  for (int e = 0; e < 2; ++e) {
    EndState& E = ends_[e];
    E.end = *end_of[e];
    E.normal = e == 0 ? -1.0 : 1.0;
    E.wall = E.end.has_wall() ? E.normal * E.end.gap : 0.0;
    E.has_back = E.end.has_back_wall();
    E.wall_back = E.has_back ? -E.normal * E.end.gap_back : 0.0;
    const double u = setup_.u0(e == 0 ? 0.0 : L_);
    if (E.end.type == bar::EndType::fixed && u != 0)
      throw InputError("u0", fmt::format("u0 must vanish at the fixed end x = {} (got {})",
                                         e == 0 ? 0.0 : L_, u));
    // The window holds about tau / dt knots plus the sub-step instants (kinks, contact events).
    E.knots.reserve(static_cast<std::size_t>(2 * tau_grid_.step) + setup_.u0.knots().size() +
                    setup_.v0.knots().size() + 64);
    E.knots.push_back({GridTime{}, u, 0.0, 0.5 * u, 0.0, false});
    E.closed = E.end.has_wall() && E.normal * (u - E.wall) >= 0;
    if (!E.closed && E.has_back && -E.normal * (u - E.wall_back) >= 0) {
      E.closed = true;
      E.side = -1;
    }
    if (E.closed) {
      // A state that starts on a wall (a subharmonic member at the centre of a contact
      // phase): the force at t = 0 is the initial strain, -EA n u0_x at the end, compressive on
      // the front wall and tensile on the back one.
      const double inward_slope = e == 0 ? setup_.u0.slope(0.0, +1) : setup_.u0.slope(L_, -1);
      E.force = E.side * std::max(0.0, -E.side * ea_ * E.normal * inward_slope);
    }
    E.contact_u = E.wall_at(E.side);
    if (method_ == ContactMethod::event) {
      // Kinks of R_e inside (0, tau]: data knots reaching the end, and the end of the IC term.
      // Each function's arrival times increase along its knots (from x = 0 for end 0, from
      // x = L for end 1) and grid_time is monotone: two sorted runs, merged, and tau put in its
      // place give the sorted list without a sort.
      std::vector<GridTime> runs[2];
      for (int j = 0; j < 2; ++j) {
        const std::vector<double>& knots = (j == 0 ? setup_.u0 : setup_.v0).knots();
        for (std::size_t i = 0; i < knots.size(); ++i) {
          const double x = e == 0 ? knots[i] : knots[knots.size() - 1 - i];
          const double time = (e == 0 ? x : L_ - x) / c_;
          if (time > 0 && time < tau_) runs[j].push_back(grid_time(time));
        }
      }
      std::vector<GridTime> times(runs[0].size() + runs[1].size() + 1);
      const auto merged_end =
          std::merge(runs[0].begin(), runs[0].end(), runs[1].begin(), runs[1].end(), times.begin());
      *merged_end = tau_grid_;
      std::inplace_merge(times.begin(), merged_end, times.end());
      times.erase(std::unique(times.begin(), times.end()), times.end());
      E.pending.assign(times.begin(), times.end());
    }
  }
}

double TdbemMarch::q_at(int e, GridTime s, std::size_t* hint) const {
  const auto& k = ends_[e].knots;
  const std::size_t i = knot_index(e, s, hint);
  if (i == k.size()) return k.back().q;
  if (i == 0 || k[i].t == s) return k[i].q;  // on a knot (every grid query when tau = m dt)
  const Knot& prev = k[i - 1];
  const Knot& next = k[i];
  const double w = steps_between(s, prev.t) / steps_between(next.t, prev.t);
  return prev.q + w * (next.q - prev.q);
}

inline double TdbemMarch::q_slope(int e, GridTime s, std::size_t* hint) const {
  const auto& k = ends_[e].knots;
  if (k.size() < 2) return 0;
  std::size_t i = knot_index(e, s, hint);
  if (i == k.size()) i = k.size() - 1;
  if (i == 0) i = 1;
  return k[i].slope;  // (k[i].q - k[i - 1].q) / seconds_between(k[i].t, k[i - 1].t)
}

double TdbemMarch::r_end(int e, GridTime t) const {
  const GridTime retarded_time = minus(t, tau_grid_);
  double value = 0;
  if (setup_.body_force != 0) value = body_coef_ * body_integral(c_, seconds(t), L_);
  if (retarded_time <= GridTime{}) {
    const double ct = c_ * seconds(t);
    if (e == 1) {
      value += 0.5 * setup_.u0(std::max(L_ - ct, 0.0));
      value += v0_is_zero_ ? 0.0 : setup_.v0.integral(std::max(L_ - ct, 0.0), L_) / (2 * c_);
    } else {
      value += 0.5 * setup_.u0(std::min(ct, L_));
      value += v0_is_zero_ ? 0.0 : setup_.v0.integral(0.0, std::min(ct, L_)) / (2 * c_);
    }
  } else {
    value += v0_total_ / (2 * c_) + q_at(1 - e, retarded_time, &retarded_hint_[1 - e]);
  }
  return value;
}

void TdbemMarch::push_knot(int e, GridTime t, double u, double s, bool kink) {
  EndState& E = ends_[e];
  const double q = 0.5 * c_ * s + 0.5 * u;
  // A tracked kink whose slope change turns out to vanish (to round-off) is no kink: drop its
  // echo, so that echo trains do not accumulate over long runs (one per contact event). With a
  // tangent every echo stays: a kink of size zero may have a derivative that is not.
  if (method_ == ContactMethod::event && !tangent_ && E.knots.size() >= 2 && E.knots.back().kink) {
    Knot& k1 = E.knots.back();
    const Knot& k0 = E.knots[E.knots.size() - 2];
    const double before = (k1.q - k0.q) / steps_between(k1.t, k0.t);
    const double after = (q - k1.q) / steps_between(t, k1.t);
    if (std::abs(after - before) <= 1e-11 * std::max(std::abs(before), std::abs(after))) {
      k1.kink = false;
      auto& pending = ends_[1 - e].pending;
      const GridTime echo = plus(k1.t, tau_grid_);
      // std::lower_bound, searched from the back: the echo was scheduled a step or so ago, as
      // the latest pending time or near it.
      const GridTime from = later(echo, -merge_steps_);
      const GridTime* it = pending.end();
      while (it != pending.begin() && !(*(it - 1) < from)) --it;
      if (it != pending.end() && std::abs(steps_between(*it, echo)) <= merge_steps_)
        pending.erase(it);
    }
  }
  const Knot& last = E.knots.back();
  const double slope = (q - last.q) / seconds_between(t, last.t);
  E.knots.push_back({t, u, s, q, slope, false});
  if (tangent_) {
    KnotTangent& next = tangent_->next;
    next.dq = 0.5 * c_ * next.ds + 0.5 * next.du;
    next.moving = (next.dt.array() != 0).any();
    E.tangents.push_back(std::move(next));
  }
  if (!std::isfinite(u) || !std::isfinite(s)) ok_ = false;
  if (kink) mark_kink(e);
}

void TdbemMarch::mark_kink(int e) {
  if (method_ != ContactMethod::event) return;
  Knot& k = ends_[e].knots.back();
  if (k.kink) return;
  k.kink = true;
  // The echo of this kink reaches the other end tau later.
  EndState& other = ends_[1 - e];
  const GridTime echo = plus(k.t, tau_grid_);
  const double ahead = steps_between(echo, other.knots.back().t);
  if (ahead <= merge_steps_) {
    if (ahead >= -merge_steps_) mark_kink(1 - e);
    return;
  }
  // std::upper_bound, searched from the back: an echo is tau after now, mostly the latest.
  const GridTime* at = other.pending.end();
  while (at != other.pending.begin() && echo < *(at - 1)) --at;
  other.pending.insert(at, echo);
}

void TdbemMarch::step_end(int e, GridTime ta, GridTime tb) {
  EndState& E = ends_[e];
  if (method_ == ContactMethod::projection) {
    const double h = seconds_between(tb, ta);
    const Knot a = E.knots.back();
    const double r = r_end(e, tb);
    switch (E.end.type) {
      case bar::EndType::fixed: {
        const double s = -2 * r / c_;
        E.force = -ea_ * E.normal * (s - a.s) / h;
        push_knot(e, tb, 0.0, s, false);
        break;
      }
      case bar::EndType::free:
        E.force = 0;
        push_knot(e, tb, 2 * r + c_ * a.s, a.s, false);
        break;
      case bar::EndType::contact:
      case bar::EndType::clearance: {
        const double u_free = 2 * r + c_ * a.s;
        // On a wall counts as closed, as at t = 0 (the grid reproduces mode 1's onset 1.1
        // exactly: u_free(1.1) is the wall to the last bit).
        int side = E.normal * (u_free - E.wall) >= 0 ? 1 : 0;
        if (side == 0 && E.has_back && -E.normal * (u_free - E.wall_back) >= 0) side = -1;
        const bool closed = side != 0;
        if (E.closed && (!closed || side != E.side))
          events_.push_back({seconds(ta), e == 1, false, E.side < 0});
        if (closed && (!E.closed || side != E.side))
          events_.push_back({seconds(tb), e == 1, true, side < 0});
        E.closed = closed;
        if (closed) {
          E.side = side;
          const double wall = E.wall_at(side);
          // Signed: compressive on the front wall, tensile on the back one.
          E.force = ea_ * E.normal * (u_free - wall) / (c_ * h);
          push_knot(e, tb, wall, (wall - 2 * r) / c_, false);
        } else {
          E.force = 0;
          push_knot(e, tb, u_free, a.s, false);
        }
        break;
      }
    }
    return;
  }
  // Event method: split the step at the kinks of R_e that fall inside it.
  std::vector<GridTime>& cuts = cuts_;
  cuts.clear();
  bool kink_at_end = false;
  GridTime end_kink = tb;  // the kink arriving at tb
  while (!E.pending.empty() && steps_between(E.pending.front(), tb) <= merge_steps_) {
    const GridTime p = E.pending.front();
    E.pending.pop_front();
    if (steps_between(p, ta) <= merge_steps_) {
      // A kink a round-off after ta (the previous step ended a round-off short of it) is the
      // knot at ta: it stays tracked, so its echo train goes on and no later step interpolates
      // across it (which would lose energy).
      mark_kink(e);
      if (tangent_ && !E.tangents.back().moving) retag_last(e, arrival_dt(e, p));
      continue;
    }
    if (steps_between(tb, p) <= merge_steps_) {
      if (!kink_at_end) end_kink = p;
      kink_at_end = true;
      continue;
    }
    if (cuts.empty() || steps_between(p, cuts.back()) > merge_steps_) cuts.push_back(p);
  }
  GridTime a = ta;
  for (const GridTime& cut : cuts) {
    if (tangent_) tangent_->end_dt = arrival_dt(e, cut);
    substep_event(e, a, cut, true);
    a = cut;
  }
  if (tangent_) tangent_->end_dt = kink_at_end ? arrival_dt(e, end_kink) : tangent_->zero;
  substep_event(e, a, tb, kink_at_end);
}

void TdbemMarch::substep_event(int e, GridTime ta, GridTime tb, bool kink_at_end) {
  EndState& E = ends_[e];
  const Knot a = E.knots.back();
  switch (E.end.type) {
    case bar::EndType::fixed: {
      const double s = -2 * r_end(e, tb) / c_;
      E.force = -ea_ * E.normal * (s - a.s) / seconds_between(tb, ta);
      if (tangent_) set_next_tangent_holding(e, tb);
      push_knot(e, tb, 0.0, s, kink_at_end);
      return;
    }
    case bar::EndType::free:
      E.force = 0;
      if (tangent_) {
        const Eigen::VectorXd ds = E.tangents.back().ds;
        set_next_tangent(tangent_->end_dt, 2 * r_tangent(e, tb, tangent_->end_dt) + c_ * ds, ds);
      }
      push_knot(e, tb, 2 * r_end(e, tb) + c_ * a.s, a.s, kink_at_end);
      return;
    case bar::EndType::contact:
    case bar::EndType::clearance:
      if (E.closed) {
        solve_closed_to(e, ta, tb, kink_at_end);
      } else {
        solve_open(e, ta, tb, kink_at_end);
      }
      return;
  }
}

// Open end over [ta, tb] (no kink of R inside): free motion unless the free displacement
// crosses a wall, in which case the step is split at the crossing. Local times in steps.
// A clearance end's two walls are gap + gap_back apart, so one sub-step of free motion (linear
// in t, quadratic with a body force) ends beyond at most one of them: the one it crossed.
void TdbemMarch::solve_open(int e, GridTime ta, GridTime tb, bool kink_at_end) {
  EndState& E = ends_[e];
  const Knot a = E.knots.back();
  const double h = steps_between(tb, ta);
  const double r_b = r_end(e, tb);  // R_e(tb), used below (a pure function of the history)
  const double u_b = 2 * r_b + c_ * a.s;
  // The tangent: knot a's, and u_b's at tb moving with end_dt.
  KnotTangent ga;
  Eigen::VectorXd du_b;
  if (tangent_) {
    ga = E.tangents.back();
    du_b = 2 * r_tangent(e, tb, tangent_->end_dt) + c_ * ga.ds;
  }
  // n: the outward normal of the wall in question (the end's for the front wall, its opposite
  // for the back one), so that a violation n (u - wall) > 0 is a penetration of either.
  double n = E.normal, wall = E.wall;
  if (E.has_back && !(n * (u_b - wall) > 0) && -n * (u_b - E.wall_back) > 0) {
    n = -n;
    wall = E.wall_back;
  }
  auto gap_violation = [&](GridTime t) { return n * (2 * r_end(e, t) + c_ * a.s - wall); };
  const double pb = n * (u_b - wall);
  // The free displacement at the wall at tb, a kink of R: a grazing (of one sign it touches).
  if (tangent_ && kink_at_end && std::abs(pb) <= kink_margin()) tangent_->on_kink = true;
  if (!(pb > 0)) {
    E.force = 0;
    if (tangent_) set_next_tangent(tangent_->end_dt, du_b, ga.ds);
    push_knot(e, tb, u_b, a.s, kink_at_end);
    return;
  }
  E.side = n == E.normal ? 1 : -1;
  const bool back = E.side < 0;
  // Crossing: the free displacement is linear in t (quadratic with a body force).
  const double pa = std::min(n * (a.u - wall), 0.0);
  const double pm = gap_violation(later(ta, 0.5 * h));
  const double alpha = (4 * pm - 3 * pa - pb) / h;
  const double beta = 2 * (pa - 2 * pm + pb) / (h * h);
  double root = h * (-pa) / (pb - pa);
  if (std::abs(beta) * h * h > 1e-10 * (std::abs(pa) + std::abs(pb))) {
    for (int it = 0; it < 20; ++it) {
      const double p = pa + root * (alpha + beta * root);
      const double dp = alpha + 2 * beta * root;
      if (!(dp > 0)) break;
      const double next = std::clamp(root - p / dp, 0.0, h);
      if (next == root) break;
      root = next;
    }
  }
  // The closing instant's derivative: the root of the chord from (ta, pa) to (tb, pb), both
  // moving with their knots; the closing knot is on the wall (du = 0) with the open S.
  Eigen::VectorXd dt_close;
  if (tangent_) {
    const double w = std::clamp(root / h, 0.0, 1.0);
    dt_close = (1 - w) * ga.dt + w * tangent_->end_dt -
               seconds_between(tb, ta) / (pb - pa) * n * ((1 - w) * ga.du + w * du_b);
  }
  // A crossing within round-off of ta or tb is put there, and the end is then held where it
  // is (a round-off off the wall): a closed end's outgoing wave is minus its incoming one, an
  // open end's plus, so moving the instant by a round-off leaves every slope of Q, and the
  // energy, exact. Moving the end onto the wall (or joining ta and tb by a chord) would change
  // the energy in proportion to the round-off and shift the next closing by more, an error that
  // grows period after period on mode 1, whose closings all fall on grid points.
  E.closed = true;
  // A closing on a kink of R (a sub-step end that is one) has two one-sided derivatives.
  if (tangent_ &&
      ((root <= root_snap_steps && a.kink) || (h - root <= root_snap_steps && kink_at_end)))
    tangent_->on_kink = true;
  if (root <= root_snap_steps) {  // closed from ta
    E.contact_u = a.u;
    if (tangent_) {
      KnotTangent& last = E.tangents.back();
      last.dt = dt_close;
      last.du.setZero();
      last.dq = 0.5 * c_ * last.ds;
      last.moving = true;
    }
    mark_kink(e);
    events_.push_back({seconds(ta), e == 1, true, back});
    const double s = (E.contact_u - 2 * r_b) / c_;
    E.force = -ea_ * E.normal * (s - a.s) / seconds_between(tb, ta);
    if (tangent_) set_next_tangent_holding(e, tb);
    push_knot(e, tb, E.contact_u, s, kink_at_end);
    return;
  }
  if (h - root <= root_snap_steps) {  // open up to tb, closed from tb
    E.contact_u = u_b;
    E.force = 0;
    events_.push_back({seconds(tb), e == 1, true, back});
    if (tangent_) set_next_tangent(dt_close, tangent_->zero, ga.ds);
    push_knot(e, tb, E.contact_u, a.s, true);
    return;
  }
  const GridTime t_close = later(ta, root);
  E.contact_u = wall;
  if (tangent_) set_next_tangent(dt_close, tangent_->zero, ga.ds);
  push_knot(e, t_close, wall, a.s, true);
  events_.push_back({seconds(t_close), e == 1, true, back});
  solve_closed_to(e, t_close, tb, kink_at_end);
}

// Closed end over [ta, tb]: stays on the wall while the force is compressive; the release
// instant is the sign change of the force (at ta, or inside the sub-step with a body force).
// Local times in steps.
void TdbemMarch::solve_closed_to(int e, GridTime ta, GridTime tb, bool kink_at_end) {
  EndState& E = ends_[e];
  const Knot a = E.knots.back();
  const double h = steps_between(tb, ta);
  const double n = E.side * E.normal;  // the wall's outward normal (solve_open)
  const bool back = E.side < 0;
  auto gap_violation = [&](GridTime t) { return n * (2 * r_end(e, t) + c_ * a.s - E.contact_u); };
  // gap_violation(ta) = 0 on the wall; the force over [ta, t] is EA * violation(t) / (c (t-ta)).
  const double pm = gap_violation(later(ta, 0.5 * h));
  const double r_b = r_end(e, tb);  // R_e(tb), used again by a step closed up to tb
  const double pb = n * (2 * r_b + c_ * a.s - E.contact_u);
  // Held or released by the sign of pb: a pb of round-off is a decision on a kink.
  if (tangent_ && std::abs(pb) <= kink_margin()) tangent_->on_kink = true;
  const double alpha = (4 * pm - pb) / h;  // the force at ta+ is EA alpha / (c step)
  const double beta = 2 * (pb - 2 * pm) / (h * h);
  auto closed_step = [&](GridTime t_end, bool kink) {
    const double s = (E.contact_u - 2 * (t_end == tb ? r_b : r_end(e, t_end))) / c_;
    E.force = -ea_ * E.normal * (s - a.s) / seconds_between(t_end, ta);
    // A release inside the sub-step needs a body force, which the tangent refuses: t_end is tb.
    if (tangent_) set_next_tangent_holding(e, t_end);
    push_knot(e, t_end, E.contact_u, s, kink);
  };
  if (alpha < 0 && pb < 0) {
    events_.push_back({seconds(ta), e == 1, false, back});
    E.closed = false;
    mark_kink(e);
    solve_open(e, ta, tb, kink_at_end);
    return;
  }
  const double force_end_rate = alpha + 2 * beta * h;
  if (alpha >= 0 && force_end_rate < 0 && beta != 0) {
    const double release = -alpha / (2 * beta);
    if (release > root_snap_steps && h - release > root_snap_steps) {
      const GridTime t_release = later(ta, release);
      closed_step(t_release, true);
      events_.push_back({seconds(t_release), e == 1, false, back});
      E.closed = false;
      solve_open(e, t_release, tb, kink_at_end);
      return;
    }
  }
  if (pb < 0) {  // tensile over the whole sub-step: release at ta
    events_.push_back({seconds(ta), e == 1, false, back});
    E.closed = false;
    mark_kink(e);
    solve_open(e, ta, tb, kink_at_end);
    return;
  }
  closed_step(tb, kink_at_end);
}

// Q_0 - C and Q_L + C give the same u (u = ... + Q_L + Q_0) and the same end equations
// (Q_e = U_e - R_e, R_e holding the other end's Q). The fixed end's S grows like its mean
// strain times t, and with it both Q; u is then a difference of two large numbers, which loses
// digits in proportion to t. Moving C = (Q_0 - Q_L) / 2 of the newest knots brings both to the
// size of u again: O(window), once every many steps.
void TdbemMarch::regauge() {
  const double shift = 0.5 * (ends_[0].knots.back().q - ends_[1].knots.back().q);
  ++regauges_;
  if (tangent_) {
    const Eigen::VectorXd d_shift =
        0.5 * (ends_[0].tangents.back().dq - ends_[1].tangents.back().dq);
    for (int e = 0; e < 2; ++e)
      for (KnotTangent& k : ends_[e].tangents) {
        k.dq += e == 0 ? -d_shift : d_shift;
        k.ds += (e == 0 ? -2 / c_ : 2 / c_) * d_shift;
      }
  }
  for (int e = 0; e < 2; ++e) {
    const double dq = e == 0 ? -shift : shift, ds = 2 * dq / c_;
    auto& knots = ends_[e].knots;
    for (Knot& k : knots) {
      k.q += dq;
      k.s += ds;
    }
    for (std::size_t i = 1; i < knots.size(); ++i)
      knots[i].slope = (knots[i].q - knots[i - 1].q) / seconds_between(knots[i].t, knots[i - 1].t);
  }
}

bool TdbemMarch::advance_to(double target) {
  if (!std::isfinite(target)) throw InputError("t", "must be finite");
  if (!(target > t_)) return ok_;
  GridTime goal = grid_time(target);
  // A target between grid points holds the round-off of t (which grows with t): a kink of R
  // within it is the target. Stopping on the kink, rather than moving the kink to the target,
  // keeps it exact, so stops at t = k T on a periodic orbit do not smear its kinks (and the
  // energy) over long runs.
  const double target_round_off =
      8 * std::numeric_limits<double>::epsilon() * std::max(1.0, target / step_);
  while (ok_ && now_ < goal) {
    // The next grid point (the one after, when now_ is a round-off short of a grid point).
    GridTime next{now_.step + (fraction(now_) > 1 - root_snap_steps ? 2 : 1), 0};
    if (!(next < goal)) {
      next = goal;
      if (goal.tick != 0)
        for (const auto& E : ends_)
          for (const GridTime& p : E.pending) {
            if (steps_between(p, goal) > target_round_off) break;
            if (steps_between(goal, p) <= target_round_off && now_ < p) next = goal = p;
          }
    }
    step_end(0, now_, next);
    step_end(1, now_, next);
    now_ = next;
    // Keep exactly the window [t - tau, t] (plus one knot before it).
    const GridTime window_start = minus(now_, tau_grid_);
    for (auto& E : ends_)
      while (E.knots.size() > 2 && E.knots[1].t <= window_start) {
        E.knots.pop_front();
        if (tangent_) E.tangents.pop_front();
      }
    // Once every query is at a positive retarded time (t > tau), keep Q at the size of u.
    if (window_start > GridTime{} && ends_[0].knots.front().t > GridTime{} &&
        ends_[1].knots.front().t > GridTime{} &&
        std::abs(ends_[0].knots.back().q - ends_[1].knots.back().q) > 4 * gauge_scale_)
      regauge();
  }
  t_ = ok_ ? target : seconds(now_);
  return ok_;
}

double TdbemMarch::end_displacement(bool right) const {
  return ends_[right ? 1 : 0].knots.back().u;
}
double TdbemMarch::end_force(bool right) const {
  return ends_[right ? 1 : 0].force;
}
bool TdbemMarch::in_contact(bool right) const {
  return ends_[right ? 1 : 0].closed;
}
std::size_t TdbemMarch::stored_knots() const {
  return ends_[0].knots.size() + ends_[1].knots.size();
}

double TdbemMarch::displacement(double x) const {
  const GridTime s0 = retarded(x / c_), sL = retarded((L_ - x) / c_);
  const double t = seconds(now_), lo = x - c_ * t, hi = x + c_ * t;
  double value = body_coef_ * (body_integral(c_, t, x) + body_integral(c_, t, L_ - x));
  value += sL <= GridTime{} ? 0.5 * setup_.u0(std::min(hi, L_)) : q_at(1, sL);
  value += s0 <= GridTime{} ? 0.5 * setup_.u0(std::max(lo, 0.0)) : q_at(0, s0);
  value += setup_.v0.integral(std::max(lo, 0.0), std::min(hi, L_)) / (2 * c_);
  return value;
}

double TdbemMarch::velocity(double x) const {
  return velocity(x, nullptr);
}

double TdbemMarch::velocity(double x, std::size_t* hints) const {
  const GridTime s0 = retarded(x / c_), sL = retarded((L_ - x) / c_);
  const double t = seconds(now_), lo = x - c_ * t, hi = x + c_ * t;
  double value = body_coef_ * (body_rate(c_, t, x) + body_rate(c_, t, L_ - x));
  value += sL <= GridTime{} ? 0.5 * c_ * setup_.u0.slope(hi, -1) + 0.5 * setup_.v0(hi)
                            : q_slope(1, sL, hints ? &hints[1] : nullptr);
  value += s0 <= GridTime{} ? -0.5 * c_ * setup_.u0.slope(lo, +1) + 0.5 * setup_.v0(lo)
                            : q_slope(0, s0, hints ? &hints[0] : nullptr);
  return value;
}

// velocity(x, hints) and strain(x, hints) in one pass: the same expressions, one knot search
// per end instead of two.
void TdbemMarch::velocity_and_strain(double x, std::size_t* hints, double& v, double& ux) const {
  const GridTime s0 = retarded(x / c_), sL = retarded((L_ - x) / c_);
  const double t = seconds(now_), lo = x - c_ * t, hi = x + c_ * t;
  v = body_coef_ * (body_rate(c_, t, x) + body_rate(c_, t, L_ - x));
  ux = body_coef_ * (body_slope(c_, t, x) - body_slope(c_, t, L_ - x));
  if (sL <= GridTime{}) {
    const double us = setup_.u0.slope(hi, -1), vs = setup_.v0(hi);
    v += 0.5 * c_ * us + 0.5 * vs;
    ux += 0.5 * us + vs / (2 * c_);
  } else {
    const double q = q_slope(1, sL, &hints[1]);
    v += q;
    ux += q / c_;
  }
  if (s0 <= GridTime{}) {
    const double us = setup_.u0.slope(lo, +1), vs = setup_.v0(lo);
    v += -0.5 * c_ * us + 0.5 * vs;
    ux += 0.5 * us - vs / (2 * c_);
  } else {
    const double q = q_slope(0, s0, &hints[0]);
    v += q;
    ux += -q / c_;
  }
}

double TdbemMarch::strain(double x) const {
  return strain(x, nullptr);
}

double TdbemMarch::strain(double x, std::size_t* hints) const {
  const GridTime s0 = retarded(x / c_), sL = retarded((L_ - x) / c_);
  const double t = seconds(now_), lo = x - c_ * t, hi = x + c_ * t;
  double value = body_coef_ * (body_slope(c_, t, x) - body_slope(c_, t, L_ - x));
  value += sL <= GridTime{} ? 0.5 * setup_.u0.slope(hi, -1) + setup_.v0(hi) / (2 * c_)
                            : q_slope(1, sL, hints ? &hints[1] : nullptr) / c_;
  value += s0 <= GridTime{} ? 0.5 * setup_.u0.slope(lo, +1) - setup_.v0(lo) / (2 * c_)
                            : -q_slope(0, s0, hints ? &hints[0] : nullptr) / c_;
  return value;
}

// Every x where the field (a quadratic in x at most) changes form at the current time. The
// knots of each end arrive in monotone order (end 0 from x = 0, end 1 from x = L), so the two
// window sequences are merged with the few other points rather than sorted (O(window)).
std::vector<double> TdbemMarch::breakpoints(int elements) const {
  std::vector<double> nodes;
  for (int i = 0; i <= elements; ++i) nodes.push_back(L_ * i / elements);
  return breakpoints(nodes);
}

std::vector<double> TdbemMarch::breakpoints(const std::vector<double>& nodes) const {
  const auto inside = [&](double p) { return p >= 0 && p <= L_; };
  std::vector<double> other(nodes);
  const double ct = c_ * seconds(now_);
  for (const auto* f : {&setup_.u0, &setup_.v0})
    for (double k : f->knots()) {
      if (inside(k - ct)) other.push_back(k - ct);
      if (inside(k + ct)) other.push_back(k + ct);
    }
  if (inside(ct)) other.push_back(ct);
  if (inside(L_ - ct)) other.push_back(L_ - ct);
  std::sort(other.begin(), other.end());
  std::vector<double> from0, from1;  // both increasing in x
  from0.reserve(ends_[0].knots.size());
  from1.reserve(ends_[1].knots.size());
  for (auto k = std::make_reverse_iterator(ends_[0].knots.end());
       k != std::make_reverse_iterator(ends_[0].knots.begin()); ++k)
    if (const double p = c_ * seconds_between(now_, k->t); inside(p)) from0.push_back(p);
  for (const auto& k : ends_[1].knots)
    if (const double p = L_ - c_ * seconds_between(now_, k.t); inside(p)) from1.push_back(p);
  std::vector<double> ends(from0.size() + from1.size());
  std::merge(from0.begin(), from0.end(), from1.begin(), from1.end(), ends.begin());
  std::vector<double> pts(ends.size() + other.size());
  std::merge(ends.begin(), ends.end(), other.begin(), other.end(), pts.begin());
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  return pts;
}

// Calls f(x, weight, element) at the two Gauss points of every piece: exact for cubics in x.
template <class F>
void TdbemMarch::integrate_pieces(int elements, F&& f) const {
  const std::vector<double> pts = breakpoints(elements);
  const double dx = L_ / elements;
  const double g = 0.5 / std::sqrt(3.0);
  for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
    const double a = pts[i], b = pts[i + 1], h = b - a;
    if (!(h > 1e-15 * L_)) continue;
    const double mid = 0.5 * (a + b);
    const int j = std::clamp(static_cast<int>(std::floor(mid / dx)), 0, elements - 1);
    f(mid - g * h, 0.5 * h, j);
    f(mid + g * h, 0.5 * h, j);
  }
}

std::vector<double> TdbemMarch::project(int elements, bool use_velocity) const {
  std::vector<double> result(static_cast<std::size_t>(elements) + 1, 0.0);
  const double dx = L_ / elements;
  // The pieces come in increasing x: the retarded times t - x/c and t - (L - x)/c are monotone,
  // so each end's knot search walks on from the previous one.
  std::size_t hints[2] = {ends_[0].knots.size(), 0};
  integrate_pieces(elements, [&](double x, double w, int j) {
    const double value = use_velocity ? velocity(x, hints) : displacement(x);
    const double theta = (x - j * dx) / dx;
    result[j] += w * value * (1 - theta);
    result[j + 1] += w * value * theta;
  });
  return result;
}

std::vector<double> TdbemMarch::projected_velocity(const std::vector<double>& nodes) const {
  std::vector<double> result(nodes.size(), 0.0);
  const std::vector<double> pts = breakpoints(nodes);
  const double g = 0.5 / std::sqrt(3.0);
  const auto last = nodes.size() - 1;
  std::size_t hints[2] = {ends_[0].knots.size(), 0};  // pieces come in increasing x
  std::size_t k = 0;  // the element [nodes[k], nodes[k + 1]] holding the piece
  for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
    const double a = pts[i], b = pts[i + 1], h = b - a;
    if (!(h > 1e-15 * L_)) continue;
    const double mid = 0.5 * (a + b);
    while (k + 1 < last && mid >= nodes[k + 1]) ++k;
    const double width = nodes[k + 1] - nodes[k];
    for (double x : {mid - g * h, mid + g * h}) {
      const double value = 0.5 * h * velocity(x, hints);
      const double theta = (x - nodes[k]) / width;
      result[k] += value * (1 - theta);
      result[k + 1] += value * theta;
    }
  }
  return result;
}

std::vector<double> TdbemMarch::projected_displacement(int elements) const {
  return project(elements, false);
}
std::vector<double> TdbemMarch::projected_velocity(int elements) const {
  return project(elements, true);
}

double TdbemMarch::energy() const {
  const auto& m = setup_.material;
  if (setup_.body_force == 0 && now_ > tau_grid_) return window_energy();
  double total = 0;
  std::size_t hints[2] = {ends_[0].knots.size(), 0};  // pieces come in increasing x
  integrate_pieces(1, [&](double x, double w, int) {
    double v, ux;
    velocity_and_strain(x, hints, v, ux);
    total += w * (0.5 * m.density * m.area * v * v + 0.5 * ea_ * ux * ux);
    if (setup_.body_force != 0) total -= w * setup_.body_force * m.area * displacement(x);
  });
  return total;
}

// Without a body force and once t > tau (no initial-data term left), v = Q_L' + Q_0' and
// u_x = (Q_L' - Q_0') / c are constant between the x where a knot of either end's window
// arrives: x = c (t - t_k) from x = 0, x = L - c (t - t_k) from x = L, each monotone in the knot
// index. One merge of the two sequences gives every piece in order, each with its two slopes:
// O(window) per call, no sort and no search. The value is the general path's (same pieces,
// same slopes; a constant integrand, so Gauss points add nothing) up to summation order.
double TdbemMarch::window_energy() const {
  const auto& m = setup_.material;
  const auto& k0 = ends_[0].knots;
  const auto& k1 = ends_[1].knots;
  // (b.q - a.q) / seconds_between(b.t, a.t), b the knot after a.
  const auto slope = [](const Knot&, const Knot& b) { return b.slope; };
  const double inf = std::numeric_limits<double>::infinity();
  // End 0, interval (knot j - 1, knot j) covers x in [c (t - t_j), c (t - t_{j-1})]: walking up
  // in x walks j down from the newest knot. End 1, interval (j - 1, j) covers [L - c (t -
  // t_{j-1}), L - c (t - t_j)]: j walks up from the oldest. The oldest interval of end 0 and the
  // newest of end 1 extend to the far end (the window holds a knot at or before t - tau; beyond
  // it the slope is that of the last interval).
  auto hi0 = std::prev(k0.end()), hi1 = std::next(k1.begin());  // knot j of each end
  const auto lowest0 = std::next(k0.begin()), highest1 = std::prev(k1.end());
  const auto end0_upper = [&] {
    return hi0 != lowest0 ? c_ * seconds_between(now_, std::prev(hi0)->t) : inf;
  };
  const auto end1_upper = [&] {
    return hi1 != highest1 ? L_ - c_ * seconds_between(now_, hi1->t) : inf;
  };
  while (end0_upper() <= 0) --hi0;
  while (end1_upper() <= 0) ++hi1;
  const double half_rho_a = 0.5 * m.density * m.area, half_ea_c2 = 0.5 * ea_ / (c_ * c_);
  // Neumaier's compensated sum: the pieces are many (2 tau / dt) and all positive.
  double total = 0, compensation = 0, x = 0;
  double upper0 = end0_upper(), upper1 = end1_upper();
  double a = slope(*std::prev(hi0), *hi0), b = slope(*std::prev(hi1), *hi1);
  while (x < L_) {  // each pass ends at L or moves an index: at most the window's size passes
    const double next = std::min({upper0, upper1, L_});
    if (next - x > 1e-15 * L_) {
      const double v = a + b, c_ux = b - a;
      const double term = (next - x) * (half_rho_a * v * v + half_ea_c2 * c_ux * c_ux);
      const double sum = total + term;
      compensation += total >= term ? (total - sum) + term : (term - sum) + total;
      total = sum;
    }
    x = next;
    if (upper0 <= next) {
      --hi0;
      upper0 = end0_upper();
      a = slope(*std::prev(hi0), *hi0);
    }
    if (upper1 <= next) {
      ++hi1;
      upper1 = end1_upper();
      b = slope(*std::prev(hi1), *hi1);
    }
  }
  total += compensation;
  return total;
}

bar::History TdbemSolver::simulate(const bar::BarSetup& setup,
                                   const bar::SimulationOptions& options) const {
  options.validate();
  for (double p : options.probes)
    if (p < 0 || p > setup.material.length)
      throw InputError("probes", fmt::format("must lie in [0, length] = [0, {}] (got {})",
                                             setup.material.length, p));
  TdbemMarch march(setup, options.dt, method_);
  const bool right = setup.observed_end_is_right();
  const long steps = std::max(1L, static_cast<long>(std::ceil(options.t_end / options.dt - 1e-9)));
  const long stride = std::max(
      1L, static_cast<long>(std::ceil(static_cast<double>(steps) / (options.history_samples - 1))));
  bar::History h;
  h.probes = options.probes;
  h.probe_u.resize(options.probes.size());
  auto record = [&] {
    h.t.push_back(march.time());
    h.u_contact.push_back(march.end_displacement(right));
    h.contact_force.push_back(march.end_force(right));
    if (options.energy) h.energy.push_back(march.energy());
    for (std::size_t k = 0; k < options.probes.size(); ++k)
      h.probe_u[k].push_back(march.displacement(options.probes[k]));
  };
  record();
  for (long k = stride;; k += stride) {
    const double t = k >= steps ? options.t_end : std::min(k * options.dt, options.t_end);
    if (!march.advance_to(t)) break;
    record();
    if (k >= steps) break;
  }
  return h;
}

bar::FieldSnapshot TdbemSolver::snapshot(const bar::BarSetup& setup, double t,
                                         const bar::SnapshotRequest& request) const {
  if (!std::isfinite(t) || t < 0) throw InputError("t", fmt::format("must be >= 0 (got {})", t));
  if (request.elements < 1)
    throw InputError("elements", fmt::format("must be >= 1 (got {})", request.elements));
  TdbemMarch march(setup, request.dt, method_);
  bar::FieldSnapshot s;
  s.t = t;
  const int n = request.elements;
  if (request.nodes.empty())
    for (int i = 0; i <= n; ++i) s.x.push_back(setup.material.length * i / n);
  else
    s.x = request.nodes;
  if (!march.advance_to(t)) {
    s.ok = false;
    s.message = fmt::format("tdbem: non-finite end values before t = {}", t);
    return s;
  }
  if (request.nodal_u)
    for (double x : s.x) s.u.push_back(march.displacement(x));
  if (request.nodal_v)
    for (double x : s.x) s.v.push_back(march.velocity(x));
  if (request.projected_u) {
    if (!request.nodes.empty())
      throw InputError("nodes", "tdbem: projected_u on another node grid is not built");
    s.u_projected = march.projected_displacement(n);
  }
  if (request.projected_v)
    s.v_projected =
        request.nodes.empty() ? march.projected_velocity(n) : march.projected_velocity(s.x);
  for (const auto* field : {&s.u, &s.v, &s.u_projected, &s.v_projected})
    for (double value : *field)
      if (!std::isfinite(value)) {
        s.ok = false;
        s.message = "tdbem: non-finite field value";
      }
  return s;
}

}  // namespace backbone::contact_bar
