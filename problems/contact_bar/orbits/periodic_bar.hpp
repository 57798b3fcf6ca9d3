// Nonlinear modes of the contact bar as a shooting problem: periodic orbits that start at rest.
//
// The bar of a BarSetup template (fixed at x = 0, unilateral contact at x = L with gap g0) is
// released from rest (v0 = 0) from a piecewise-linear u0 and simulated by any bar::BarSolver
// (the TD-BEM by default, the exact characteristics oracle for validation). Unknowns, in the
// layout of core::PeriodicOrbitProblem:
//     x = [ u0(y_1) ... u0(y_N) | k_1 ... k_K | T ]
// u0 at the nodes y_1..y_N of the representation grid (y_0 = 0 is the fixed end, u0 = 0 there;
// with start_on_wall u0(y_N) = u0(L) = g0 is no unknown), then K = free_knots ordered knot
// positions (0 by default: y_i = i L / N, uniform), then the period. With K free knots the grid
// is mapped piecewise-linearly so that node knot_nodes[j] sits at k_j: a u0 with K kinks
// anywhere (mode 2: one; the subharmonic members: two; README.md, section 'Representability')
// is then held exactly, which a uniform grid only does to O(dx). Residual (M equations, sampled
// on the uniform snapshot grid of M elements, nodes 1..M):
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
#include <optional>
#include <string>
#include <vector>

#include "continuation/scaled_problem.hpp"
#include "core/orbits/periodic_orbit.hpp"
#include "core/stability/floquet.hpp"
#include "problems/bar/bar.hpp"
#include "problems/contact_bar/orbits/monodromy.hpp"

namespace backbone::contact_bar {

struct OrbitOptions {
  int elements = 20;            // N: u0 unknowns at nodes 1..N of the representation grid
  int free_knots = 0;           // K movable knots, kept ordered (0 < k_1 < ... < k_K < L): node
                                // knot_nodes[j] sits at k_j, the grid is mapped piecewise
                                // linearly between them. 0: uniform grid. A u0 with K kinks
                                // anywhere is then held exactly (README.md, 'Representability')
  int knot_node = 0;            // K = 1 only, when knot_nodes is empty: 1..N-1; 0 picks
                                // round(N / 3) (the crest of mode 2)
  std::vector<int> knot_nodes;  // K reference nodes, increasing in 1..N-1; empty: K = 1 uses
                                // knot_node, K >= 2 round(j N / (K + 1)), j = 1..K
  bool start_on_wall = false;   // u0(L) = g0 is not an unknown (N - 1 nodal unknowns): states
                                // that start in contact, e.g. the subharmonic members at the
                                // centre of a contact phase (README.md, 'Subharmonic continuum')
  int test_elements = 0;        // M: residual sampled on a uniform grid of M elements (M
                                // equations); 0: M = state size (square system).
                                // M > that: overdetermined but consistent (true orbits zero
                                // every test function), solved by least squares; the N
                                // projections of a square system have spurious roots that
                                // M >= 2N removes (test_periodic_bar.cpp,
                                // OversampledResidualHasNoSpuriousRoots)
  int steps_per_period = 2000;  // dt = T / steps_per_period; must be even
  double fixed_dt = 0;          // > 0: this dt instead (T/2 and T then fall between steps)
  // Path rows: equations appended after the M residual rows that pick a path on a manifold of
  // orbits (README.md, 'Subharmonic continuum'); ContactBarOrbitProblem::set_path_rows(false)
  // drops them, e.g. to measure the dimension of the periodicity residual alone.
  double fixed_energy = 0;   // > 0: (energy(x) - fixed_energy) / fixed_energy = 0
  double fixed_shape = -1;   // in [0, 1]: the subharmonic shape (first contact phase / total
                             // contact time) fixed, a linear row in the knots of the last two
                             // kinks, k_J-1 and k_J (needs start_on_wall, K >= J):
                             // 1 - k_J = shape (2 - (2J - 1) (k_J - k_J-1)) / J (knots in units
                             // of L; J = 2: knots 1 and 2), times L / g0 as the residual rows
  int subharmonic_mode = 2;  // J of the subharmonic members (even): their kinks are knots 1..J
  // Units that follow the orbit (continuation::LocalScale): above the gap, the unit of u0 in
  // continuation is the orbit's amplitude (its L2 norm over the bar), not g0, so that a step
  // is relative and the rank report's column scaling does not degrade as the amplitude grows
  // (problems/contact_bar/orbits/README.md, section 'Amplitude units'). false: g0 throughout.
  bool amplitude_units = false;
  // The Jacobian of the regular residual from the exact solution's tangent (README.md,
  // 'Exact Jacobian') instead of finite differences: for the exact solver and the TD-BEM's
  // event march (which reproduces the exact solution on these states), without path rows.
  bool exact_jacobian = false;
  // The same Jacobian from the TD-BEM march's own tangent (ContactBarOrbitProblem::
  // tdbem_jacobian) where it applies, else as exact_jacobian says.
  bool tdbem_jacobian = false;
  int path_rows() const { return (fixed_energy > 0 ? 1 : 0) + (fixed_shape >= 0 ? 1 : 0); }
  int nodal_unknowns() const { return elements - (start_on_wall ? 1 : 0); }
  int state_size() const { return nodal_unknowns() + free_knots; }
  void validate() const;  // throws core::InputError naming the field
};

class ContactBarOrbitProblem : public core::PeriodicOrbitProblem,
                               public continuation::LocalScale,
                               public core::FloquetProblem {
 public:
  // setup: material and ends (left fixed, right contact or free, no body force); its u0, v0
  // are ignored. The solver must outlive the problem. Throws core::InputError.
  ContactBarOrbitProblem(bar::BarSetup setup, const bar::BarSolver& solver, OrbitOptions options);
  // Same, sharing ownership of the solver (a driver that hands the problem away).
  ContactBarOrbitProblem(bar::BarSetup setup, std::shared_ptr<const bar::BarSolver> solver,
                         OrbitOptions options);

  std::string name() const override { return "contact_bar"; }
  // A copy sharing the (immutable, thread-safe) solver: the branch-point location's second core.
  std::unique_ptr<core::Problem> clone() const override {
    return std::make_unique<ContactBarOrbitProblem>(*this);
  }
  int state_size() const override { return options_.state_size(); }
  // M = test_elements (state_size() when 0).
  int num_equations() const override {
    return (options_.test_elements > 0 ? options_.test_elements : state_size()) +
           (path_rows_enabled_ ? options_.path_rows() : 0);
  }
  // Path rows on (default) or off: off, the residual is the periodicity residual F alone.
  void set_path_rows(bool enabled) { path_rows_enabled_ = enabled; }
  // A copy (same solver, options and formulation) with path rows off: F alone.
  ContactBarOrbitProblem without_path_rows() const;
  bool path_rows_enabled() const { return path_rows_enabled_; }
  // The subharmonic shape of x from the knots of its last two kinks (README.md, 'Subharmonic
  // continuum of mode J'): (1 - k_J) J / (2 - (2J - 1) (k_J - k_J-1)) with lengths in units of
  // L, J = options.subharmonic_mode. NaN with fewer than J knots.
  double subharmonic_shape(const core::Vector& x) const;
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
  // The smallest |u0'| over the segments of u0, over the rms slope s = sqrt(2E / (EA L)): 1 for
  // the modes and the subharmonic members (slopes +-s), below 1 for the families attached to
  // a mode, which end where it reaches 0 (README.md, 'Attached families: the law').
  double min_slope(const core::Vector& x) const;
  // period, frequency, energy, end_amplitude (= |u0(L)|), min_slope, plus knot (K = 1) or
  // knot_1..knot_K,
  // and shape with K >= 2 on the wall (the subharmonic members). (The contact structure of a member
  // costs an exact simulation: subharmonic.hpp adds it to branch.csv after the trace, not per
  // observable call.)
  core::Observables observables(const core::Vector& x) const override;
  // u_s for the u0 entries, L for a free knot, L/c for the period.
  core::Vector typical_scale() const override;
  // sqrt(dx / L) for the u0 entries (dx = L / N; the trapezoid rule's half weight at x = L),
  // 1 for a free knot and the period: a step is then |du0|_L2 / (u_s sqrt(L)) plus the period
  // change in L/c, the same at every N for the same change of the orbit.
  core::Vector step_weights() const override;
  // With options.amplitude_units: max(1, A / u_s) for the u0 entries, A = the L2 norm of u0
  // over the bar divided by sqrt(L) (the step_weights norm), 1 for knots and the period; ones
  // without. The unit of u0 is then max(u_s, A): the gap near grazing, the amplitude above.
  bool local_scale_enabled() const override { return options_.amplitude_units; }
  core::Vector local_scale_factor(const core::Vector& x) const override;
  // The same ratio for the M periodicity rows (in units of u_s: then of max(u_s, A)), 1 for
  // the path rows; empty without options.amplitude_units.
  core::Vector local_residual_factor(const core::Vector& x) const override;
  // Sparsity of the residual's Jacobian (problems/contact_bar/orbits/README.md, section 'Amplitude
  // units'), for the TD-BEM and exact solvers: row i depends on u0 only near the images of its test
  // support under x -> x +- c t (t = T/2 regular, T paper; reflected at both ends, open or closed:
  // contact instants and fronts travel on the same characteristics), widened by one test element
  // and, for the TD-BEM, one step c dt (its end histories are interpolated over a step). The period
  // and free-knot columns are dense, and for the paper formulation the columns at the source of
  // each contact release (found by one simulation at x). None (every column differenced) for
  // other solvers and with path rows (they are dense rows).
  std::optional<core::JacobianPattern> jacobian_pattern(const core::Vector& x) const override;
  // With options.exact_jacobian where it applies (exact_jacobian_applies), the Jacobian from
  // the exact solution's tangent; else finite differences (core::Problem).
  core::EvalStatus compute_jacobian(const core::Vector& x, core::Matrix& J) const override;
  bool exact_jacobian_applies() const;
  // The regular residual's Jacobian from the TD-BEM march's tangent (solver/tdbem.hpp,
  // 'Tangent'): its u0 columns are the march's derivative in the hats of the grid; its period
  // column is half the time derivative of the projected v at T/2, c^2 (u_x(L) psi_i(L) -
  // int u_x psi_i'), from the march's field (the march is exact on these states, so moving T
  // moves only the instant). For the TD-BEM's event march, the regular formulation, a uniform
  // grid (no free knots) not starting on the wall, without path rows; EvalStatus failed
  // otherwise.
  core::EvalStatus tdbem_jacobian(const core::Vector& x, core::Matrix& J) const;
  bool tdbem_jacobian_applies() const;
  // Where the Jacobian comes from, for the trace's header and summary.txt: "exact",
  // "differences", "differences (...)" saying why the exact one does not apply, or, when only
  // the path rows stand in the way, that F alone (rank reports, the atlas) takes the exact one.
  std::string jacobian_description() const override;
  // exact or tdbem applies (the regular formulation, no path rows).
  bool jacobian_exact() const override;
  // u_s: the gap g0 (1e-3 L when there is none); the residual is in these units.
  double displacement_scale() const;

  // Floquet multipliers (core::FloquetProblem; README.md, section 'Stability'), in the
  // representation of the monodromy options:
  //   fronts: K, the isolated multipliers exactly (monodromy.hpp, orbit_front_monodromy), one
  //   tangent simulation of one period; one trivial multiplier (the time shift; the energy's
  //   belongs to the continuum on the circle); bifurcations read from them;
  //   grid: the full state (u, v) on a grid, 2N x 2N, by differences of 4N simulations of one
  //   period. Two trivial multipliers (time shift and energy); the projection keeps the
  //   isolated multipliers from converging pointwise, so no bifurcation is read from them.
  core::EvalStatus monodromy(const core::Vector& x, core::Matrix& M) const override;
  core::FloquetStructure floquet_structure() const override;
  void set_monodromy_options(const MonodromyOptions& options) {
    options.validate();
    monodromy_options_ = options;
  }
  const MonodromyOptions& monodromy_options() const { return monodromy_options_; }

  // The initial displacement at x, as the solver sees it (knots at the node positions).
  bar::PiecewiseLinear initial_displacement(const core::Vector& x) const;
  // Its knots (x = 0, then the mapped nodes, the last exactly L) and values, unchecked.
  void u0_at_nodes(const core::Vector& x, std::vector<double>& knots,
                   std::vector<double>& values) const;
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
  // at b L, b = (1 + g0/(s L))/4, slope +-s, T = (1 + b) L / c; 'Mode J': J - 1 kinks on the
  // J - 1 free knots), sampled on the grid. Any mode >= 1.
  core::Vector contact_family_guess(int mode, double amplitude_ratio) const;
  // The subharmonic member of family.hpp at this energy and shape in (0, 1], T = 2 T_J
  // (J = options.subharmonic_mode); needs start_on_wall and K >= J free knots (its J kinks are
  // the first J knots). InputError.
  core::Vector subharmonic_guess(double energy, double shape) const;
  // Mode J of a clearance end at energy E (family.hpp, ClearanceMode): on the front wall
  // (start_on_wall), its J kinks on the J free knots, T of the closed form. InputError.
  core::Vector clearance_guess(int mode, double energy) const;
  // u0 at node i = 1..N (the wall position g0 at node N with start_on_wall).
  double node_value(const core::Vector& x, int i) const;
  // Index of knot j (0-based) in x.
  int knot_index(int j) const { return options_.nodal_unknowns() + j; }
  // The K reference nodes of the knots (options.knot_nodes or the automatic rule).
  std::vector<int> reference_knot_nodes() const;

  const bar::BarSetup& setup_template() const { return setup_; }
  const OrbitOptions& options() const { return options_; }
  const bar::BarSolver& solver() const { return solver_; }

 protected:
  core::EvalStatus compute_residual(const core::Vector& x, core::Vector& r) const override;
  // ok when x is a state the residual takes: a finite positive period, finite nodal values,
  // knots ordered inside (0, L), u0(L) on the admissible side of the walls.
  core::EvalStatus admissible(const core::Vector& x) const;
  template <class F>
  void for_each_mapped_node(F&& f) const;  // periodic_bar.cpp

 private:
  double gap() const;
  // The solver has the exact tangent: the exact one, or the TD-BEM's event march.
  bool exact_jacobian_applies_to_solver() const;
  std::string exact_description() const;  // jacobian_description() without tdbem
  core::Vector mode_guess(int mode, double ratio, core::Vector x) const;
  std::shared_ptr<const bar::BarSolver> owned_solver_;  // empty unless shared
  bar::BarSetup setup_;
  const bar::BarSolver& solver_;
  OrbitOptions options_;
  MonodromyOptions monodromy_options_;
  bool path_rows_enabled_ = true;
};

// Reference nodes for knots at the given positions (increasing, in (0, L)): the nearest nodes
// of the uniform grid of `elements` intervals, pushed apart to stay strictly increasing in
// 1..elements-1, so that the mapped grid starts nearly uniform (OrbitOptions::knot_nodes).
std::vector<int> nearest_knot_nodes(int elements, double length, const std::vector<double>& at);

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

// Closed forms of the contact family: problems/contact_bar/orbits/family.hpp (ContactFamily).

}  // namespace backbone::contact_bar
