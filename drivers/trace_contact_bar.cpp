// Registers the contact bar with `backbone trace`: branches mode1 and mode2, the nonlinear
// modes born from the linear modes omega_k = (2k-1) pi c / (2L) at grazing.
//
// The scene gives the bar (problems/contact_bar/scene.hpp: length, youngs_modulus, density,
// area, gap, contact, elements = the u0 grid); the keys below add the shooting setup. The
// start is the grazing-side orbit of the contact family (end amplitude (1 + start_offset) g0),
// not the sine of the linear mode: at grazing every initial condition is 4L/c-periodic and a
// nodal Newton from the sine lands on such a non-contact orbit (measured: T = 4L/c exactly).
// Mode 2 moves one knot with the physics (free_knots = 1, the crest of the tent) because its
// kink travels with T and a uniform grid holds it only to O(dx).
//
//   backbone trace problems/contact_bar/scenes/paper.ini --branch mode1 --out out/m1
//   backbone trace problems/contact_bar/scenes/paper.ini --branch mode1 --elements 20
//   backbone trace problems/contact_bar/scenes/paper.ini --branch mode2 --free_knots 0
#include <fmt/format.h>

#include <algorithm>
#include <memory>

#include "core/errors.hpp"
#include "core/table.hpp"
#include "drivers/trace_registry.hpp"
#include "problems/contact_bar/periodic_bar.hpp"
#include "problems/contact_bar/scene.hpp"
#include "problems/contact_bar/tdbem.hpp"
#include "problems/exact_bar/exact_bar_solver.hpp"

namespace {

using namespace backbone;
namespace po = boost::program_options;

po::options_description orbit_scene_keys() {
  po::options_description keys = contact_bar::scene_keys();
  po::options_description shooting("contact bar shooting");
  shooting.add_options()  //
      ("shooting_elements", po::value<long>()->default_value(20),
       "intervals of the u0 grid (0: the scene's elements). 20 holds modes 1 and 2 exactly "
       "(mode 2 with its free knot); at 100 mode 1 meets a continuum of other periodic orbits "
       "at end amplitude 2 g0 and follows it (measured; no branch-point detection yet), at "
       "~100x the cost per point")  //
      ("test_elements", po::value<long>()->default_value(-1),
       "elements of the grid the residual is sampled on (its equations): 0 = as many as "
       "unknowns (square), -1 = auto (2x the unknowns: overdetermined, consistent, no "
       "spurious roots; least-squares Newton, eigen only)")  //
      ("steps_per_period", po::value<long>()->default_value(40),
       "time steps per period, dt = T / steps_per_period (even; event contact is exact for "
       "piecewise-linear orbits at any dt <= L/c)")  //
      ("shooting_solver", po::value<std::string>()->default_value("tdbem"),
       "bar solver of the residual: tdbem or exact")  //
      ("start_offset", po::value<double>()->default_value(0.05),
       "first orbit: end amplitude (1 + start_offset) * gap, just inside contact")  //
      ("start_guess", po::value<std::string>()->default_value("contact_family"),
       "contact_family (exact piecewise-linear orbit) or linear_mode (sine, linear period)")  //
      ("free_knots", po::value<long>()->default_value(-1),
       "movable knots of the u0 grid: 0, 1, or -1 = auto (0 for mode1, 1 for mode2)")         //
      ("energy_max", po::value<double>()->default_value(1e-2), "stop above this energy [J]")  //
      ("max_points", po::value<long>()->default_value(1000),
       "points on the branch, first included")  //
      ("rank_check_every", po::value<long>()->default_value(1),
       "verified rank report every k points (0: never)")  //
      ("rank_threshold", po::value<double>()->default_value(1e-5),
       "rank report: singular values below this times the largest are candidate null "
       "directions. Measured along the paper scene's branches (branch.csv sigma_zero, "
       "sigma_kept): the forward-difference Jacobian's null value reaches 2.8e-6 (kinks of "
       "the contact map), the smallest kept one is 5.6e-5; verify decides")  //
      ("ds", po::value<double>()->default_value(2.0),
       "first step, dimensionless: Euclidean in u0 / gap, knot / L and T c / L")           //
      ("ds_max", po::value<double>()->default_value(2.0), "largest step (dimensionless)")  //
      ("newton_tolerance", po::value<double>()->default_value(1e-10),
       "||F||_inf to converge; F is in units of the gap, so this is relative to g0")  //
      ("return_tolerance", po::value<double>()->default_value(1e-6),
       "reject a converged point whose orbit, re-simulated over T by the exact oracle, misses "
       "u0 or v0 = 0 by more than this, relative to max|u0| (0: no check). Catches spurious "
       "roots of the projected residual");
  keys.add(shooting);
  return keys;
}

drivers::TraceSetup setup_contact_bar(const core::Scene& scene, const std::string& branch) {
  const int mode = branch == "mode2" ? 2 : 1;
  bar::BarSetup setup = contact_bar::bar_from_scene(scene);  // u0, v0: the orbit's own

  std::shared_ptr<const bar::BarSolver> solver;
  const std::string solver_name = scene.choice("shooting_solver", {"tdbem", "exact"});
  if (solver_name == "exact")
    solver = std::make_shared<exact_bar::ExactBarSolver>();
  else
    solver =
        std::make_shared<contact_bar::TdbemSolver>(contact_bar::contact_method_from_scene(scene));

  contact_bar::OrbitOptions options;
  const long shooting_elements = scene.integer("shooting_elements", 0);
  options.elements =
      static_cast<int>(shooting_elements > 0 ? shooting_elements : scene.integer("elements", 2));
  options.steps_per_period = static_cast<int>(scene.integer("steps_per_period", 2));
  const long knots = scene.integer("free_knots", -1);
  options.free_knots = knots < 0 ? (mode == 2 ? 1 : 0) : static_cast<int>(knots);
  const long test_elements = scene.integer("test_elements", -1);
  options.test_elements = static_cast<int>(
      test_elements < 0 ? 2 * (options.elements + options.free_knots) : test_elements);
  if (setup.right.type != bar::EndType::contact || !(setup.right.gap > 0))
    throw core::InputError("right_end",
                           "the contact-bar modes need right_end = contact and gap > 0");

  auto problem = std::make_unique<contact_bar::ContactBarOrbitProblem>(setup, solver, options);
  const double ratio = 1 + scene.positive("start_offset");
  const std::string guess = scene.choice("start_guess", {"contact_family", "linear_mode"});

  drivers::TraceSetup s;
  s.guess = guess == "linear_mode" ? problem->linear_mode_guess(mode, ratio)
                                   : problem->contact_family_guess(mode, ratio);
  // Energy grows along the family: the direction of the contact family's own tangent.
  s.direction = problem->contact_family_guess(mode, ratio * 1.01) -
                problem->contact_family_guess(mode, ratio);

  const contact_bar::ContactBarOrbitProblem* p = problem.get();
  const double return_tolerance = scene.non_negative("return_tolerance");
  if (return_tolerance > 0) {
    // Exact oracle sampled on 4x as many intervals as unknowns (finer than the default test
    // grid): a spurious root of the projected equations is not a root of these.
    const int check_elements = 4 * p->state_size();
    s.reject_point = [p, return_tolerance, check_elements](const core::Vector& x) {
      const exact_bar::ExactBarSolver oracle;
      const contact_bar::ReturnError e = contact_bar::return_error(*p, x, oracle, check_elements);
      if (e.worst() <= return_tolerance) return std::string();
      return fmt::format(
          "exact re-simulation misses the orbit by {:.2e} (u) / {:.2e} (v) > "
          "return_tolerance {:g}",
          e.displacement, e.velocity, return_tolerance);
    };
  }
  const bar::Material material = setup.material;
  const double gap = setup.right.gap;
  s.describe_point = [p, material, gap, mode](const continuation::BranchPoint& point) {
    const double energy = point.observable("energy");
    const double exact = mode == 1 ? contact_bar::mode1_frequency(material, gap, energy)
                                   : contact_bar::mode2_frequency(material, gap, energy);
    return fmt::format("closed-form rel err {:.2e}",
                       std::abs(point.observable("frequency") / exact - 1));
  };
  s.write_extra_outputs = [p, material, gap, mode](const std::filesystem::path& out,
                                                   const continuation::Branch& b) {
    // Per point: the closed form at the point's own energy and the exact-oracle return error.
    const exact_bar::ExactBarSolver oracle;
    core::Table check({"point", "energy", "frequency", "closed_form_frequency", "relative_error",
                       "return_error_u", "return_error_v", "node"});
    for (const auto& point : b.points) {
      const double energy = point.observable("energy");
      const double w = point.observable("frequency");
      const double exact = mode == 1 ? contact_bar::mode1_frequency(material, gap, energy)
                                     : contact_bar::mode2_frequency(material, gap, energy);
      const contact_bar::ReturnError re = contact_bar::return_error(*p, point.x, oracle);
      // Node of the mode: where u0 changes sign inside (0, L) (NaN for mode 1: none).
      const bar::PiecewiseLinear u0 = p->initial_displacement(point.x);
      double node = std::nan("");
      const auto& xs = u0.knots();
      const auto& ys = u0.values();
      for (std::size_t i = 2; i < xs.size(); ++i)
        if (ys[i - 1] > 0 && ys[i] <= 0) {
          node = xs[i - 1] + (xs[i] - xs[i - 1]) * ys[i - 1] / (ys[i - 1] - ys[i]);
          break;
        }
      check.add_row({static_cast<double>(point.index), energy, w, exact, std::abs(w / exact - 1),
                     re.displacement, re.velocity, node});
    }
    check.write_csv(out / "closed_form_check.csv");
  };
  s.problem = std::move(problem);
  return s;
}

}  // namespace

static const bool registered = drivers::register_trace_problem(
    {"contact_bar",
     "elastic bar fixed at x = 0, rigid wall at gap g0 beyond x = L (Signorini contact)",
     &orbit_scene_keys,
     {"mode1", "mode2"},
     setup_contact_bar});
