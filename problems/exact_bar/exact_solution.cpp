#include "problems/exact_bar/exact_solution.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/errors.hpp"

namespace backbone::exact_bar {

using core::InputError;

namespace {

constexpr double infinity = std::numeric_limits<double>::infinity();
constexpr double epsilon = std::numeric_limits<double>::epsilon();

// A computed event closer than this to a segment boundary is taken to sit on it. Local event
// times carry a few ulps of tau of round-off; without snapping, every periodic event would
// spawn a new ulp-long segment per period and the segment count would grow without bound.
double snap_tolerance(double tau) {
  return 64 * epsilon * tau;
}

// Two values (or slopes) equal to a few ulps: a signal continuous across a breakpoint.
bool same_to_ulps(double a, double b) {
  return std::abs(a - b) <= 8 * epsilon * (std::abs(a) + std::abs(b));
}

// Whether a front between a signal's values (or slopes) a and b carries a jump: a relative jump
// under 1e-12 is none. The knots of a u0 on a grid leave such fronts where the slope does not
// change (the slopes' round-off), and an event on one is no kink of the map: the tangent's error
// in treating it as none is that jump (move_closing_at_a_silent_front).
bool carries_jump(double a, double b) {
  return std::abs(a - b) > 1e-12 * (std::abs(a) + std::abs(b));
}

// Cap on stored segments: a runaway event cascade is reported as a failure, not a hang.
constexpr std::size_t max_segments = 20'000'000;

// Free end at outward distance gap_left >= 0 from its wall, outward velocity q + qm s:
// the first s >= 0 at which it starts to penetrate, +infinity if never. Grazing (touching
// the wall with zero velocity, or an excursion shorter than tol) is not a contact.
double closure_time(double gap_left, double q, double qm, double tol) {
  if (gap_left <= 0) {
    if (q > 0) return (qm < 0 && -q / qm <= tol) ? infinity : 0.0;
    if (q == 0) return qm > 0 ? 0.0 : infinity;
    return qm > 0 ? -2 * q / qm : infinity;  // comes back to the wall and crosses it
  }
  if (qm == 0) return q > 0 ? gap_left / q : infinity;
  // Roots of (qm/2) s^2 + q s - gap_left = 0, computed without cancellation.
  const double disc = q * q + 2 * qm * gap_left;
  if (disc <= 0) return infinity;  // never reaches the wall, or only grazes it
  const double root_q = -0.5 * (q + std::copysign(std::sqrt(disc), q));
  const double r1 = root_q / (0.5 * qm);
  const double r2 = -gap_left / root_q;
  double first = infinity;
  if (r1 > 0) first = r1;
  if (r2 > 0) first = std::min(first, r2);
  return first;
}

// Closed end with outward incoming velocity q + qm s: the first s >= 0 at which the
// contact force EA (q + qm s) / c becomes negative, +infinity if never.
double release_time(double q, double qm) {
  if (q < 0 || (q == 0 && qm < 0)) return 0.0;
  if (qm < 0) return -q / qm;
  return infinity;
}

}  // namespace

ExactBarSolution::ExactBarSolution(const bar::BarSetup& setup, double t_end)
    : ExactBarSolution(setup, t_end, InitialTangent{}) {}

ExactBarSolution::ExactBarSolution(const bar::BarSetup& setup, double t_end, InitialTangent tangent)
    : setup_(setup), t_end_(t_end), seed_(std::move(tangent)) {
  setup_.validate();
  if (!std::isfinite(t_end) || t_end < 0)
    throw InputError("t_end", fmt::format("must be finite and >= 0 (got {})", t_end));
  const std::size_t knots = setup_.u0.knots().size();
  if (!seed_.d_knot.empty() || !seed_.d_value.empty()) {  // a tangent
    for (double v : setup_.v0.values())
      if (v != 0) throw InputError("v0", "the tangent of the exact solution needs v0 = 0");
    if (setup_.body_force != 0)
      throw InputError("body_force", "the tangent of the exact solution needs no body force");
    if (seed_.d_knot.size() != knots || seed_.d_value.size() != knots)
      throw InputError("tangent", fmt::format("needs one derivative per knot of u0 ({})", knots));
    tangent_size_ = static_cast<int>(seed_.d_knot.front().size());
    for (std::size_t i = 0; i < knots; ++i)
      if (seed_.d_knot[i].size() != tangent_size_ || seed_.d_value[i].size() != tangent_size_)
        throw InputError("tangent", "every derivative must have the same size");
  }
  c_ = setup_.material.wave_speed();
  tau_ = setup_.material.length / c_;
  b_ = setup_.body_force / setup_.material.density;
  march();
}

template <class Seg>
const Seg& ExactBarSolution::Chunked<Seg>::locate(long k, double r) const {
  k = std::clamp<long>(k, 0, static_cast<long>(first.size()) - 1);
  const auto begin = segments.begin() + static_cast<std::ptrdiff_t>(first[k]);
  const auto end = segments.begin() + static_cast<std::ptrdiff_t>(end_of(k));
  auto it = std::upper_bound(begin, end, r, [](double x, const Seg& seg) { return x < seg.r0; });
  return it == begin ? *begin : *(it - 1);
}

ExactBarSolution::Local ExactBarSolution::to_local(double t) const {
  double k = std::floor(t / tau_);
  double r = std::fma(-k, tau_, t);
  if (r < 0) {
    k -= 1;
    r = std::fma(-k, tau_, t);
  } else if (r >= tau_) {
    k += 1;
    r = std::max(0.0, std::fma(-k, tau_, t));
  }
  return {static_cast<long>(k), r};
}

double ExactBarSolution::global_time(long k, double r) const {
  return std::fma(static_cast<double>(k), tau_, r);
}

// Characteristics: R+ is carried right, R- left, both gain b per unit time. A(t) is the R+
// reaching x = L at t, B(t) the R- reaching x = 0, so
//   R+(x, t) = A(t + (L - x)/c) - b (L - x)/c,   R-(x, t) = B(t + x/c) - b x/c.
// Window k = [k tau, (k+1) tau): each end reflects its incoming chunk (the two ends are
// independent inside a window) and what it emits at local time r of window k arrives at the
// other end at local time r of window k + 1, increased by b tau. Window 0 comes from the
// initial data.
void ExactBarSolution::march() {
  const double L = setup_.material.length;
  std::vector<double> xs{0.0, L};
  for (const auto* f : {&setup_.u0, &setup_.v0})
    for (double k : f->knots())
      if (k > 0 && k < L) xs.push_back(k);
  std::sort(xs.begin(), xs.end());
  xs.erase(std::unique(xs.begin(), xs.end()), xs.end());

  const auto& u0 = setup_.u0;
  const auto& v0 = setup_.v0;
  a_.first.push_back(0);
  b_sig_.first.push_back(0);
  EndState left_state{false, 1, u0(0.0), 0.0, {}};
  EndState right_state{false, 1, u0(L), 0.0, {}};
  if (initial_) {
    seed_characteristic_state(left_state, right_state);
    march_windows(left_state, right_state);
    return;
  }
  for (std::size_t j = 0; j + 1 < xs.size(); ++j) {  // B on [0, tau): x = c t
    const double xa = xs[j], xb = xs[j + 1], xm = 0.5 * (xa + xb);
    const double t0 = xa / c_, t1 = j + 2 == xs.size() ? tau_ : xb / c_;
    b_sig_.segments.push_back(
        {0, t0, t1, v0(xa) + c_ * u0.slope(xm, 1) + b_ * t0, c_ * v0.slope(xm, 1) + b_});
  }
  for (std::size_t j = xs.size() - 1; j > 0; --j) {  // A on [0, tau): x = L - c t
    const double xa = xs[j - 1], xb = xs[j], xm = 0.5 * (xa + xb);
    const double t0 = (L - xb) / c_, t1 = j == 1 ? tau_ : (L - xa) / c_;
    a_.segments.push_back(
        {0, t0, t1, v0(xb) - c_ * u0.slope(xm, 1) + b_ * t0, -c_ * v0.slope(xm, 1) + b_});
  }

  if (tangent_size_ > 0) {
    seed_initial_signals(xs);
    left_state.du = Eigen::VectorXd(seed_.d_value.front());
    right_state.du = Eigen::VectorXd(seed_.d_value.back());
  }
  march_windows(left_state, right_state);
}

void ExactBarSolution::march_windows(EndState& left_state, EndState& right_state) {
  // Signals must cover [0, t_end + tau] (a profile at t reads them up to t + tau) and the end
  // tracks [0, t_end]; one more window keeps every query strictly inside.
  const long last_window = static_cast<long>(std::ceil(t_end_ / tau_)) + 1;
  if (tangent_size_ > 0) {
    // A segment's tangent holds sparse vectors, which std::vector copies (Eigen's have no move
    // constructor) each time it grows: room for every window's pieces at the first window's
    // count, plus events, avoids that.
    const auto windows = static_cast<std::size_t>(last_window) + 2;
    a_tan_.reserve(windows * (a_tan_.size() + 4));
    b_tan_.reserve(windows * (b_tan_.size() + 4));
  }
  for (long k = 0; k <= last_window; ++k) {
    right_.first.push_back(right_.segments.size());
    b_sig_.first.push_back(b_sig_.segments.size());
    march_end(Side::right, k, right_state);  // A chunk k -> B chunk k + 1
    left_.first.push_back(left_.segments.size());
    a_.first.push_back(a_.segments.size());
    march_end(Side::left, k, left_state);  // B chunk k -> A chunk k + 1
    const Segment& last_a = a_.segments.back();
    const Segment& last_b = b_sig_.segments.back();
    if (!std::isfinite(last_a.at(last_a.r1)) || !std::isfinite(last_b.at(last_b.r1)) ||
        !std::isfinite(right_state.u) || !std::isfinite(left_state.u)) {
      ok_ = false;
      message_ = fmt::format("non-finite characteristic signal near t = {}", global_time(k, 0));
      return;
    }
    if (segment_count() > max_segments) {
      ok_ = false;
      message_ = fmt::format("more than {} signal segments before t = {} (event cascade)",
                             max_segments, global_time(k, 0));
      return;
    }
  }
  keep_closings_on_fronts();
}

// A candidate is a boundary between incoming segments b and b + 1 at which an open end reached
// its wall. It is a kink only where a front arrives there: the incoming value or slope jumps
// (a window's end, or a release at the other end, splits a signal without a jump).
void ExactBarSolution::keep_closings_on_fronts() {
  const double tol = snap_tolerance(tau_);
  for (const auto& [side, b] : front_closing_candidates_) {
    const auto& incoming = side == Side::right ? a_ : b_sig_;
    if (b + 1 >= incoming.segments.size()) continue;
    const Segment& s = incoming.segments[b];
    const Segment& next = incoming.segments[b + 1];
    const double before = s.at(s.r1), after = next.at(next.r0);
    const bool jump = carries_jump(before, after) || carries_jump(s.slope, next.slope);
    const double t = global_time(s.k, s.r1);
    if (jump && t <= t_end_ + tol) closings_on_fronts_.push_back(t);
  }
  std::sort(closings_on_fronts_.begin(), closings_on_fronts_.end());
  closings_on_fronts_.erase(std::unique(closings_on_fronts_.begin(), closings_on_fronts_.end()),
                            closings_on_fronts_.end());
  front_closing_candidates_.clear();
}

// An open end that reaches its wall just as a front arrives closes at the front. Where the
// front carries no jump (a knot of u0 whose slope does not change: on mode 1 every grid node x_j
// whose echo arrives at the closing, T = 3 L/c + x_j / c), the map is smooth there and the
// closing is the root of w + yc s = wall at s = 0: it moves by d s = -dw / yc, and the open
// history before it (of the same value) extends to it. Across a front with a jump
// (carries_jump) the closing stays on the front (README.md, 'Tangent').
void ExactBarSolution::move_closing_at_a_silent_front(Side side, const Segment& before, double yc,
                                                      bool approaching, const EndState& state,
                                                      SegmentTangent& piece) {
  auto& emitted = side == Side::right ? b_tan_ : a_tan_;
  const auto& track = side == Side::right ? right_ : left_;
  if (!approaching || emitted.empty() || track.segments.empty() || track.segments.back().closed)
    return;
  if (carries_jump(before.at(before.r1), yc)) return;
  const Eigen::VectorXd d_sc = state.du / -yc;
  const Sensitivity sparse = d_sc.sparseView(1.0, 0.0);
  piece.dr0 += sparse;
  emitted.back().dr1 += sparse;
}

void ExactBarSolution::march_end(Side side, long k, EndState& state) {
  const bool right = side == Side::right;
  const bar::End& model = right ? setup_.right : setup_.left;
  const double n = right ? 1.0 : -1.0;  // outward normal
  const double tol = snap_tolerance(tau_);
  const auto& incoming = right ? a_ : b_sig_;
  const auto& incoming_tangent = right ? a_tan_ : b_tan_;
  const bool tangent = tangent_size_ > 0;
  const std::size_t begin = incoming.first[static_cast<std::size_t>(k)];
  const std::size_t end = incoming.end_of(k);
  for (std::size_t i = begin; i < end; ++i) {
    const Segment s = incoming.segments[i];
    const SegmentTangent* ts = tangent ? &incoming_tangent[i] : nullptr;
    if (model.type == bar::EndType::fixed) {
      emit(side, k, s.r0, s.r1, s.y0, s.slope, true, false, state, ts);
      continue;
    }
    if (model.type == bar::EndType::free) {
      emit(side, k, s.r0, s.r1, s.y0, s.slope, false, false, state, ts);
      continue;
    }
    // Contact end: walk the segment through its events. The incoming invariant is the
    // end velocity when free (v = in); toward a wall whose outward normal is m (the end's n for
    // the front wall, -n for a clearance end's back wall) the incoming velocity is q = m * in.
    double rc = s.r0;
    const bool open_at_start = !state.closed;
    double yc = s.y0;
    // Tangent: the derivatives of rc and of the value yc there (README.md, 'Tangent').
    SegmentTangent piece;
    if (tangent) piece = {ts->dr0, ts->dr1, ts->dy0};
    auto emit_to = [&](double r1, const Sensitivity* dr1, bool negative, bool closed) {
      if (!tangent) return emit(side, k, rc, r1, yc, s.slope, negative, closed, state);
      piece.dr1 = dr1 ? *dr1 : ts->dr1;
      emit(side, k, rc, r1, yc, s.slope, negative, closed, state, &piece);
    };
    // Moves rc to the event at rc + ds (with d(ds) when tangent) and yc with it (segments
    // are constant with a tangent: yc's derivative stays).
    auto advance = [&](double ds, const Sensitivity& d_ds) {
      if (tangent) piece.dr0 += d_ds;
      yc += s.slope * ds;
      rc += ds;
    };
    for (int events = 0; rc < s.r1; ++events) {
      const double len = s.r1 - rc;
      if (events > 16) {  // cannot happen with exact roots; safety against a float cycle
        emit_to(s.r1, nullptr, state.closed, state.closed);
        break;
      }
      if (state.closed) {
        const double m = state.side * n;
        const double sr = release_time(m * yc, m * s.slope);
        if (sr <= tol) {
          state.closed = false;
          continue;
        }
        if (sr >= len - tol) {
          emit_to(s.r1, nullptr, true, true);
          break;
        }
        // Inside a segment only where its slope is not zero: never with a tangent, whose
        // segments are constant (they release at a start, above).
        if (tangent) throw std::logic_error("exact tangent: a release inside a sloped segment");
        emit_to(rc + sr, nullptr, true, true);
        advance(sr, Sensitivity());
        yc = 0.0;  // the force vanishes exactly at release
        state.closed = false;
      } else {
        const double q = n * yc, qm = n * s.slope;
        double sc = closure_time(std::max(0.0, model.gap - n * state.u), q, qm, tol);
        int wall = 1;
        if (model.has_back_wall()) {
          const double sb = closure_time(std::max(0.0, model.gap_back + n * state.u), -q, -qm, tol);
          if (sb < sc) {
            sc = sb;
            wall = -1;
          }
        }
        const double wall_u = wall > 0 ? n * model.gap : -n * model.gap_back;
        if (sc <= tol) {
          // Reached at this segment's start from an open end: the previous segment's end, which
          // its own check missed by more than the snap (a duplicate of it is dropped).
          if (events == 0 && i > 0 && open_at_start &&
              (front_closing_candidates_.empty() ||
               front_closing_candidates_.back() != std::pair{side, i - 1}))
            front_closing_candidates_.emplace_back(side, i - 1);
          // The previous open piece's emission must not have been read yet: the right end of
          // window k reads what the left end emitted in window k - 1 before the left end marches
          // window k (march_windows), so a left end at its window's first segment keeps the
          // closing on the front.
          if (tangent && events == 0 && open_at_start && i > 0 && (right || i > begin))
            move_closing_at_a_silent_front(side, incoming.segments[i - 1], yc,
                                           (wall > 0 ? q : -q) > 0, state, piece);
          state.closed = true;
          state.side = wall;
          state.u = wall_u;
          state.u_compensation = 0;
          if (tangent) state.du.setZero();
          continue;
        }
        if (sc >= len - tol) {
          // The end reaches its wall at the segment's end: a kink where a front arrives there
          // (keep_closings_on_fronts).
          if (sc <= len + tol) front_closing_candidates_.emplace_back(side, i);
          emit_to(s.r1, nullptr, false, false);
          break;
        }
        Sensitivity d_sc, d_close;
        if (tangent) {
          // w(rc + sc) = wall: w(rc) + yc sc = wall_u (a constant segment), so
          // yc d_sc = -(dw + sc dyc).
          Eigen::VectorXd dense = state.du;
          dense += sc * piece.dy0;
          d_sc = (dense / -yc).sparseView(1.0, 0.0);
          d_close = piece.dr0 + d_sc;
        }
        emit_to(rc + sc, tangent ? &d_close : nullptr, false, false);
        advance(sc, d_sc);
        state.closed = true;
        state.side = wall;
        state.u = wall_u;  // the wall position, exactly
        state.u_compensation = 0;
        if (tangent) state.du.setZero();
      }
    }
  }
}

// Appends one piece of end history [r0, r1) of window k with incoming invariant
// in0 + in_slope (r - r0); the outgoing one is -incoming (fixed end, closed contact) or
// +incoming (free end). It reaches the other end in window k + 1, increased by b tau.
void ExactBarSolution::emit(Side side, long k, double r0, double r1, double in0, double in_slope,
                            bool reflect_negative, bool closed, EndState& state,
                            const SegmentTangent* tangent) {
  if (!(r1 > r0)) return;
  if (tangent) {
    const double sign = reflect_negative ? -1.0 : 1.0;
    auto& other_tangent = side == Side::right ? b_tan_ : a_tan_;
    other_tangent.push_back({tangent->dr0, tangent->dr1, sign * tangent->dy0});
    if (!reflect_negative) {  // the free end's displacement gains int in = in0 (r1 - r0)
      // Into the dense du in place: sparse temporaries would allocate once per segment.
      double* du = state.du.data();
      for (Sensitivity::InnerIterator e(tangent->dy0); e; ++e)
        du[e.index()] += (r1 - r0) * e.value();
      for (Sensitivity::InnerIterator e(tangent->dr1); e; ++e) du[e.index()] += in0 * e.value();
      for (Sensitivity::InnerIterator e(tangent->dr0); e; ++e) du[e.index()] -= in0 * e.value();
    }
  }
  const double sign = reflect_negative ? -1.0 : 1.0;
  const double out0 = sign * in0, out_slope = sign * in_slope;
  auto& track = side == Side::right ? right_ : left_;
  auto& other = side == Side::right ? b_sig_ : a_;
  track.segments.push_back(
      {k, r0, r1, in0, in_slope, out0, out_slope, state.u, closed, closed && state.side < 0});
  if (!reflect_negative) {  // free: the end moves with v = incoming
    const double len = r1 - r0;
    // Compensated sum: a free end adds one increment per segment for the whole run.
    const double increment = in0 * len + 0.5 * in_slope * len * len - state.u_compensation;
    const double sum = state.u + increment;
    state.u_compensation = (sum - state.u) - increment;
    state.u = sum;
  }
  const Segment next{k + 1, r0, r1, out0 + b_ * tau_, out_slope};
  // A breakpoint across which the signal is continuous with the same slope (a front that has
  // been cancelled by a reflection) is dropped, or fronts would pile up window after window.
  // (Not with a tangent: the perturbed signal need not be continuous there.)
  if (tangent_size_ == 0 && other.segments.size() > other.first.back()) {
    Segment& last = other.segments.back();
    const double left_value = last.at(r0);
    if (last.r1 == r0 && same_to_ulps(left_value, next.y0) &&
        same_to_ulps(last.slope, next.slope)) {
      last.r1 = r1;
      return;
    }
  }
  other.segments.push_back(next);
}

double ExactBarSolution::front_tolerance(double t) const {
  return 8 * epsilon * (setup_.material.length + c_ * std::abs(t));
}

void ExactBarSolution::check_time(double t) const {
  if (!(t >= 0) || !(t <= t_end_ * (1 + 1e-12) + 1e-12 * tau_))
    throw InputError("t",
                     fmt::format("must lie in the solved interval [0, {}] (got {})", t_end_, t));
}

std::vector<ExactBarSolution::Piece> ExactBarSolution::profile(double t) const {
  check_time(t);
  const double L = setup_.material.length;
  const Local lt = to_local(t);
  const long k = lt.k;
  const double rt = lt.r;
  std::vector<double> xs{0.0, L};
  auto add_breakpoints = [&](const Chunked<Segment>& sig, bool from_right) {
    for_each_front(sig, from_right, t, [&](std::size_t, double x) { xs.push_back(x); });
  };
  add_breakpoints(a_, true);
  add_breakpoints(b_sig_, false);
  // Fronts within round-off of each other or of an end are one front (the argument t + offset
  // carries a few ulps of t): no sliver pieces, and the ends are never mistaken for fronts.
  std::sort(xs.begin(), xs.end());
  const double tol = front_tolerance(t);
  std::vector<double> kept{0.0};
  for (double x : xs)
    if (x - kept.back() > tol && L - x > tol) kept.push_back(x);
  kept.push_back(L);
  xs.swap(kept);

  // Value of a signal at argument t + offset (offset in [0, tau]), using the segment that
  // holds t + mid_offset, so that the value is the limit from inside the piece.
  auto value = [&](const Chunked<Segment>& sig, double offset, double mid_offset, double& slope) {
    const double rm = rt + mid_offset;
    const long kk = rm < tau_ ? k : k + 1;
    const double shift = kk == k ? 0.0 : tau_;
    const Segment& seg = sig.locate(kk, rm - shift);
    slope = seg.slope;
    return seg.at(rt + offset - shift);
  };

  std::vector<Piece> pieces;
  pieces.reserve(xs.size());
  double u = u_end(Side::left, t);
  for (std::size_t j = 0; j + 1 < xs.size(); ++j) {
    const double xa = xs[j], xb = xs[j + 1], xm = 0.5 * (xa + xb);
    double slope_a, slope_b;
    const double plus_a = value(a_, (L - xa) / c_, (L - xm) / c_, slope_a) - b_ * (L - xa) / c_;
    const double minus_a = value(b_sig_, xa / c_, xm / c_, slope_b) - b_ * xa / c_;
    const double plus_slope = (b_ - slope_a) / c_;
    const double minus_slope = (slope_b - b_) / c_;
    Piece p{xa,
            xb,
            u,
            0.5 * (plus_a + minus_a),
            0.5 * (plus_slope + minus_slope),
            (minus_a - plus_a) / (2 * c_),
            (minus_slope - plus_slope) / (2 * c_)};
    pieces.push_back(p);
    u = p.u_at(xb);
  }
  return pieces;
}

namespace {

// Index of the piece holding x and, when x sits on a boundary between two pieces (within a
// few ulps), the index of the neighbour across it (else the same index).
template <class P>
std::pair<std::size_t, std::size_t> pieces_at(const std::vector<P>& pieces, double x, double tol) {
  auto it = std::upper_bound(pieces.begin(), pieces.end(), x,
                             [](double s, const P& p) { return s < p.xa; });
  std::size_t k = static_cast<std::size_t>(it - pieces.begin());
  k = k == 0 ? 0 : std::min(k - 1, pieces.size() - 1);
  if (k > 0 && x - pieces[k].xa <= tol) return {k - 1, k};
  if (k + 1 < pieces.size() && pieces[k].xb - x <= tol) return {k, k + 1};
  return {k, k};
}

}  // namespace

double ExactBarSolution::u(double x, double t) const {
  const double L = setup_.material.length;
  if (!(x >= 0 && x <= L)) throw InputError("x", fmt::format("must lie in [0, {}] (got {})", L, x));
  const auto pieces = profile(t);
  const auto [k, k2] = pieces_at(pieces, x, front_tolerance(t));
  return pieces[k2].u_at(std::max(x, pieces[k2].xa));
}

double ExactBarSolution::v(double x, double t) const {
  const double L = setup_.material.length;
  if (!(x >= 0 && x <= L)) throw InputError("x", fmt::format("must lie in [0, {}] (got {})", L, x));
  const auto pieces = profile(t);
  const auto [k, k2] = pieces_at(pieces, x, front_tolerance(t));
  if (k == k2) return pieces[k].v_at(x);
  return 0.5 * (pieces[k].v_at(pieces[k].xb) + pieces[k2].v_at(pieces[k2].xa));
}

double ExactBarSolution::strain(double x, double t) const {
  const double L = setup_.material.length;
  if (!(x >= 0 && x <= L)) throw InputError("x", fmt::format("must lie in [0, {}] (got {})", L, x));
  const auto pieces = profile(t);
  const auto [k, k2] = pieces_at(pieces, x, front_tolerance(t));
  if (k == k2) return pieces[k].e_at(x);
  return 0.5 * (pieces[k].e_at(pieces[k].xb) + pieces[k2].e_at(pieces[k2].xa));
}

Side ExactBarSolution::observed() const {
  return setup_.observed_end_is_right() ? Side::right : Side::left;
}

const ExactBarSolution::EndSegment& ExactBarSolution::end_segment(Side side, double t,
                                                                  double& r) const {
  check_time(t);
  const Local lt = to_local(t);
  const auto& track = side == Side::right ? right_ : left_;
  const EndSegment& seg = track.locate(lt.k, lt.r);
  r = lt.r - seg.r0 + (lt.k - seg.k) * tau_;  // time since the segment's start
  return seg;
}

double ExactBarSolution::end_strain(const EndSegment& seg, Side side, double s) const {
  const double in = seg.in0 + seg.in_slope * s;
  const double out = seg.out0 + seg.out_slope * s;
  // Right end: R+ = in, R- = out. Left end: R- = in, R+ = out. Strain = (R- - R+) / (2c).
  return side == Side::right ? (out - in) / (2 * c_) : (in - out) / (2 * c_);
}

double ExactBarSolution::u_end(double t) const {
  return u_end(observed(), t);
}

double ExactBarSolution::u_end(Side side, double t) const {
  double s;
  const EndSegment& seg = end_segment(side, t, s);
  const double v0 = 0.5 * (seg.in0 + seg.out0);
  const double v1 = 0.5 * (seg.in_slope + seg.out_slope);
  return seg.u0 + v0 * s + 0.5 * v1 * s * s;
}

double ExactBarSolution::contact_force(double t) const {
  return contact_force(observed(), t);
}

double ExactBarSolution::contact_force(Side side, double t) const {
  double s;
  const EndSegment& seg = end_segment(side, t, s);
  return -setup_.material.axial_stiffness() * end_strain(seg, side, s);
}

bool ExactBarSolution::in_contact(Side side, double t) const {
  double s;
  return end_segment(side, t, s).closed;
}

double ExactBarSolution::energy(double t) const {
  const auto pieces = profile(t);
  const double rho_a = setup_.material.density * setup_.material.area;
  const double ea = setup_.material.axial_stiffness();
  const double fa = setup_.body_force * setup_.material.area;
  double total = 0;
  for (const Piece& p : pieces) {  // integrand quadratic on each piece: Simpson is exact
    auto density = [&](double x) {
      const double v = p.v_at(x), e = p.e_at(x);
      return 0.5 * (rho_a * v * v + ea * e * e) - fa * p.u_at(x);
    };
    const double xm = 0.5 * (p.xa + p.xb);
    total += (p.xb - p.xa) / 6 * (density(p.xa) + 4 * density(xm) + density(p.xb));
  }
  return total;
}

std::vector<ContactInterval> ExactBarSolution::contact_intervals() const {
  return contact_intervals(observed());
}

std::vector<ContactInterval> ExactBarSolution::contact_intervals(Side side) const {
  const auto& track = (side == Side::right ? right_ : left_).segments;
  std::vector<ContactInterval> out;
  for (std::size_t i = 0; i < track.size(); ++i) {
    const double t_close = global_time(track[i].k, track[i].r0);
    if (!(t_close < t_end_)) break;
    if (!track[i].closed) continue;
    std::size_t j = i;
    while (j + 1 < track.size() && track[j + 1].closed && track[j + 1].back == track[i].back) ++j;
    double release = j + 1 < track.size() ? global_time(track[j + 1].k, track[j + 1].r0) : infinity;
    if (release > t_end_) release = infinity;
    out.push_back({t_close, release, track[i].back});
    i = j;
  }
  return out;
}

bar::FieldSnapshot ExactBarSolution::snapshot(double t, const bar::SnapshotRequest& request) const {
  if (request.elements < 1)
    throw InputError("elements", fmt::format("must be >= 1 (got {})", request.elements));
  bar::FieldSnapshot snap;
  snap.t = t;
  const double L = setup_.material.length;
  const bool uniform = request.nodes.empty();
  const int n = uniform ? request.elements : static_cast<int>(request.nodes.size()) - 1;
  const auto nodes = static_cast<std::size_t>(n) + 1;
  if (uniform) {
    snap.x.resize(nodes);
    for (std::size_t i = 0; i < nodes; ++i) snap.x[i] = L * static_cast<double>(i) / n;
  } else {
    snap.x = request.nodes;
  }
  if (!ok_) {
    snap.ok = false;
    snap.message = message_;
    return snap;
  }
  const auto pieces = profile(t);
  if (request.nodal_u || request.nodal_v) {
    if (request.nodal_u) snap.u.resize(nodes);
    if (request.nodal_v) snap.v.resize(nodes);
    for (std::size_t i = 0; i < nodes; ++i) {
      const auto [k, k2] = pieces_at(pieces, snap.x[i], front_tolerance(t));
      if (request.nodal_u) snap.u[i] = pieces[k2].u_at(std::max(snap.x[i], pieces[k2].xa));
      // On a front v has two one-sided limits: report their average.
      if (request.nodal_v)
        snap.v[i] = k == k2 ? pieces[k].v_at(snap.x[i])
                            : 0.5 * (pieces[k].v_at(pieces[k].xb) + pieces[k2].v_at(pieces[k2].xa));
    }
  }
  if (request.projected_u || request.projected_v) {
    // int f psi_i dx over each (piece x cell) intersection: f psi is at most cubic there,
    // so Simpson's rule is exact.
    if (request.projected_u) snap.u_projected.assign(nodes, 0.0);
    if (request.projected_v) snap.v_projected.assign(nodes, 0.0);
    const double h = L / n;
    for (const Piece& p : pieces) {
      auto j = uniform
                   ? static_cast<std::size_t>(std::clamp(std::floor(p.xa / h), 0.0, n - 1.0))
                   : static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(
                         std::upper_bound(snap.x.begin(), snap.x.end(), p.xa) - snap.x.begin() - 1,
                         0, n - 1));
      if (j > 0 && snap.x[j] > p.xa) --j;
      for (; j < static_cast<std::size_t>(n) && snap.x[j] < p.xb; ++j) {
        const double a = std::max(p.xa, snap.x[j]), b = std::min(p.xb, snap.x[j + 1]);
        if (!(b > a)) continue;
        const double xj = snap.x[j], xj1 = snap.x[j + 1], width = xj1 - xj;
        const double m = 0.5 * (a + b), w = (b - a) / 6;
        auto add = [&](std::vector<double>& proj, auto f) {
          auto left_hat = [&](double x) { return (xj1 - x) / width; };
          auto right_hat = [&](double x) { return (x - xj) / width; };
          proj[j] += w * (f(a) * left_hat(a) + 4 * f(m) * left_hat(m) + f(b) * left_hat(b));
          proj[j + 1] += w * (f(a) * right_hat(a) + 4 * f(m) * right_hat(m) + f(b) * right_hat(b));
        };
        if (request.projected_u) add(snap.u_projected, [&](double x) { return p.u_at(x); });
        if (request.projected_v) add(snap.v_projected, [&](double x) { return p.v_at(x); });
      }
    }
  }
  for (const auto* field : {&snap.u, &snap.v, &snap.u_projected, &snap.v_projected})
    for (double value : *field)
      if (!std::isfinite(value)) {
        snap.ok = false;
        snap.message = fmt::format("non-finite field at t = {}", t);
        return snap;
      }
  return snap;
}

std::size_t ExactBarSolution::segment_count() const {
  return a_.segments.size() + b_sig_.segments.size() + left_.segments.size() +
         right_.segments.size();
}

ExactBarSolution solve(const bar::BarSetup& setup, double t_end) {
  return ExactBarSolution(setup, t_end);
}

std::vector<ContactInterval> contact_intervals(const bar::BarSetup& setup, double t_end) {
  return ExactBarSolution(setup, t_end).contact_intervals();
}

}  // namespace backbone::exact_bar
