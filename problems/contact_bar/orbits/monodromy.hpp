// The monodromy of a contact-bar orbit: the derivative of the period map of the full state
// (u, v), in a stated finite representation (README.md, section 'Stability').
//
// Representation: continuous piecewise-linear u and v on a node grid (the orbit's own, or a
// uniform one of `elements` intervals), nodal values at y_1..y_N (y_0 = 0 is the fixed end,
// u = v = 0 there). The state
// s = [u_1..u_N | v_1..v_N] is simulated over one period T by the problem's bar solver, and
// mapped back onto the grid: u by its point values at the nodes, v by its L2 projection onto
// the same space (hat-weighted integrals, solved with the P1 mass matrix). Both are exact for a
// piecewise-linear state on the grid, so the period map is exact wherever the state at T is one
// (the free bar after 2L/c or 4L/c: -I and I); a state at T with kinks off the grid is
// projected, and a projection dissipates (README.md, 'Stability').
//
// The bar solver marches the piecewise-linear u0 exactly, a piecewise-linear v0 to second order
// in c dt / dx (its end histories are quadratic between steps, the march's linear): the time step
// of the map is the problem's, or courant dx / c when smaller (T / dt an integer). Measured on the
// free bar after 4L/c (tests/problems/contact_bar/orbits/test_monodromy.cpp): the v columns of M
// are off by 0.46 (c dt / dx)^2, the u columns by round-off.
// M = d(map)/ds from the march's own tangent, one march carrying 2N directions
// (solver/tdbem.hpp, 'Tangent'), when the problem's solver is the TD-BEM's event march and the
// state is off a contact end's wall: on a kink of the map, the side of the march's own contact
// decisions (on a clearance end's walls, the side away from the wall). Otherwise by central
// differences, 4N simulations of one period (on `threads` threads), the mean of the two sides at
// a kink; for a state on a contact end's wall, the columns of u(L) and v(L) are the one-sided
// differences away from it.
// The period map is affine while the contact sequence and the grid cells holding its instants'
// fronts stay the same, except where a front's characteristic moves with the state: its
// projection is quadratic in the motion, and differences carry an error linear in the step
// (up to 3.3e-5 of |M| on mode 1 at 40 intervals at the default step).
//
//   contact_bar::MonodromyOptions o; o.elements = 40;
//   core::Matrix M;
//   core::EvalStatus st = contact_bar::full_state_monodromy(problem, x, o, M);   // 2N x 2N
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/problem.hpp"
#include "core/types.hpp"
#include "problems/bar/bar.hpp"
#include "problems/contact_bar/orbits/tdbem_fronts.hpp"
#include "problems/exact_bar/front_monodromy.hpp"

namespace backbone::contact_bar {

class ContactBarOrbitProblem;

struct MonodromyOptions {
  // fronts: the isolated multipliers exactly, from the orbit's fronts (front_monodromy below);
  // grid: the projected full state on a grid, by differences (the rest of these options).
  enum class Representation { fronts, grid };
  Representation representation = Representation::fronts;
  int elements = 0;             // N of a uniform representation; 0: the problem's own nodes
  double relative_step = 1e-6;  // difference step: this times max(max|u0|, gap) for u, times
                                // c / L that for v
  double courant = 1.0 / 32;    // c dt / dx of the map at most (0.46 / 32^2 = 4.5e-4 in M's v
                                // columns)
  int threads = 1;
  // tangent: the march's tangent where it applies (above), differences elsewhere; differences:
  // always (the check of the tangent).
  enum class Derivatives { tangent, differences };
  Derivatives derivatives = Derivatives::tangent;
  void validate() const;  // InputError naming stability_elements / stability_step
};
MonodromyOptions::Representation parse_representation(const std::string& key,
                                                      const std::string& value);  // InputError

// The representation's nodes 0 = y_0 < ... < y_N = L: the uniform grid of `elements` intervals,
// or with elements = 0 the problem's own node grid at x (mapped by its free knots, so that a
// kink of u0 on a knot is held exactly).
std::vector<double> full_state_nodes(const ContactBarOrbitProblem& problem, const core::Vector& x,
                                     int elements);

// The state s of the orbit x on the nodes: u0 at y_1..y_N, v0 = 0 (size 2N).
core::Vector full_state(const ContactBarOrbitProblem& problem, const core::Vector& x,
                        const std::vector<double>& nodes);

// The time step of the map at period T (the rule above, dx the smallest interval).
double full_state_time_step(const ContactBarOrbitProblem& problem, double period,
                            const std::vector<double>& nodes, double courant);

// The period map of the representation at period T and time step dt: s -> [u(y_i, T) |
// P v(., T)], by the problem's bar solver on the node grid (TD-BEM or the exact solver; the
// FEM refuses other grids: EvalStatus failed, as when the simulation fails).
core::EvalStatus full_state_map(const ContactBarOrbitProblem& problem,
                                const std::vector<double>& nodes, double period, double dt,
                                const core::Vector& state, core::Vector& mapped);

// M at the orbit x (2N x 2N). EvalStatus failed, before any simulation, when the node grid has
// an interval under L / (64 N): the time step follows it, and the cost with it.
core::EvalStatus full_state_monodromy(const ContactBarOrbitProblem& problem, const core::Vector& x,
                                      const MonodromyOptions& options, core::Matrix& M);

// The isolated multipliers' matrix K of the orbit x (exact_bar/front_monodromy.hpp,
// README.md 'Stability'): the orbit simulated by the exact characteristics solver, its state
// taken at a time its end is free, K from the tangent over one period. Not ok (with the
// reason) when the orbit's fronts do not come back.
exact_bar::FrontMonodromy orbit_front_monodromy(const ContactBarOrbitProblem& problem,
                                                const core::Vector& x);

// K of the orbit x by the TD-BEM's own march (tdbem_fronts.hpp) at the problem's time step,
// from the same t0 as orbit_front_monodromy, so that the two K share their fronts' order. Not ok
// unless the problem's solver is the TD-BEM's event march.
TdbemFronts orbit_tdbem_front_monodromy(const ContactBarOrbitProblem& problem,
                                        const core::Vector& x);

// Per cluster of eigenvalues of K within 1e-4 |K| of each other, its size less its
// eigenvectors (singular values of K - mu I under 1e-8 |K|, mu the cluster's mean), summed: a
// positive defect is a Jordan block, along which a perturbation grows linearly in the number of
// periods. The widths: K carries the traced orbit's error e (1e-10), which splits a Jordan
// block of size 2 by sqrt(e) and leaves K - mu I a singular value of about e. mu: K's
// eigenvalues (front_eigenvalues); without them, -1 when they do not converge.
int jordan_defect(const Eigen::MatrixXd& K, const Eigen::VectorXcd& mu);
int jordan_defect(const Eigen::MatrixXd& K);

// The perturbed state of the check below: the orbit's state plus a random perturbation (u and
// v continuous and piecewise linear on `elements` uniform intervals, nodal values uniform in
// [-1, 1] times relative_size times max|u0|, u = v = 0 at x = 0), with the orbit's interior
// knots moved by up to relative_size L (at most a quarter of the orbit's neighbouring
// intervals: its fronts' shifts), and u(L) put on a wall it would cross, so that at a grazing
// one of the two signs keeps the end's value. A negative relative_size draws the opposite
// perturbation: every value and every knot's move the same with the other sign (the end's
// value on a wall aside). Empty when the state cannot hold the draw (a velocity with jumps), or
// for relative_size 0 or not finite, or elements < 1.
std::optional<bar::BarSetup> perturbed_setup(const bar::BarSetup& setup, double relative_size,
                                             int elements, unsigned seed);

// The check that needs no representation: perturbed_setup's state simulated by the exact
// characteristics solver for `periods` periods of T. At t = k T (k = 1..10, then growing by
// half, and the last) the distance to the orbit as a set is taken: min over tau of the distance
// of the two states (the larger of max_x |u - u_orbit(tau)| on 4 elements + 1 points and the
// largest |int_0^x (v - v_orbit(tau)) dx| / c, averaged over each of their cells, over max|u0|;
// a scan near tau = 0 and one over the whole period), so that the drift along the orbit of a
// perturbed energy (the trivial pair's Jordan block, linear in k) is not counted.
// A multiplier of modulus 1 + d in a direction the perturbation excites grows it like
// (1 + d)^k; without growth every excited multiplier has |mu| <= largest^(1 / periods)
// (README.md, section 'Stability'). On a kink of the period map (a grazing) the draw and its
// opposite lie on its two sides, to first order.
struct PerturbationGrowth {
  double initial = 0;  // distance at t = 0 (relative to max|u0|)
  double largest = 0;  // largest distance over the sampled k, over the initial one
  double last = 0;     // the distance at k = periods, over the initial one
  std::vector<std::pair<int, double>> history;  // (k, distance over the initial one)
  bool ok = false;
};
PerturbationGrowth perturbation_growth(const bar::BarSetup& setup, double period, int periods,
                                       double relative_size, int elements, unsigned seed);

}  // namespace backbone::contact_bar
