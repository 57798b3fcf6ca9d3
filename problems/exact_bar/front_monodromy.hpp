// The isolated Floquet multipliers of a periodic orbit of the bar, from its fronts
// (README.md, 'Fronts').
//
// The orbits of the contact bar start at rest from a piecewise-linear u0, so their Riemann
// invariants are piecewise constant: values between finitely many fronts. A perturbation is a
// change of the values (any bounded function) and a shift of each front. Over one period T
//   - the values are carried along the characteristics and reflected with a sign, an isometry
//     of L2 whose spectrum lies on the unit circle, and they move the fronts (a contact starts
//     when the end's displacement, an integral of them, reaches the wall);
//   - a front shift moves the fronts and leaves every value where it was (a closing or release
//     that comes earlier or later emits the same values, starting earlier or later).
// So the monodromy is block triangular, [[U, 0], [C, K]], and its multipliers off the unit
// circle are the eigenvalues of K, the derivative of the fronts' arrival times at T with respect
// to theirs at 0 (a time shift of the orbit moves every front alike: K 1 = 1, the trivial
// multiplier). K is built here exactly, from the tangent of the exact solver, with no grid and
// no projection; the energy's multiplier +1 and the continuum belong to U.
//
//   auto m = exact_bar::front_monodromy(setup, state, T);   // state: at a time the end is free
//   Eigen::EigenSolver<Eigen::MatrixXd> es(m.K);
#pragma once

#include <Eigen/Dense>
#include <string>

#include "problems/bar/bar.hpp"
#include "problems/exact_bar/exact_solution.hpp"

namespace backbone::exact_bar {

struct FrontMonodromy {
  bool ok = false;
  std::string message;  // why not ok
  // fronts x fronts: d(arrival time at T of each front) / d(its arrival time at 0), the fronts
  // in the state's order (A's, then B's), times in the characteristic state's r.
  Eigen::MatrixXd K;
  // fronts x pieces: the same arrival times' derivatives in the values.
  Eigen::MatrixXd C;
  // Checks of the block structure, relative (0 in exact arithmetic):
  double value_leak = 0;        // max |d(value at T) / d(front)| over max |value|
  double isometry_error = 0;    // max |G - W| / max W: G the Gram matrix of the values' images
                                // in the L2 product (piece lengths W), W = diag(lengths)
  double time_shift_error = 0;  // max |K 1 - 1|
  double return_error = 0;      // max over fronts |start(T) - start(0)| / tau and over pieces
                                // |value(T) - value(0)| / max |value|: how periodic the orbit is
};

// A traced orbit's state carries its residual: breakpoints between equal slopes jump by
// round-off, and two fronts that meet in the exact orbit sit a few ulps apart with a sliver
// between them. Here jumps under `tolerance` times the largest |value| are not fronts (such
// neighbours become one piece with their length-weighted mean value), and pieces shorter than
// 1e-9 tau are dropped (the fronts on either side become one, with the sum of their jumps).
constexpr double default_jump_tolerance = 1e-7;
CharacteristicState without_small_jumps(const CharacteristicState& state, double tolerance,
                                        double tau);

// The orbit's state in characteristic form (without_small_jumps) at a time t0 in [0, T) at
// which its right end is free, as far as the free flights allow from a contact event and from
// a front at an end, at t0 and at t0 + T (where the tangent march reads it). t0 NaN if the end
// is closed throughout. `orbit` is solved over at least [0, T].
struct OrbitState {
  double t0 = 0;
  CharacteristicState state;
};
OrbitState free_flight_state(const ExactBarSolution& orbit, double period,
                             double jump_tolerance = default_jump_tolerance);

// K at the orbit through `state` (in characteristic form at a time its right end is free; the
// orbit's period T). Not ok when the state's fronts at T (jumps over jump_tolerance times the
// largest |value|) do not match its fronts at 0 (to 1e-6 tau: not a periodic orbit, or not of
// this contact sequence) or the march fails.
FrontMonodromy front_monodromy(const bar::BarSetup& setup, const CharacteristicState& state,
                               double period, double jump_tolerance = default_jump_tolerance);

}  // namespace backbone::exact_bar
