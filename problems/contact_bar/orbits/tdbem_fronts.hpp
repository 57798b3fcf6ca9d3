// The isolated multipliers' matrix K of an orbit by the TD-BEM's own march, to set against the
// exact solver's (exact_bar/front_monodromy.hpp; README.md, 'Stability').
//
// The TD-BEM marches the orbit from its state at rest to a time t0 at which the end is free,
// and its field there is read in characteristic form (tdbem_characteristic_state): A and B
// piecewise constant between fronts. Each front is then moved by +-h, the state handed back to
// the TD-BEM as initial data (u0 piecewise linear, v0 piecewise constant with jumps:
// exact_bar::with_characteristic_state), marched over one period T, and its fronts read again:
// K's column is the motion of every front at T over 2h. With the event method the march is
// exact for such data (solver/README.md) and its map is affine in h while no event crosses a
// front or a step boundary that matters, so the differences carry only round-off over h. Near a
// grazing a front may leave the matching window: the column is retried with h / 10 and h / 100;
// a side that still changes the fronts leaves the other side's difference (TdbemFronts::kink). No
// derivative, no grid and no march of the exact solver enter: only exact_bar's helpers of the
// characteristic form and its choice of t0 (any time of free flight gives K up to a similarity).
//
//   contact_bar::TdbemFronts f = contact_bar::tdbem_front_monodromy(setup, t0, T, dt);
//   f.K;  // fronts x fronts, the fronts ordered as in exact_bar::CharacteristicState
#pragma once

#include <Eigen/Dense>
#include <string>

#include "problems/bar/bar.hpp"
#include "problems/contact_bar/solver/tdbem.hpp"
#include "problems/exact_bar/exact_solution.hpp"

namespace backbone::contact_bar {

// The march's field at its current time in characteristic form: R+ = v - c u_x and
// R- = v + c u_x on each piece between the field's breakpoints (read at its middle; pieces
// under 1e-12 L dropped, and under 1e-9 L at an end), neighbours within 8 ulps merged. A sliver's
// value (a piece between two fronts that nearly meet) is formed from knots that close in time and
// carries round-off over its length. InputError "tdbem_fronts" when the field is not piecewise
// constant in R+- (a piece over 1e-9 L whose two quarter points differ by more than 1e-9 of the
// largest value).
exact_bar::CharacteristicState tdbem_characteristic_state(const TdbemMarch& march);

struct TdbemFronts {
  bool ok = false;
  std::string message;                   // why not ok
  exact_bar::CharacteristicState state;  // the TD-BEM's state at t0
  Eigen::MatrixXd K;                     // d(front times at t0 + T) / d(front times at t0)
  // The one-sided differences (steps +h and -h alone) and their largest difference: round-off
  // over h (1e-10) where the map is smooth; of order 1 where the orbit sits on a kink of it (a
  // grazing contact: one side touches the wall, the other does not), and K is their mean;
  // infinity where one side's march changes the fronts within h (a new front, or one lost),
  // and K is the other side's difference.
  Eigen::MatrixXd K_forward, K_backward;
  double kink = 0;
};

// K of the orbit that starts at rest from `setup` (period T), by the TD-BEM (event method) at
// time step dt, from its state at t0. relative_step: h over tau.
TdbemFronts tdbem_front_monodromy(const bar::BarSetup& setup, double t0, double period, double dt,
                                  double relative_step = 1e-6);

// The eigenvalues of a fronts' return map K (false when they do not converge). The shifted QR
// iteration can stall on such a K (one point of 30 on the family attached to mode 1 at T = 3.5,
// 80 intervals, by the TD-BEM): it is retried once on Q K Q, Q a fixed Householder reflection,
// the same eigenvalues in another Hessenberg form.
bool front_eigenvalues(const Eigen::MatrixXd& K, Eigen::VectorXcd& mu);

// The bottleneck distance between the eigenvalues of `a` and of `b`: the smallest d such that
// they pair off one to one within d (multiplicities count); infinity when the sizes differ, NaN
// when the QR iteration for either's eigenvalues does not converge, even after a similarity.
// A greedy nearest pairing can leave the last of a cluster a far partner (sqrt 2 on a family
// attached to mode 1 at 80 intervals, where K differed by 5e-9).
double multiplier_distance(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b);

}  // namespace backbone::contact_bar
