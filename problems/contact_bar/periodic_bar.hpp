// Nonlinear modes of the contact bar as a shooting problem: periodic orbits that start at rest.
//
// The bar of a BarSetup template (fixed at x = 0, unilateral contact at x = L with gap g0) is
// released from rest (v0 = 0) from a piecewise-linear u0 and simulated by any bar::BarSolver
// (the TD-BEM by default, the exact characteristics oracle for validation). Unknowns, in the
// layout of core::PeriodicOrbitProblem:
//     x = [ u0(y_1) ... u0(y_N) | k_1 ... k_K | T ]
// u0 at the nodes y_1..y_N of the representation grid (y_0 = 0 is the fixed end, u0 = 0 there),
// then K = free_knots movable knot positions (0 by default: y_i = i L / N, uniform), then the
// period. With one free knot the grid is mapped piecewise-linearly so that node knot_node sits
// at k_1: a u0 with one kink anywhere (mode 2; README.md, section 'Representability') is then
// held exactly, which a uniform grid only does to O(dx). Residual (N + K equations, sampled on
// the uniform snapshot grid of N + K elements, nodes 1..N+K):
//  - displacement_periodicity (paper): f_i = u0(x_i) - u(x_i, T)
//  - half_period_velocity (regular, default): r_i = (L / c) * int v(x, T/2) psi_i dx / int psi_i
//    i.e. the hat-weighted average of v at T/2 times the travel time L/c. The scale makes r a
//    displacement: for an error of amplitude a in u0, v ~ c a / L so r ~ a, the same order as
//    the paper's f, and both are compared against one absolute Newton tolerance.
// The time step is dt = T / steps_per_period (even, so T/2 is on the grid and the residual is
// smooth in T), or a fixed dt when fixed_dt > 0.
//
//   bar::BarSetup s; s.right = {bar::EndType::contact, 1e-3};      // paper scene
//   contact_bar::TdbemSolver tdbem(...);
//   contact_bar::OrbitOptions o; o.elements = 20; o.steps_per_period = 2000;
//   contact_bar::ContactBarOrbitProblem orbit(s, tdbem, o);
//   core::Vector x = orbit.contact_family_guess(1, 1.2);          // mode 1, |eps| = 1.2 g0 / L
//   auto newton = core::make_corrector("eigen", {});
//   newton->solve(orbit, x);                                       // x: [u0 | T]
//   double E = orbit.energy(x), w = orbit.frequency(x);
#pragma once

#include <algorithm>
#include <memory>
#include <string>

#include "core/periodic_orbit.hpp"
#include "problems/bar/bar.hpp"

namespace backbone::contact_bar {

struct OrbitOptions {
  int elements = 20;            // N: u0 unknowns at nodes 1..N of the representation grid
  int free_knots = 0;           // 0: uniform grid; 1: node knot_node moves (its position is
                                // an unknown)
  int knot_node = 0;            // 1..N-1; 0 picks round(N / 3) (the crest of mode 2)
  int test_elements = 0;        // M: residual sampled on a uniform grid of M elements (M
                                // equations); 0: M = elements + free_knots (square system).
                                // M > that: overdetermined but consistent (true orbits zero
                                // every test function), solved by least squares; the N
                                // projections of a square system have spurious roots that
                                // M >= 2N removes (measured, see trace_contact_bar.cpp)
  int steps_per_period = 2000;  // dt = T / steps_per_period; must be even
  double fixed_dt = 0;          // > 0: this dt instead (T/2 and T then fall between steps)
  void validate() const;        // throws core::InputError naming the field
};

class ContactBarOrbitProblem : public core::PeriodicOrbitProblem {
 public:
  // setup: material and ends (left fixed, right contact or free, no body force); its u0, v0
  // are ignored. The solver must outlive the problem. Throws core::InputError.
  ContactBarOrbitProblem(bar::BarSetup setup, const bar::BarSolver& solver, OrbitOptions options);
  // Same, sharing ownership of the solver (a driver that hands the problem away).
  ContactBarOrbitProblem(bar::BarSetup setup, std::shared_ptr<const bar::BarSolver> solver,
                         OrbitOptions options);

  std::string name() const override { return "contact_bar"; }
  int state_size() const override { return options_.elements + options_.free_knots; }
  // M = test_elements (state_size() when 0).
  int num_equations() const override {
    return options_.test_elements > 0 ? options_.test_elements : state_size();
  }
  // Potential energy of u0: 1/2 int EA u0_x^2 dx (v0 = 0), exact for piecewise-linear u0.
  double energy(const core::Vector& x) const override;
  // Node positions y_1..y_N of the representation grid at x (mapped when a knot is free),
  // then the knot positions themselves.
  core::Vector node_positions(const core::Vector& x) const;
  // Uniform positions y_i = i L / N, then the knot (reference) positions: for orbits.csv.
  core::Vector state_coordinates() const override;
  // orbits.csv rows: u0 at its actual knots, x = 0 and the mapped nodes (a free knot moves
  // them), so the written orbit is exactly the piecewise-linear u0 the residual simulated.
  void initial_state_samples(const core::Vector& x, core::Vector& coordinates,
                             core::Vector& values) const override;
  // period, frequency, energy, end_amplitude (= |u0(L)|), plus knot (free knot only).
  core::Observables observables(const core::Vector& x) const override;
  // u_s for the u0 entries, L for a free knot, L/c for the period.
  core::Vector typical_scale() const override;
  // sqrt(dx / L) for the u0 entries (dx = L / N; the trapezoid rule's half weight at x = L),
  // 1 for a free knot and the period: a step is then |du0|_L2 / (u_s sqrt(L)) plus the period
  // change in L/c, the same at every N for the same change of the orbit.
  core::Vector step_weights() const override;
  // u_s: the gap g0 (1e-3 L when there is none); the residual is in these units.
  double displacement_scale() const;

  // The initial displacement at x, as the solver sees it (knots at the node positions).
  bar::PiecewiseLinear initial_displacement(const core::Vector& x) const;
  // The full setup the residual simulates at x (template + u0, v0 = 0).
  bar::BarSetup setup_at(const core::Vector& x) const;
  // Time step used at period T.
  double time_step(double period) const;

  // Starting guesses, both at end amplitude |u0(L)| = amplitude_ratio * g0 (> 1: in contact).
  // linear_mode_guess: the sine of linear mode k, u0 = -A sin((2k-1) pi x / 2L) sign-adjusted
  // so that the end starts away from the wall, at the linear period 4L / ((2k-1) c).
  core::Vector linear_mode_guess(int mode, double amplitude_ratio) const;
  // contact_family_guess: the exact piecewise-linear orbit of the contact family (README.md
  // 'Mode 1': u0 = eps x, T = (3L + g0/|eps|)/c; 'Mode 2': a tent with its crest
  // at b L, b = (1 + g0/(s L))/4, slope +-s, T = (1 + b) L / c), sampled on the grid.
  core::Vector contact_family_guess(int mode, double amplitude_ratio) const;

  const bar::BarSetup& setup_template() const { return setup_; }
  const OrbitOptions& options() const { return options_; }
  const bar::BarSolver& solver() const { return solver_; }

 protected:
  core::EvalStatus compute_residual(const core::Vector& x, core::Vector& r) const override;

 private:
  int reference_knot_node() const;
  double gap() const;
  std::shared_ptr<const bar::BarSolver> owned_solver_;  // empty unless shared
  bar::BarSetup setup_;
  const bar::BarSolver& solver_;
  OrbitOptions options_;
};

// How far the orbit at x is from periodic, re-simulated over one period T by `oracle` (the
// exact solver for validation) and sampled on a uniform grid of `elements` intervals:
// displacement = max_i |u(x_i, T) - u0(x_i)| / max_i |u0(x_i)|, velocity = (L/c) max_i
// |hat-averaged v(x_i, T)| / max_i |u0(x_i)| (relative, like the acceptance criteria).
// NaN when the simulation fails.
struct ReturnError {
  double displacement = 0;
  double velocity = 0;
  double worst() const { return std::max(displacement, velocity); }
};
ReturnError return_error(const ContactBarOrbitProblem& problem, const core::Vector& x,
                         const bar::BarSolver& oracle, int elements = 1000);

// Closed forms of the contact family (c = sqrt(E/rho), EA, g0 from the setup), for tests and
// reports. Mode 1 (README.md 'Mode 1'): T = (3L + g0 sqrt(EA L / (2E))) / c above grazing
// E = EA g0^2 / (2L). Mode 2 (derived the same way from d'Alembert, see the .cpp): a tent
// u0 of slopes +-s with its crest at bL, T = (5L + g0 sqrt(EA L / (2E))) / (4c) above grazing
// E = EA (3 g0)^2 / (2L). Both return 2 pi / T, NaN below grazing.
double mode1_frequency(const bar::Material& material, double gap, double energy);
double mode2_frequency(const bar::Material& material, double gap, double energy);

}  // namespace backbone::contact_bar
