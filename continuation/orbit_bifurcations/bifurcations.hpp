// Bifurcations of periodic orbits along a traced branch, detected from the multipliers its
// points carry (BranchPoint::floquet, core/stability/floquet.hpp) and located on the branch
// (continuation/README.md, section 'Stability and bifurcations of orbits').
//
// Between two consecutive points whose stability is decided, a change in where the non-trivial
// multipliers leave the unit circle (core::OutsideCounts) is a bifurcation:
//   fold              a real multiplier crosses +1 (test: prod (mu - 1), a sign change);
//   period_doubling   a real multiplier crosses -1, or a conservative pair collides there
//                     (test: prod (mu + 1), a sign change);
//   torus             a complex pair leaves the circle (Neimark-Sacker; test: the largest
//                     complex |mu| less 1, a sign change; in a conservative problem a Krein
//                     collision, where the pair leaves from the circle and the test does not
//                     change sign: located by bisection on the count).
// A point between the two is corrected on the hyperplane through x_a + s (x_b - x_a) normal to
// x_b - x_a; s is found by the Illinois variant of regula falsi on the test where it changes
// sign, by bisection on the count elsewhere, until the bracket is below 1e-10 of the orbit's
// size (max(1, |x|), in the unknowns: the test's sign is noise closer than that) or the test is
// exactly 0. The multipliers are computed again at the located orbit.
//
// Grazing: a problem naming grazing observables (core::FloquetProblem::grazing_observables, an
// event speed that is 0 where the orbit meets a switching surface tangentially) has no
// saltation matrix at the grazing orbit, so the branch cannot reach it. When such an observable g
// falls towards 0 at the end of a branch that did not stop on its point budget (its smallest
// value on the branch, below half its largest, and falling), the problem's grazing problem
// (FloquetProblem::grazing_problem: the orbit with that event off whose extremum lies on the
// surface, a smooth system) is corrected from the branch's last point: the located grazing orbit
// itself. Its multipliers are reported from the branch's last point (on the impacting side they
// grow like 1 / g).
//
//   auto found = detect_orbit_bifurcations(problem, branch, *corrector, options.floquet,
//                                          [](const OrbitBifurcation& b) { print(b); });
//   bifurcation_table(found, branch.points.front().observables).write_csv(out /
//   "bifurcations.csv");
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "continuation/branch.hpp"
#include "core/io/table.hpp"
#include "core/problem.hpp"
#include "core/solvers/newton.hpp"
#include "core/stability/floquet.hpp"

namespace backbone::continuation {

struct OrbitBifurcation {
  std::string type;      // fold, period_doubling, torus, grazing
  int after_point = 0;   // between this point of the branch and the next (grazing: the last)
  bool located = false;  // the location converged (else x is the best bracket end)
  core::Vector x;        // the located orbit (problem's unknowns)
  core::Observables observables;
  core::Floquet floquet;   // recomputed at x (grazing: at the nearest corrected orbit)
  double test_value = 0;   // the test function at x (grazing: g, 0 by construction)
  int location_steps = 0;  // corrected points spent
};

// Detects and locates the bifurcations of branch (whose points carry multipliers), in order;
// on_found is called with each as soon as it is located. corrector solves the bordered systems.
std::vector<OrbitBifurcation> detect_orbit_bifurcations(
    const core::Problem& problem, const Branch& branch, core::Corrector& corrector,
    const core::FloquetOptions& floquet,
    const std::function<void(const OrbitBifurcation&)>& on_found = {});

// bifurcations.csv: type, the observables (template_point's names, then any other), stable,
// max_multiplier_modulus, then re and im of each multiplier (multiplier_K_re, multiplier_K_im by
// decreasing modulus), located (0/1), after_point, test_value, location_steps.
core::Table bifurcation_table(const std::vector<OrbitBifurcation>& found,
                              const core::Observables& template_point);

// One line for the progress output: type, the observables, the multipliers.
std::string bifurcation_line(const OrbitBifurcation& b);

}  // namespace backbone::continuation
