// The TD-BEM march's tangent (tdbem.hpp, 'Tangent'; solver/README.md, 'Tangent').
//
// Every history knot of an end carries its derivative in the P directions: of its time t_k
// (nonzero for a contact instant and for the echo of a kink, which keeps its source's) and of
// its values U, S, Q taken at that time (the total derivative along the moving knot). Between
// knots Q is the chord, so at a time s of the interval (k, k + 1), w = (s - t_k) / (t_k+1 - t_k):
//   dQ(s) = (1 - w) dq_k + w dq_k+1 - m ((1 - w) dt_k + w dt_k+1) + m ds,   m the chord's slope,
// ds the motion of s itself (an event time) or 0 (a grid time, a readout). Each step of the
// march is linear in R and in the previous knot, so its derivative is the same expression in
// their derivatives; a closing moves as the root of the chord of the free gap, on the wall
// (du = 0) with the open S. The field's readouts differentiate the same formulas as the values,
// and the projection of v adds, for each moving knot, the jump of v across its characteristic
// times that characteristic's motion (Leibniz).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>

#include "core/errors.hpp"
#include "problems/contact_bar/solver/tdbem.hpp"

namespace backbone::contact_bar {

using core::InputError;
using Eigen::VectorXd;

namespace {
// A kink within this many steps of a readout's time is on it: an event time carries the
// round-off of its root (where mode 1's end turns at T, the kink fell 1.1e-11 steps from T at 40
// intervals and 1.6e-9 at 80), and which side of a readout a moving kink falls must not depend
// on that. Differences at the monodromy's step move a contact instant by 1e-3 steps or so.
constexpr double readout_snap_steps = 1e-6;
}  // namespace

bar::BarSetup TdbemMarch::with_node_knots(const bar::BarSetup& setup,
                                          const TangentDirections& directions) {
  std::vector<double> y = directions.nodes;
  const double length = setup.material.length;
  if (y.size() < 2 || y.front() != 0 || std::abs(y.back() - length) > 1e-12 * length)
    throw InputError("tangent", fmt::format("the nodes must run from 0 to the length {} (got {} "
                                            "nodes)",
                                            length, y.size()));
  for (std::size_t i = 1; i < y.size(); ++i)
    if (!(y[i] > y[i - 1])) throw InputError("tangent", "the nodes must increase strictly");
  y.back() = length;
  if (setup.right.type == bar::EndType::fixed)
    throw InputError("tangent", "a fixed end at x = L holds u0(L), the last hat's direction");
  bar::BarSetup out = setup;
  for (bar::PiecewiseLinear* f : {&out.u0, &out.v0}) {
    const std::vector<double>& k = f->knots();
    for (std::size_t i = 1; i < k.size(); ++i)
      if (k[i] == k[i - 1]) throw InputError("tangent", "u0 and v0 must be continuous (no jumps)");
    std::vector<double> x;
    std::merge(k.begin(), k.end(), y.begin(), y.end(), std::back_inserter(x));
    x.erase(std::unique(x.begin(), x.end()), x.end());
    x.back() = length;
    if (x.size() == k.size()) continue;  // the nodes are knots already: the same data
    std::vector<double> values(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) values[i] = (*f)(x[i]);
    *f = bar::PiecewiseLinear(std::move(x), std::move(values));
  }
  return out;
}

TdbemMarch::TdbemMarch(const bar::BarSetup& setup, double dt, ContactMethod method,
                       const TangentDirections& directions)
    : TdbemMarch(with_node_knots(setup, directions), dt, method) {
  if (method != ContactMethod::event)
    throw InputError("tangent",
                     "needs the event method (the projection's closings are not "
                     "instants)");
  if (setup.body_force != 0) throw InputError("tangent", "is built without a body force");
  auto t = std::make_unique<Tangent>();
  t->nodes = directions.nodes;
  t->nodes.back() = L_;
  t->n = static_cast<int>(t->nodes.size()) - 1;
  t->velocity = directions.velocity;
  t->size = t->n * (directions.velocity ? 2 : 1);
  t->zero = VectorXd::Zero(t->size);
  t->end_dt = t->zero;
  tangent_ = std::move(t);
  for (int e = 0; e < 2; ++e) {
    EndState& E = ends_[e];
    KnotTangent first{tangent_->zero, tangent_->zero, tangent_->zero, tangent_->zero, false};
    add_hat_values(first.du, false, e == 0 ? 0.0 : L_, 1.0);
    first.dq = 0.5 * first.du;
    E.tangents.reserve(E.knots.size() + 16);
    E.tangents.push_back(std::move(first));
  }
}

// The hat functions' pieces: element j = [y_j, y_j+1] carries psi_j (1 - theta) and psi_j+1
// theta; psi_0 is no direction.
void TdbemMarch::add_hat_values(VectorXd& d, bool v_block, double x, double coef) const {
  const std::vector<double>& y = tangent_->nodes;
  const int n = tangent_->n, offset = v_block ? n : 0;
  if (!(x >= 0 && x <= L_)) return;
  const auto j = static_cast<int>(std::clamp<std::ptrdiff_t>(
      std::upper_bound(y.begin(), y.end(), x) - y.begin() - 1, 0, n - 1));
  const double theta = (x - y[static_cast<std::size_t>(j)]) /
                       (y[static_cast<std::size_t>(j) + 1] - y[static_cast<std::size_t>(j)]);
  if (j >= 1) d[offset + j - 1] += coef * (1 - theta);
  d[offset + j] += coef * theta;
}

void TdbemMarch::add_hat_slopes(VectorXd& d, bool v_block, double x, int side, double coef) const {
  const std::vector<double>& y = tangent_->nodes;
  const int n = tangent_->n, offset = v_block ? n : 0;
  if ((side < 0 && !(x > 0)) || (side > 0 && !(x < L_)) || x < 0 || x > L_) return;
  // The element on `side` of x: [y_j, y_j+1] with y_j < x <= y_j+1 (left) or y_j <= x < y_j+1.
  const auto it =
      side < 0 ? std::lower_bound(y.begin(), y.end(), x) : std::upper_bound(y.begin(), y.end(), x);
  const auto j = static_cast<int>(std::clamp<std::ptrdiff_t>(it - y.begin() - 1, 0, n - 1));
  const double h = y[static_cast<std::size_t>(j) + 1] - y[static_cast<std::size_t>(j)];
  if (j >= 1) d[offset + j - 1] -= coef / h;
  d[offset + j] += coef / h;
}

void TdbemMarch::add_hat_integrals(VectorXd& d, bool v_block, double a, double b,
                                   double coef) const {
  const std::vector<double>& y = tangent_->nodes;
  const int n = tangent_->n, offset = v_block ? n : 0;
  a = std::max(a, 0.0);
  b = std::min(b, L_);
  if (!(b > a)) return;
  auto j = static_cast<int>(std::clamp<std::ptrdiff_t>(
      std::upper_bound(y.begin(), y.end(), a) - y.begin() - 1, 0, n - 1));
  for (; j < n && y[static_cast<std::size_t>(j)] < b; ++j) {
    const double y0 = y[static_cast<std::size_t>(j)], h = y[static_cast<std::size_t>(j) + 1] - y0;
    const double t0 = (std::max(a, y0) - y0) / h, t1 = (std::min(b, y0 + h) - y0) / h;
    if (!(t1 > t0)) continue;
    // int theta = h (t1^2 - t0^2) / 2, int (1 - theta) = h (t1 - t0) - that.
    const double rising = 0.5 * h * (t1 * t1 - t0 * t0), falling = h * (t1 - t0) - rising;
    if (j >= 1) d[offset + j - 1] += coef * falling;
    d[offset + j] += coef * rising;
  }
}

VectorXd TdbemMarch::q_tangent(int e, GridTime s, const VectorXd* ds) const {
  const auto& k = ends_[e].knots;
  const auto& g = ends_[e].tangents;
  std::size_t i = knot_index(e, s, nullptr);
  // A time this close to a knot is on it: an event's, within merge_steps_ (the march's rule); a
  // readout's (t - x / c, which carries the round-off of x / c) within readout_snap_steps.
  const double snap = ds ? merge_steps_ : readout_snap_steps;
  if (i > 0 && steps_between(s, k[i - 1].t) <= snap) --i;
  // A readout at the end of the history with a kink arriving a round-off later: the mean of the
  // sides adds half the motion of that kink (it would be a knot before s on the other side).
  VectorXd pending = tangent_->zero;
  const auto& next = ends_[e].pending;
  if (!ds && i + 1 >= k.size() && !next.empty() &&
      steps_between(next.front(), s) <= readout_snap_steps) {
    const VectorXd dt = arrival_dt(e, next.front());
    pending = -0.5 * (next_slope(e, next.front()) - k.back().slope) * dt;
  }
  if (i == k.size()) return g.back().dq + pending;  // beyond the last knot Q is held (q_at)
  if (i == 0 || steps_between(k[i].t, s) <= snap) {
    // On a knot: an event time s moves along the left interval (its values are that
    // interval's end); a fixed time (a readout) on a moving knot sits on a kink of the map, and
    // takes the mean of the two sides, as central differences do.
    // Knot 0 may be the window's first, at t - tau: its stored slope is still the interval's
    // before it (0 for the knot at t = 0, which does not move).
    VectorXd d = g[i].dq;
    if (ds) return d + k[i].slope * (*ds - g[i].dt);
    if (!g[i].moving) return d + pending;
    const double after = slope_after(e, i);
    return d - 0.5 * (k[i].slope + after) * g[i].dt + pending;
  }
  const double w = steps_between(s, k[i - 1].t) / steps_between(k[i].t, k[i - 1].t);
  const double m = k[i].slope;
  VectorXd d = (1 - w) * g[i - 1].dq + w * g[i].dq;
  if (g[i - 1].moving || g[i].moving) d -= m * ((1 - w) * g[i - 1].dt + w * g[i].dt);
  if (ds) d += m * *ds;
  return d;
}

double TdbemMarch::slope_after(int e, std::size_t i) const {
  // A sliver interval (a kink a round-off before a step's end) has a slope of round-off over
  // round-off: the one after it stands for it.
  const auto& k = ends_[e].knots;
  std::size_t j = i + 1;
  if (j < k.size() && steps_between(k[j].t, k[i].t) <= readout_snap_steps) ++j;
  return j < k.size() ? k[j].slope : next_slope(e, k[i].t);
}

double TdbemMarch::next_slope(int e, GridTime t) const {
  // Q_e = U_e - R_e: an open end holds S (U = 2 R + c S, Q' = R'), a closed or fixed one U
  // (Q' = -R'). R' is the other end's slope after t - tau, or the data's before tau.
  const EndState& E = ends_[e];
  const GridTime source = minus(t, tau_grid_);
  double rate;
  if (source <= GridTime{}) {
    rate = data_rate(e, t);
  } else {
    const auto& k = ends_[1 - e].knots;
    std::size_t i = knot_index(1 - e, later(source, -merge_steps_), nullptr);
    if (i < k.size() && steps_between(k[i].t, source) <= merge_steps_) ++i;  // after the knot
    rate = k[std::clamp<std::size_t>(i, 1, k.size() - 1)].slope;
  }
  const bool holds_u = E.end.type == bar::EndType::fixed || E.closed;
  return holds_u ? -rate : rate;
}

VectorXd TdbemMarch::q_slope_tangent(int e, GridTime s) const {
  const auto& k = ends_[e].knots;
  const auto& g = ends_[e].tangents;
  if (k.size() < 2) return tangent_->zero;
  std::size_t i = knot_index(e, s, nullptr);
  if (i == k.size()) i = k.size() - 1;
  if (i == 0) i = 1;
  VectorXd d = g[i].dq - g[i - 1].dq;
  if (g[i - 1].moving || g[i].moving) d -= k[i].slope * (g[i].dt - g[i - 1].dt);
  return d / seconds_between(k[i].t, k[i - 1].t);
}

double TdbemMarch::data_point(int e, GridTime t) const {
  const double ct = c_ * seconds(t);
  return e == 1 ? std::max(L_ - ct, 0.0) : std::min(ct, L_);
}

double TdbemMarch::data_rate(int e, GridTime t) const {
  const double x = data_point(e, t);
  return e == 1 ? -0.5 * c_ * setup_.u0.slope(x, -1) + 0.5 * setup_.v0(x)
                : 0.5 * c_ * setup_.u0.slope(x, +1) + 0.5 * setup_.v0(x);
}

VectorXd TdbemMarch::r_tangent(int e, GridTime t, const VectorXd& dt) const {
  VectorXd d = tangent_->zero;
  const GridTime retarded_time = minus(t, tau_grid_);
  const bool v = tangent_->velocity;
  if (retarded_time <= GridTime{}) {
    // R_1 = u0(L - ct) / 2 + int_{L - ct}^L v0 / (2c), R_0 = u0(ct) / 2 + int_0^ct v0 / (2c).
    const double x = data_point(e, t);
    add_hat_values(d, false, x, 0.5);
    if (v) add_hat_integrals(d, true, e == 1 ? x : 0.0, e == 1 ? L_ : x, 0.5 / c_);
    if ((dt.array() != 0).any()) d += data_rate(e, t) * dt;
    return d;
  }
  if (v) add_hat_integrals(d, true, 0.0, L_, 0.5 / c_);
  return d + q_tangent(1 - e, retarded_time, &dt);
}

VectorXd TdbemMarch::arrival_dt(int e, GridTime p) const {
  const GridTime source = minus(p, tau_grid_);
  if (source <= GridTime{}) return tangent_->zero;  // a data knot, or tau itself
  const auto& k = ends_[1 - e].knots;
  const std::size_t i = knot_index(1 - e, later(source, -merge_steps_), nullptr);
  if (i < k.size() && std::abs(steps_between(k[i].t, source)) <= merge_steps_)
    return ends_[1 - e].tangents[i].dt;
  return tangent_->zero;
}

void TdbemMarch::retag_last(int e, const VectorXd& dt) {
  const auto& k = ends_[e].knots;
  KnotTangent& g = ends_[e].tangents.back();
  if (k.size() < 2 || !(dt.array() != 0).any()) return;
  const Knot& b = k[k.size() - 1];
  const Knot& a = k[k.size() - 2];
  const double h = seconds_between(b.t, a.t);
  const VectorXd shift = dt - g.dt;
  g.du += (b.u - a.u) / h * shift;
  g.ds += (b.s - a.s) / h * shift;
  g.dq = 0.5 * c_ * g.ds + 0.5 * g.du;
  g.dt = dt;
  g.moving = true;
}

void TdbemMarch::set_next_tangent(const VectorXd& dt, const VectorXd& du, const VectorXd& ds) {
  tangent_->next.dt = dt;
  tangent_->next.du = du;
  tangent_->next.ds = ds;
}

void TdbemMarch::set_next_tangent_holding(int e, GridTime t) {
  set_next_tangent(tangent_->end_dt, tangent_->zero, -2 / c_ * r_tangent(e, t, tangent_->end_dt));
}

VectorXd TdbemMarch::tangent_displacement(double x) const {
  if (!tangent_) throw InputError("tangent", "this march carries no tangent");
  const GridTime s0 = retarded(x / c_), sL = retarded((L_ - x) / c_);
  const double t = seconds(now_), lo = x - c_ * t, hi = x + c_ * t;
  VectorXd d = tangent_->zero;
  if (sL <= GridTime{})
    add_hat_values(d, false, std::min(hi, L_), 0.5);
  else
    d += q_tangent(1, sL, nullptr);
  if (s0 <= GridTime{})
    add_hat_values(d, false, std::max(lo, 0.0), 0.5);
  else
    d += q_tangent(0, s0, nullptr);
  if (tangent_->velocity) add_hat_integrals(d, true, lo, hi, 0.5 / c_);
  return d;
}

Eigen::MatrixXd TdbemMarch::tangent_projected_velocity(const std::vector<double>& nodes) const {
  if (!tangent_) throw InputError("tangent", "this march carries no tangent");
  const int p = tangent_->size;
  Eigen::MatrixXd result = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(nodes.size()), p);
  const std::vector<double> pts = breakpoints(nodes);
  const double g = 0.5 / std::sqrt(3.0);
  const auto last = nodes.size() - 1;
  const double t = seconds(now_);
  // The hats of `nodes` at x: the element holding x and its two weights.
  const auto add_row = [&](double x, double weight, const VectorXd& d) {
    if (!(x >= 0 && x <= L_)) return;
    const auto k = static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(
        std::upper_bound(nodes.begin(), nodes.end(), x) - nodes.begin() - 1, 0,
        static_cast<std::ptrdiff_t>(last) - 1));
    const double theta = (x - nodes[k]) / (nodes[k + 1] - nodes[k]);
    result.row(static_cast<Eigen::Index>(k)) += weight * (1 - theta) * d.transpose();
    result.row(static_cast<Eigen::Index>(k) + 1) += weight * theta * d.transpose();
  };
  // A knot whose characteristic is within `edge` of an end is at that end (readout_snap_steps):
  // the sliver piece between them is its motion, counted below, not integrated here.
  const double edge = std::max(1e-12 * L_, c_ * readout_snap_steps * step_);
  // v at fixed x, differentiated: the slopes' derivatives, or the data's hats before tau.
  for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
    const double a = pts[i], b = pts[i + 1], h = b - a;
    if (!(h > 1e-15 * L_) || b <= edge || a >= L_ - edge) continue;
    const double mid = 0.5 * (a + b);
    for (double x : {mid - g * h, mid + g * h}) {
      const GridTime s0 = retarded(x / c_), sL = retarded((L_ - x) / c_);
      const double lo = x - c_ * t, hi = x + c_ * t;
      VectorXd d = tangent_->zero;
      if (sL <= GridTime{}) {
        add_hat_slopes(d, false, hi, -1, 0.5 * c_);
        if (tangent_->velocity) add_hat_values(d, true, hi, 0.5);
      } else {
        d += q_slope_tangent(1, sL);
      }
      if (s0 <= GridTime{}) {
        add_hat_slopes(d, false, lo, +1, -0.5 * c_);
        if (tangent_->velocity) add_hat_values(d, true, lo, 0.5);
      } else {
        d += q_slope_tangent(0, s0);
      }
      add_row(x, 0.5 * h, d);
    }
  }
  // A moving knot's characteristic carries a jump of v across x_k: end 0's at c (t - t_k)
  // (v jumps from the later interval's slope to the earlier's as x grows; x_k moves by
  // -c dt_k), end 1's at L - c (t - t_k) (earlier to later; +c dt_k).
  for (int e = 0; e < 2; ++e) {
    const auto& k = ends_[e].knots;
    const auto& tg = ends_[e].tangents;
    // A knot whose characteristic is at an end (now, or tau ago) moves it in or out of the
    // bar: one side's term, taken at half weight (the mean of the sides).
    // Knot 0 may be the one at t - tau exactly (the window keeps it): its stored slope is still
    // the interval's before it.
    for (std::size_t i = 0; i < k.size(); ++i) {
      if (!tg[i].moving) continue;
      const double along = c_ * seconds_between(now_, k[i].t);
      double x = e == 0 ? along : L_ - along;
      if (x < -edge || x > L_ + edge) continue;
      const bool at_end = x <= edge || x >= L_ - edge;
      x = std::clamp(x, 0.0, L_);
      const double later_slope = slope_after(e, i);
      const double earlier_slope = k[i].slope, weight = at_end ? 0.5 : 1.0;
      if (e == 0)
        add_row(x, weight, (later_slope - earlier_slope) * (-c_) * tg[i].dt);
      else
        add_row(x, weight, (earlier_slope - later_slope) * c_ * tg[i].dt);
    }
    // A kink arriving a round-off after now: on the other side it has arrived, its
    // characteristic at this end; half its term.
    const auto& next = ends_[e].pending;
    if (!next.empty() && steps_between(next.front(), now_) <= readout_snap_steps) {
      const VectorXd dt = arrival_dt(e, next.front());
      const double jump = next_slope(e, next.front()) - k.back().slope;  // later - earlier
      if (e == 0)
        add_row(0.0, 0.5, jump * (-c_) * dt);
      else
        add_row(L_, 0.5, -jump * c_ * dt);
    }
  }
  return result;
}

}  // namespace backbone::contact_bar
