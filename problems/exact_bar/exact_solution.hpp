// The exact motion of the bar (d'Alembert / characteristics), built once, queried cheaply.
//
// For piecewise-linear u0, v0 and a constant body force the Riemann invariants
// R+ = v - c u_x and R- = v + c u_x are piecewise-linear along the characteristics, so the
// whole motion is carried by two piecewise-linear signals of time: A(t), the R+ arriving at
// x = L, and B(t), the R- arriving at x = 0 (jumps allowed). Each end reflects its incoming
// signal (free: unchanged, fixed or closed contact: sign flip); a contact end switches
// free -> closed when its displacement reaches the wall (exact root of a quadratic) and
// closed -> free when the contact force EA (n * incoming) / c turns negative (linear root).
// Nothing is discretised in time: every value is exact to round-off, and the cost is the
// number of signal segments (never a number of time steps). This is the reference of every
// test and the accuracy limit of every benchmark.
//
//   bar::BarSetup s;                                        //
//   problems/contact_bar/orbits/README.md 'Mode 1' s.right = {bar::EndType::contact, 1e-3}; s.u0 =
//   bar::PiecewiseLinear({0.0, 1.0}, {0.0, -0.01}); exact_bar::ExactBarSolution sol =
//   exact_bar::solve(s, 3.1); sol.contact_intervals();          // {[1.1, 2)}
//   sol.contact_force(1.5);           // 0.01 = EA |eps|
//   sol.u(0.5, 3.1);                  // -0.005: back to u0
//   sol.energy(2.0);                  // EA L eps^2 / 2
#pragma once

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "problems/bar/bar.hpp"

namespace backbone::exact_bar {

enum class Side { left, right };

// Forward sensitivities of a solution with respect to n parameters p on which its initial
// displacement depends (v0 = 0, no body force): per knot i of setup.u0, the derivatives of its
// position and of its value, each a vector of size n (README.md, 'Tangent').
// Sparse: a segment depends on the few knots its characteristics come from, except where an
// event (a closing, a release) has gathered the end's whole history.
using Sensitivity = Eigen::SparseVector<double>;
struct InitialTangent {
  std::vector<Sensitivity> d_knot, d_value;
};

// The state of the bar in characteristic form at a time t (README.md, 'Fronts'): A over the
// next transit, the R+ = v - c u_x that reaches x = L at t + r, r in [0, tau), and B, the R- that
// reaches x = 0 at t + r, each piecewise constant: start[0] = 0 < start[1] < ... < tau, one value
// per piece. With a fixed end at x = 0 it is the whole state: R+(x) = A((L - x) / c),
// R-(x) = B(x / c), and u follows by integrating u_x = (R- - R+) / (2 c) from the fixed end.
// Every interior start is a front (a jump of the signal).
struct CharacteristicState {
  std::vector<double> a_start, a_value, b_start, b_value;
  int fronts() const { return static_cast<int>(a_start.size() + b_start.size()) - 2; }
  int pieces() const { return static_cast<int>(a_value.size() + b_value.size()); }
};

// One constant piece of A or B over [t, t + tau) as the march left it (pieces are not merged
// across breakpoints without a jump), with its derivatives when the solution carries a
// tangent: of its start (r, relative to t) and of its value.
struct SignalPiece {
  bool of_a = true;
  double start = 0, end = 0, value = 0;
  Sensitivity d_start, d_value;
};

// The derivatives of the hat projections int v(x, t) psi_i dx on a uniform grid: d_p, one
// column per node i = 0..elements (n x (elements + 1): the gradient of that projection in the
// n parameters) at fixed t; and d_t, their rate in t.
struct ProjectedVelocityTangent {
  Eigen::MatrixXd d_p;
  Eigen::VectorXd d_t;
};

// One closed-contact episode of an end: closed on [t_close, t_release).
struct ContactInterval {
  double t_close = 0;
  double t_release = 0;    // +infinity if the end is still closed at the solution's t_end
  bool back_wall = false;  // on the wall behind a clearance end
};

// The same state as initial data of any bar solver: `setup` with u0 continuous and piecewise
// linear (u_x = (R- - R+) / (2 c) integrated from u(0) = 0) and v0 = (R+ + R-) / 2 piecewise
// constant, its jumps on the fronts (bar::PiecewiseLinear::with_jumps). InputError "a_signal",
// "b_signal" as the constructor below.
bar::BarSetup with_characteristic_state(bar::BarSetup setup, const CharacteristicState& state);

class ExactBarSolution {
 public:
  // Solves on [0, t_end]. Throws core::InputError for a bad setup or t_end (key "t_end").
  ExactBarSolution(const bar::BarSetup& setup, double t_end);
  // The same, carrying the forward sensitivities seeded by `tangent` (InputError "v0" or
  // "body_force" when either is not zero, "tangent" when its sizes do not fit u0).
  ExactBarSolution(const bar::BarSetup& setup, double t_end, InitialTangent tangent);

  // Solves on [0, t_end] from a state in characteristic form (its fronts inside (0, tau), the
  // left end fixed, the right end free of its walls, no body force; setup.u0 and v0 are not
  // read). With `tangent` it carries the derivatives in n = fronts + pieces parameters: the
  // starts of A's fronts, then B's, then A's values, then B's (README.md, 'Fronts').
  ExactBarSolution(const bar::BarSetup& setup, double t_end, CharacteristicState initial,
                   bool tangent);

  // false if the event march failed (non-finite signal or runaway event count).
  bool ok() const { return ok_; }
  const std::string& message() const { return message_; }
  const bar::BarSetup& setup() const { return setup_; }
  double t_end() const { return t_end_; }

  // Fields at (x, t), x in [0, L], t in [0, t_end] (else InputError, key "x" or "t").
  // v and the strain jump across fronts: at a jump they return the average of the two
  // one-sided limits (a node within a few ulps of a front counts as on it).
  double u(double x, double t) const;
  double v(double x, double t) const;
  double strain(double x, double t) const;

  // End quantities; without a Side, the observed end of bar::BarSetup.
  double u_end(double t) const;
  double u_end(Side side, double t) const;
  // Compressive force -EA u_x at the end (contact force if the end is a contact end, the
  // reaction if fixed, 0 if free). Right-continuous in t (0 at the release instant).
  double contact_force(double t) const;
  double contact_force(Side side, double t) const;
  bool in_contact(Side side, double t) const;

  // E = 1/2 int (rho A v^2 + EA u_x^2) dx - int body_force A u dx, integrated exactly.
  double energy(double t) const;

  // Closed-contact episodes starting before t_end, in time order (empty for non-contact ends).
  std::vector<ContactInterval> contact_intervals() const;
  std::vector<ContactInterval> contact_intervals(Side side) const;

  // The instants in (0, t_end], in time order, where an open end reaches a wall (the front or a
  // clearance end's back wall) exactly, to the march's snap (64 eps tau), as a front arrives
  // (the incoming signal's value or slope jumps by more than 1e-12 of it): it closes there, or
  // grazes the wall and leaves. They are the kinks of the solution map; a tangent through one takes
  // the march's choice (README.md, 'Tangent').
  const std::vector<double>& closings_on_fronts() const { return closings_on_fronts_; }

  // The field on the uniform grid of request.elements intervals at time t; every projection
  // int f psi_i dx is exact (Simpson on each polynomial piece). request.dt is ignored.
  bar::FieldSnapshot snapshot(double t, const bar::SnapshotRequest& request) const;

  // With a tangent: the derivatives of snapshot(t, {elements, projected_v}).v_projected. At a
  // kink of the solution map (an event exactly on a front with a jump, a grazing) the
  // derivative is the march's choice (README.md, 'Tangent'); a closing on a front without a
  // jump, where the map is smooth, takes the closing's own motion.
  ProjectedVelocityTangent projected_velocity_tangent(double t, int elements) const;

  // The state at t in characteristic form (neighbouring pieces of equal value merged, so that
  // every interior start is a front); InputError "t" if a signal is not constant there.
  CharacteristicState characteristic_state(double t) const;
  // The pieces of A and of B over [t, t + tau), unmerged, with their derivatives (empty
  // Sensitivity without a tangent).
  std::vector<SignalPiece> signal_pieces(double t) const;
  int tangent_size() const { return tangent_size_; }

  // Number of linear pieces stored (both signals and both end tracks): the cost measure.
  std::size_t segment_count() const;

 private:
  // Times are stored window-relative: window k = [k tau, (k+1) tau), local time r in [0, tau].
  // Crossing the bar is then an exact shift (k -> k + 1), so round-off does not accumulate
  // with the number of windows.
  struct Segment {  // value y0 + slope (r - r0) on [r0, r1) of window k
    long k;
    double r0, r1, y0, slope;
    double at(double r) const { return y0 + slope * (r - r0); }
  };
  // One piece of an end's history: incoming and outgoing invariants, displacement at r0.
  struct EndSegment {
    long k;
    double r0, r1;
    double in0, in_slope, out0, out_slope;
    double u0;
    bool closed;
    bool back;  // closed on the back wall of a clearance end
  };
  // Segments in time order with the index of the first segment of each window.
  template <class Seg>
  struct Chunked {
    std::vector<Seg> segments;
    std::vector<std::size_t> first;
    std::size_t end_of(long k) const {
      const auto next = static_cast<std::size_t>(k) + 1;
      return next < first.size() ? first[next] : segments.size();
    }
    const Seg& locate(long k, double r) const;
  };
  struct EndState {
    bool closed = false;
    int side = 1;               // the wall of a closed end: +1 front, -1 back (clearance)
    double u = 0;               // displacement of the end
    double u_compensation = 0;  // Kahan: low-order part lost when adding to u
    Eigen::VectorXd du;         // its derivative (tangent only; dense: it sums the history)
  };
  // The derivatives of a segment's data (tangent only): of its start and end times and of its
  // value. With v0 = 0 and no body force every segment is constant (slope 0), and stays so.
  struct SegmentTangent {
    Sensitivity dr0, dr1, dy0;
  };
  struct Local {
    long k;
    double r;
  };
  // Field on one x-interval at a fixed time: u quadratic, v and strain linear.
  struct Piece {
    double xa, xb, ua, va, dv, ea, de;
    double u_at(double x) const {
      const double h = x - xa;
      return ua + ea * h + 0.5 * de * h * h;
    }
    double v_at(double x) const { return va + dv * (x - xa); }
    double e_at(double x) const { return ea + de * (x - xa); }
  };

  void march();
  void march_end(Side side, long k, EndState& state);
  void move_closing_at_a_silent_front(Side side, const Segment& before, double yc, bool approaching,
                                      const EndState& state, SegmentTangent& piece);
  void march_windows(EndState& left_state, EndState& right_state);
  void seed_characteristic_state(EndState& left_state, EndState& right_state);
  void emit(Side side, long k, double r0, double r1, double in0, double in_slope,
            bool reflect_negative, bool closed, EndState& state,
            const SegmentTangent* tangent = nullptr);
  void seed_initial_signals(const std::vector<double>& xs);  // a_tan_, b_tan_ of window 0
  void check_time(double t) const;
  double front_tolerance(double t) const;  // fronts closer than this in x are one front
  Local to_local(double t) const;
  double global_time(long k, double r) const;
  std::vector<Piece> profile(double t) const;
  // Calls f(i, x) for every segment i of `sig` (A when from_right, else B) whose start is a
  // front in flight at t: its argument s in (t, t + tau), at x = L - c (s - t) for A, c (s - t)
  // for B (clamped to [0, L]).
  template <class F>
  void for_each_front(const Chunked<Segment>& sig, bool from_right, double t, F&& f) const;
  const EndSegment& end_segment(Side side, double t, double& r) const;
  double end_strain(const EndSegment& seg, Side side, double r) const;
  Side observed() const;

  bar::BarSetup setup_;
  double t_end_ = 0;
  double c_ = 1, tau_ = 1, b_ = 0;  // wave speed, travel time L/c, body acceleration f/rho
  Chunked<Segment> a_, b_sig_;      // A (R+ arriving at L), B (R- arriving at 0)
  Chunked<EndSegment> left_, right_;
  bool ok_ = true;
  std::string message_;
  std::vector<double> closings_on_fronts_;  // global times, sorted
  // Boundaries (side, b) between incoming segments b and b + 1 where an open end reached its
  // wall, during the march; keep_closings_on_fronts keeps those where a front arrives.
  std::vector<std::pair<Side, std::size_t>> front_closing_candidates_;
  void keep_closings_on_fronts();
  // Tangent: its seed, its size n (0: none), the segments' derivatives beside a_ and b_sig_.
  InitialTangent seed_;
  int tangent_size_ = 0;
  std::vector<SegmentTangent> a_tan_, b_tan_;
  // The initial state in characteristic form, when given instead of u0 and v0.
  std::optional<CharacteristicState> initial_;
};

template <class F>
inline void ExactBarSolution::for_each_front(const Chunked<Segment>& sig, bool from_right, double t,
                                             F&& f) const {
  const double L = setup_.material.length;
  const Local lt = to_local(t);
  const long k = lt.k;
  const double rt = lt.r, rest = tau_ - lt.r;  // the window of t ends rest after t
  for (long kk : {k, k + 1}) {
    if (kk >= static_cast<long>(sig.first.size())) continue;
    for (std::size_t i = sig.first[kk]; i < sig.end_of(kk); ++i) {
      const double r0 = sig.segments[i].r0;
      double offset;  // s - t
      if (kk == k) {
        if (!(r0 > rt)) continue;
        offset = r0 - rt;
      } else {
        if (!(r0 < rt)) break;
        offset = rest + r0;
      }
      f(i, std::clamp(from_right ? L - c_ * offset : c_ * offset, 0.0, L));
    }
  }
}

// Convenience: ExactBarSolution(setup, t_end).
ExactBarSolution solve(const bar::BarSetup& setup, double t_end);

// Closed-contact episodes of the observed end over [0, t_end].
std::vector<ContactInterval> contact_intervals(const bar::BarSetup& setup, double t_end);

}  // namespace backbone::exact_bar
