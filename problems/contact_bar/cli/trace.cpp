// The contact bar's trace branches (trace.hpp): modeJ for every J >= 1
// (the nonlinear modes born from the linear modes omega_k = (2k-1) pi c / (2L) at grazing),
// subharmonic and subharmonic_continuum (mode 2 over two periods: a 2D manifold of orbits,
// problems/contact_bar/orbits/README.md section 'Subharmonic continuum'),
// and `simulate` (simulate.hpp).
//
// The scene gives the bar (scene.hpp: length, youngs_modulus, density, area, gap, contact,
// elements = the u0 grid); trace_keys add the shooting setup. The start is the grazing-side
// orbit of the contact family (end amplitude (1 + start_offset) g0), not the sine of the
// linear mode: at grazing every initial condition is 4L/c-periodic and a nodal Newton from the
// sine lands on such a non-contact orbit, of period 4L/c. Mode 2 moves one knot
// with the physics (free_knots = 1, the crest of the tent) because its kink travels with T and
// a uniform grid holds it only to O(dx) (problems/contact_bar/orbits/README.md, section "Shooting
// on the bar").
//
//   backbone trace problems/contact_bar/scenes/paper.ini --branch mode1 --out out/m1
//   backbone trace problems/contact_bar/scenes/paper.ini --branch mode2 --free_knots 0
#include "problems/contact_bar/cli/trace.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>

#include "core/errors.hpp"
#include "core/io/scene.hpp"
#include "core/io/table.hpp"
#include "core/jacobians/finite_difference.hpp"
#include "problems/contact_bar/cli/simulate.hpp"
#include "problems/contact_bar/figures/modes.hpp"
#include "problems/contact_bar/orbits/attached_content.hpp"
#include "problems/contact_bar/orbits/family.hpp"
#include "problems/contact_bar/orbits/grazing_limits.hpp"
#include "problems/contact_bar/orbits/manifold.hpp"
#include "problems/contact_bar/orbits/monodromy.hpp"
#include "problems/contact_bar/orbits/periodic_bar.hpp"
#include "problems/contact_bar/orbits/subharmonic.hpp"
#include "problems/contact_bar/solver/scene.hpp"
#include "problems/contact_bar/solver/tdbem.hpp"
#include "problems/exact_bar/exact_bar_solver.hpp"
#include "problems/exact_bar/exact_solution.hpp"

namespace backbone::contact_bar {

namespace {

namespace po = boost::program_options;

po::options_description subharmonic_keys() {
  po::options_description keys("subharmonic branches (subharmonic, subharmonic_continuum)");
  keys.add_options()  //
      ("energy", po::value<double>()->default_value(0),
       "subharmonic_continuum: the energy of the members [J] (0: that of strain 5 g0 / L, "
       "EA L (5 g0 / L)^2 / 2)")  //
      ("shape", po::value<double>()->default_value(-1),
       "subharmonic shape in (0, 1] or -1 (first contact phase / total contact time; 1 and "
       "the limit 0 are the grazing limits, where shape 0 itself degenerates the two-knot "
       "chart; 0.5 is mode 2). subharmonic: the shape kept along the backbone (-1: 0.3); "
       "subharmonic_continuum: the first member (-1: 1, a grazing limit)")  //
      ("path_rows", po::value<bool>()->default_value(true),
       "subharmonic branches: append the row that picks the path (shape or energy); false "
       "leaves the periodicity residual F alone, whose solutions form a 2D manifold (for "
       "`backbone inspect`: trace needs the row)")  //
      ("dimension_check", po::value<bool>()->default_value(true),
       "subharmonic branches: replace branch.csv's dimension (that of F plus the path rows) by "
       "the verified dimension of the periodicity residual F alone at each point");
  return keys;
}

// J of a branch named modeJ (J >= 1, no leading zero), else 0.
int mode_number(const std::string& branch) {
  if (branch.size() < 5 || branch.rfind("mode", 0) != 0 || branch[4] == '0' || branch.size() > 9)
    return 0;
  for (std::size_t i = 4; i < branch.size(); ++i)
    if (branch[i] < '0' || branch[i] > '9') return 0;
  return std::stoi(branch.substr(4));
}

// The subharmonic branch names: subharmonic, subharmonic_continuum, subharmonic_manifold (mode 2)
// and the same with a mode number J >= 3 appended (subharmonic4, subharmonic_continuum4, ...).
// kind is empty for any other name; mode is J (odd J too: the setup refuses it, with the reason).
struct SubharmonicBranch {
  std::string kind;  // "subharmonic", "subharmonic_continuum" or "subharmonic_manifold"
  int mode = 0;
};

SubharmonicBranch subharmonic_branch(const std::string& branch) {
  for (const char* kind : {"subharmonic_continuum", "subharmonic_manifold", "subharmonic"}) {
    const std::string k = kind;
    if (branch.rfind(k, 0) != 0) continue;
    const std::string digits = branch.substr(k.size());
    if (digits.empty()) return {k, 2};
    if (digits.size() > 5 || digits[0] == '0' ||
        digits.find_first_not_of("0123456789") != std::string::npos)
      return {};
    const int mode = std::stoi(digits);
    return mode >= 3 ? SubharmonicBranch{k, mode} : SubharmonicBranch{};
  }
  return {};
}

// The monodromy's grid, difference step and threads (keys stability_elements, stability_step,
// threads); InputError naming the key.
MonodromyOptions monodromy_options(const core::Scene& scene) {
  MonodromyOptions o;
  o.representation =
      parse_representation("stability_representation", scene.text("stability_representation"));
  o.elements = static_cast<int>(scene.integer("stability_elements", 0, 2000));
  o.relative_step = scene.number("stability_step");
  o.courant = scene.number("stability_courant");
  o.threads = static_cast<int>(scene.integer("threads", 1, core::max_jacobian_threads));
  o.validate();
  return o;
}

po::options_description trace_keys() {
  po::options_description keys = contact_bar::scene_keys();
  po::options_description shooting("contact bar shooting");
  shooting.add_options()  //
      ("shooting_elements", po::value<long>()->default_value(20),
       "intervals of the u0 grid (>= 1; 0: the scene's elements). 20 holds modes 1 and 2 "
       "exactly (mode 2 with its free knot); finer grids resolve the families attached to "
       "mode 1 (detect_branch_points) and cost more per point (bench case mode1_scaling)")  //
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
      ("free_knots", po::value<long>()->default_value(-1),
       "movable knots of the u0 grid, kept ordered: K >= 0, or -1 = auto (one per kink of the "
       "branch's exact u0: J - 1 for modeJ, 2 for the subharmonic branches)")  //
      ("knot_nodes", po::value<std::string>()->default_value(""),
       "modes: the reference nodes of the free knots, increasing in 1..N-1, separated by spaces "
       "or commas (empty: nearest the kinks at the start; mode 2: round(N / 3)); the grid is "
       "mapped so that node knot_nodes[j] sits on knot j")                                    //
      ("energy_max", po::value<double>()->default_value(1e-2), "stop above this energy [J]")  //
      ("max_points", po::value<long>()->default_value(1000),
       "points on the branch, first included")  //
      ("rank_check_every", po::value<long>()->default_value(1),
       "verified rank report every k points (0: never)")  //
      ("rank_threshold", po::value<double>()->default_value(1e-5),
       "rank report: singular values below this times the largest, in (0, 1), are candidate "
       "null directions; it lies between the null and the smallest kept values of branch.csv "
       "(sigma_zero, sigma_kept); the probes verify each candidate")  //
      ("ds", po::value<double>()->default_value(0.45),
       "first step, dimensionless: the L2 norm of the change of u0 / gap over the bar "
       "(independent of the grid), knot / L and T c / L; mode1 and mode2 in amplitude units "
       "default to 0.1 (10 % of the amplitude)")  //
      ("ds_max", po::value<double>()->default_value(0.45),
       "largest step (dimensionless; mode1, mode2 in amplitude units: 0.1)")  //
      ("newton_tolerance", po::value<double>()->default_value(3e-9),
       "||F||_inf to converge (> 0); F is in units of the gap, so this is relative to g0 and "
       "stays above the residual's round-off, which grows with the amplitude. mode1 and mode2 "
       "in amplitude units (F relative to the amplitude above the gap) default to 1e-10")  //
      ("amplitude_units", po::value<bool>()->default_value(true),
       "mode1, mode2: above the gap, steps and rank reports in units of the orbit's amplitude "
       "(the L2 norm of u0) instead of the gap, so that ds is relative and a branch covers "
       "decades of energy (problems/contact_bar/orbits/README.md, section 'Amplitude units'); "
       "false: the gap throughout")  //
      ("max_residual_work", po::value<double>()->default_value(1e7),
       "refuse a trace whose residual costs more than this many element-steps "
       "(shooting_elements x steps_per_period; a point evaluates the residual about 2 x "
       "shooting_elements times): raise it to run larger traces")  //
      ("max_memory", po::value<double>()->default_value(0),
       "refuse a trace whose dense Jacobian and its factorizations would need more than this "
       "many GB (>= 0; 0: half of this machine's memory)")  //
      ("jacobian", po::value<std::string>()->default_value("exact"),
       "the shooting Jacobian: exact (from the exact solution's tangent: "
       "problems/contact_bar/orbits/README.md, section 'Exact Jacobian'; the regular formulation "
       "with the exact solver or the TD-BEM's event march, without path rows; else differences), "
       "tdbem (the TD-BEM march's own tangent, the same matrix: a uniform grid away from the "
       "wall, else as exact) or differences (finite differences, compressed by its pattern)")  //
      ("max_dense_work", po::value<double>()->default_value(2e10),
       "refuse a trace whose dense factorizations (the rank report's SVD of the m x n "
       "Jacobian, m n^2 operations) cost more than this (> 0; 2e10: about 2000 intervals, "
       "seconds per factorization on this machine class): raise it to run larger traces")  //
      ("stability", po::value<bool>()->default_value(false),
       "Floquet multipliers of every point (branch.csv's stability columns, multipliers.csv) "
       "in the stability_representation (problems/contact_bar/orbits/README.md, section "
       "'Stability')")  //
      ("stability_representation", po::value<std::string>()->default_value("fronts"),
       "fronts: the isolated multipliers exactly, from the orbit's fronts, one tangent "
       "simulation per point (fronts.csv beside the branch: K's checks and Jordan defect); "
       "grid: the projected full state (u, v) on a grid of stability_elements, from the TD-BEM "
       "march's tangent (central differences with another solver, contact projection or a "
       "state on the wall) "
       "(problems/contact_bar/orbits/README.md, 'Stability')")  //
      ("stability_tdbem_check", po::value<bool>()->default_value(false),
       "with stability_representation fronts: K also by central differences of the TD-BEM's "
       "own march (shooting_solver tdbem, contact event), two simulations of a period per front "
       "and point (steps 10 and 100 times smaller near a grazing); fronts.csv gains tdbem_ok "
       "(1: the TD-BEM's K was computed; no tolerance), tdbem_kink (largest difference of the "
       "two one-sided differences: of order 1 on a grazing, infinite where one side fails), "
       "tdbem_k_difference (largest |K_tdbem - K|, the nearest of the central and one-sided "
       "K_tdbem) and tdbem_multiplier_difference (problems/contact_bar/orbits/README.md, "
       "'Stability')")  //
      ("stability_growth_periods", po::value<long>()->default_value(1000),
       "with stability_representation fronts, at every point: the orbit plus a random "
       "perturbation (values 1e-6 of its amplitude, knots moved by up to 1e-6 L) and its "
       "opposite, marched by the exact solver over this many periods, in [0, 10000] (0: none; "
       "the march is kept whole: 10000 took 1.1 GB on the families at 40 intervals, 1000 "
       "0.09 GB): the check on a kink of the period map, where K is one side's. fronts.csv "
       "gains, the worse of the two draws each, growth_largest (the largest distance, u "
       "and v, to the orbit as a set over the initial one), growth_modulus (its periods-th "
       "root, a bound on every excited |mu|) and growth_power (the power of k that takes the "
       "largest distance up to the middle to the largest of all: 0 bounded, 1 a linear drift, "
       "about 3 for |mu| = 1.005 over 1000 periods) (problems/contact_bar/orbits/README.md, "
       "'Stability')")  //
      ("floquet_tolerance", po::value<double>()->default_value(1e-4),
       "a multiplier with |mu| > 1 + this is unstable, in (0, 0.1). 1e-4 for the fronts: a "
       "Jordan block of size 2 (modes J >= 2) turns K's error e, the traced orbit's 1e-10, "
       "into sqrt(e). With the grid representation pass 1e-2: its projection moves "
       "multipliers by up to 3e-3 off the circle on mode 1 at 40 intervals "
       "(problems/contact_bar/orbits/README.md, 'Stability')")  //
      ("floquet_trivial_tolerance", po::value<double>()->default_value(1e-4),
       "the trivial multipliers must lie within this of +1, else the point is undecided, in "
       "(0, 0.5); with the grid representation pass 1e-2")  //
      ("stability_elements", po::value<long>()->default_value(0),
       "intervals of a uniform (u, v) grid for the monodromy, in [0, 2000] (0: the shooting "
       "grid itself, mapped by its free knots); M is 2N x 2N, dense, from one march carrying "
       "2N directions or 4N simulations (max_stability_work bounds the latter's cost)")  //
      ("max_stability_work", po::value<double>()->default_value(1e10),
       "refuse a grid monodromy whose simulations cost more than this many element-steps per "
       "point (4 N simulations of N intervals over T at stability_courant: about 30 s per point "
       "at 1e10 on this machine class, near 270 intervals on the paper scene's mode 1)")  //
      ("stability_courant", po::value<double>()->default_value(1.0 / 32),
       "c dt / dx of the monodromy's simulations at most, in (0, 1]: the velocity columns of "
       "the monodromy carry an error of 0.46 (c dt / dx)^2")  //
      ("stability_step", po::value<double>()->default_value(1e-6),
       "difference step of the grid monodromy where the tangent does not apply, relative to the "
       "orbit's amplitude, in (0, 1e-2)")  //
      ("return_tolerance", po::value<double>()->default_value(1e-6),
       "reject a converged point whose orbit, re-simulated over T by the exact oracle, misses "
       "u0 or v0 = 0 by more than this, relative to max|u0| (0: no check). Catches spurious "
       "roots of the projected residual");
  keys.add(shooting);
  keys.add(subharmonic_keys());
  keys.add(manifold_keys());
  return keys;
}

cli::TraceSetup setup_subharmonic(const core::Scene& scene, const std::string& branch);

// The run's size against max_residual_work, before anything runs (simulate's max_steps habit):
// one residual marches about elements x steps_per_period element-steps
// (problems/contact_bar/orbits/README.md, section 'Amplitude units').
void check_residual_work(const core::Scene& scene, const OrbitOptions& options) {
  const double limit = scene.positive("max_residual_work");
  const double work = static_cast<double>(options.elements) * options.steps_per_period;
  if (work <= limit) return;
  const bool steps = options.steps_per_period >= options.elements;
  throw core::InputError(
      steps ? "steps_per_period" : "shooting_elements",
      fmt::format("shooting_elements x steps_per_period = {} x {} = {:.4g} element-steps per "
                  "residual > max_residual_work {:.4g}; lower {} or raise max_residual_work",
                  options.elements, options.steps_per_period, work, limit,
                  steps ? "steps_per_period" : "shooting_elements"));
}

// The ends a contact-bar orbit needs, named by their scene keys: left_end fixed, right_end
// contact (or clearance, where allowed) with gap > 0.
void check_orbit_ends(const bar::BarSetup& setup, const std::string& what,
                      bool clearance_too = false) {
  if (setup.left.type != bar::EndType::fixed)
    throw core::InputError("left_end", fmt::format("{} need a fixed left end (got {})", what,
                                                   bar::to_string(setup.left.type)));
  if (setup.right.type != bar::EndType::contact &&
      !(clearance_too && setup.right.type == bar::EndType::clearance))
    throw core::InputError("right_end", fmt::format("{} need right_end = contact{} (got {})", what,
                                                    clearance_too ? " or clearance" : "",
                                                    bar::to_string(setup.right.type)));
  if (!(setup.right.gap > 0))
    throw core::InputError("gap",
                           fmt::format("{} need a gap > 0 (got {:g})", what, setup.right.gap));
}

// The scene's simulation keys (u0, v0, period, dt, probes) fit the bar, so that the scene.ini a
// trace writes reruns as `backbone simulate` too.
void check_simulation_keys(const core::Scene& scene) {
  const bar::BarSetup setup = setup_from_scene(scene);
  const bar::SimulationOptions simulation = simulation_from_scene(scene, 1.0);
  const double transit = setup.material.travel_time();
  if (simulation.dt > transit * (1 + 1e-12))
    throw core::InputError("dt", fmt::format("must be <= length / wave_speed = {:g} s (got {:g}): "
                                             "one step of a simulation may not cross the bar",
                                             transit, simulation.dt));
}

// dt = T / steps_per_period must not exceed the bar's travel time L / c, the largest step of
// the TD-BEM march; checked at the starting orbit's period.
void check_time_step(const bar::Material& material, double period, int steps_per_period) {
  const double dt = period / steps_per_period, transit = material.travel_time();
  if (dt <= transit * (1 + 1e-12)) return;
  throw core::InputError(
      "steps_per_period",
      fmt::format("{} steps over the starting period {:.6g} s give dt = {:.4g} s > L/c = "
                  "{:.4g} s, the largest step of the TD-BEM march; use at least {} (even)",
                  steps_per_period, period, dt, transit,
                  2 * static_cast<long>(std::ceil(period / transit / 2))));
}

// max_memory in GB (0: half of this machine's memory), and the words that say which.
std::pair<double, std::string> memory_limit(const core::Scene& scene) {
  const double given = scene.non_negative("max_memory");
  if (given > 0) return {given, ""};
  const double physical =
      static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGESIZE));
  return {physical / 2 / 1e9, " (half of this machine's memory)"};
}

// The memory a trace needs before it starts: the corrector and the rank report hold about nine
// copies of the dense m x n Jacobian (J, its QR or COD, the bordered system, the SVD's
// workspace), so a grid whose copies do not fit is refused up front (key max_memory).
void check_memory(const core::Scene& scene, const OrbitOptions& options) {
  const auto [limit_gb, limit_origin] = memory_limit(scene);
  const double equations = options.test_elements > 0 ? options.test_elements : options.state_size();
  const double unknowns = options.state_size() + 1.0;
  const double need_gb = 9 * equations * unknowns * sizeof(double) / 1e9;
  // Time, before any work: one dense SVD of the Jacobian per rank report (3000 intervals:
  // 5.4e10 operations, measured 6.4 s at the first point alone).
  const double dense_limit = scene.positive("max_dense_work");
  const double dense_work = equations * unknowns * unknowns;
  if (dense_work > dense_limit)
    throw core::InputError(
        "shooting_elements",
        fmt::format("{} intervals make a {:.0f} x {:.0f} Jacobian, whose dense factorizations "
                    "cost {:.3g} operations each, above max_dense_work {:.3g}: lower "
                    "shooting_elements, or raise max_dense_work",
                    options.elements, equations, unknowns, dense_work, dense_limit));
  if (need_gb <= limit_gb) return;
  throw core::InputError(
      "shooting_elements",
      fmt::format("{} intervals make a {:.0f} x {:.0f} Jacobian; the corrector and the rank "
                  "reports need about {:.3g} GB, above max_memory {:.3g} GB{}: lower "
                  "shooting_elements (or test_elements), or raise max_memory",
                  options.elements, equations, unknowns, need_gb, limit_gb, limit_origin));
}

// The shooting grid of the scene: shooting_elements (0: the scene's elements) and
// steps_per_period, checked against max_residual_work.
OrbitOptions shooting_grid(const core::Scene& scene) {
  OrbitOptions options;
  const long shooting_elements = scene.integer("shooting_elements", 0);
  if (shooting_elements != 0 && shooting_elements < 2)
    throw core::InputError(
        "shooting_elements",
        fmt::format("must be >= 2, or 0 for the scene's elements (got {})", shooting_elements));
  options.elements =
      static_cast<int>(shooting_elements > 0 ? shooting_elements : scene.integer("elements", 2));
  options.steps_per_period = static_cast<int>(scene.integer("steps_per_period", 2));
  const std::string jacobian = scene.choice("jacobian", {"differences", "exact", "tdbem"});
  options.exact_jacobian = jacobian != "differences";
  options.tdbem_jacobian = jacobian == "tdbem";
  check_residual_work(scene, options);
  return options;
}

std::shared_ptr<const bar::BarSolver> shooting_solver(const core::Scene& scene) {
  if (scene.choice("shooting_solver", {"tdbem", "exact"}) == "exact")
    return std::make_shared<exact_bar::ExactBarSolver>();
  return std::make_shared<TdbemSolver>(contact_method_from_scene(scene));
}

// The reject_point hook of return_tolerance > 0: a converged point whose orbit, re-simulated by
// the exact oracle on check_elements intervals, misses its start by more than the tolerance.
// None for return_tolerance 0.
std::function<std::string(const core::Vector&)> return_check(const core::Scene& scene,
                                                             const ContactBarOrbitProblem* p,
                                                             int check_elements) {
  const double return_tolerance = scene.non_negative("return_tolerance");
  if (!(return_tolerance > 0)) return {};
  return [p, return_tolerance, check_elements](const core::Vector& x) {
    const exact_bar::ExactBarSolver oracle;
    const ReturnError e = return_error(*p, x, oracle, check_elements);
    if (e.worst() <= return_tolerance) return std::string();
    return fmt::format(
        "exact re-simulation misses the orbit by {:.2e} (u) / {:.2e} (v) > "
        "return_tolerance {:g}",
        e.displacement, e.velocity, return_tolerance);
  };
}

// The scene's knot_nodes, when given, replace options.knot_nodes: one node per free knot,
// increasing in 1..N-1.
void knot_nodes_from_scene(const core::Scene& scene, OrbitOptions& options) {
  const std::string nodes = scene.text("knot_nodes");
  if (nodes.empty()) return;
  options.knot_nodes =
      core::parse_increasing_integers(nodes, "knot_nodes", 1, options.elements - 1, "a node");
  if (static_cast<int>(options.knot_nodes.size()) != options.free_knots)
    throw core::InputError(
        "knot_nodes", fmt::format("needs one node per free knot ({}; got {})", options.free_knots,
                                  options.knot_nodes.size()));
}

// describe_point of a mode: its frequency against the closed form at the point's own energy.
std::function<std::string(const continuation::BranchPoint&)> closed_form_error(
    std::function<double(double)> frequency) {
  return [frequency](const continuation::BranchPoint& point) {
    const double exact = frequency(point.observable("energy"));
    return fmt::format("closed-form rel err {:.2e}",
                       std::abs(point.observable("frequency") / exact - 1));
  };
}

// The reject_point hook of a mode: a point whose orbit never reaches the wall is refused before
// the return check. Below or near grazing the bar's non-contact orbits (every state is
// 4L/c-periodic) form a manifold of dimension N beside the mode, and on fine grids a corrector
// can land there (energy above grazing, end amplitude below the gap, period 4L/c): such an orbit
// is periodic, so the return check alone passes it. The exact oracle says whether the end closes
// on a wall at least once over the period.
std::function<std::string(const core::Vector&)> mode_check(const core::Scene& scene,
                                                           const ContactBarOrbitProblem* p,
                                                           int check_elements) {
  auto returns = return_check(scene, p, check_elements);
  return [p, returns](const core::Vector& x) {
    const double period = x[p->period_index()];
    const exact_bar::ExactBarSolution sol(p->setup_at(x), period);
    if (sol.ok() && sol.contact_intervals(exact_bar::Side::right).empty())
      return fmt::format(
          "the orbit never reaches the wall (period {:.6g} s): a non-contact "
          "orbit beside the mode, not a member of it",
          period);
    return returns ? returns(x) : std::string();
  };
}

// mode1 and mode2 in units of the amplitude: a step ds is a relative change of the orbit and
// F's round-off is relative too (problems/contact_bar/orbits/README.md, section 'Amplitude units'),
// so the defaults become 10 % steps, which give a branch enough points for the figures, and a
// tolerance of 1e-10 of the amplitude, above that round-off. Keys the scene gives are kept.
std::function<void(continuation::ContinuationOptions&, core::NewtonOptions&)>
amplitude_unit_options(const core::Scene& scene) {
  const bool ds_given = !scene.values()["ds"].defaulted();
  const bool ds_max_given = !scene.values()["ds_max"].defaulted();
  const bool tolerance_given = !scene.values()["newton_tolerance"].defaulted();
  return [=](continuation::ContinuationOptions& o, core::NewtonOptions& newton) {
    if (!ds_max_given) o.ds_max = 0.1;
    if (!ds_given) o.ds = std::min(0.1, o.ds_max);
    if (!tolerance_given) newton.residual_tolerance = 1e-10;
  };
}

// What a mode's trace reports besides the branch: the attached content of its branch points,
// each point's closed-form error, and closed_form_check.csv.
void describe_mode(cli::TraceSetup& s, const ContactBarOrbitProblem* p,
                   const ContactFamily& family) {
  // Branch points: the frequency ratio of the attached orbit's extra end content, measured
  // from exact re-simulations of both orbits (attached_content.hpp).
  s.describe_branch_point = [p](const core::Vector& on_branch, const core::Vector& attached) {
    const AttachedContent c =
        attached_content(*p, on_branch, attached, exact_bar::ExactBarSolver());
    return core::Observables{{"frequency_ratio", c.frequency_ratio},
                             {"oscillations_per_period", c.oscillations_per_period},
                             {"content_wavenumber", c.content_wavenumber},
                             {"resonance_order", c.resonance_order}};
  };
  s.describe_point = closed_form_error([family](double e) { return family.frequency(e); });
  s.write_extra_outputs = [p, family](const std::filesystem::path& out,
                                      const continuation::Branch& b) {
    // Per point: the closed form at the point's own energy, the exact-oracle return error and
    // the node (where u0 changes sign; NaN for mode 1, which has none).
    const exact_bar::ExactBarSolver oracle;
    core::Table check({"point", "energy", "frequency", "closed_form_frequency", "relative_error",
                       "return_error_u", "return_error_v", "node"});
    for (const auto& point : b.points) {
      const double energy = point.observable("energy");
      const double w = point.observable("frequency");
      const double exact = family.frequency(energy);
      const ReturnError re = return_error(*p, point.x, oracle);
      check.add_row({static_cast<double>(point.index), energy, w, exact, std::abs(w / exact - 1),
                     re.displacement, re.velocity, node_of(p->initial_displacement(point.x))});
    }
    check.write_csv(out / "closed_form_check.csv");
  };
}

// Mode J of a clearance end (problems/contact_bar/orbits/README.md, 'Modes in a clearance'):
// started on the front wall at the centre of a contact phase (start_on_wall), its J kinks on J
// free knots: the first J - 1 on the nodes nearest them at the start, the last (nearest the
// end, at L - C/2 with C the front phase) on node N - 1, since C vanishes at grazing. The first
// orbit has strain (1 + start_offset) times the grazing strain (2J - 1) g / L.
cli::TraceSetup setup_clearance_mode(const core::Scene& scene, const bar::BarSetup& setup,
                                     int mode) {
  const ClearanceMode family(setup.material, setup.right.gap, setup.right.gap_back, mode);
  if (scene.text("follow") != "none")
    throw core::InputError("follow",
                           "the clearance modes are traced without attached families "
                           "(follow = none)");
  OrbitOptions options = shooting_grid(scene);
  options.start_on_wall = true;
  const long knots = scene.integer("free_knots", -1);
  if (knots >= 0 && knots != mode)
    throw core::InputError("free_knots", fmt::format("clearance mode {} has {} kinks, one per "
                                                     "knot: {} or -1 (got {})",
                                                     mode, mode, mode, knots));
  options.free_knots = mode;
  if (options.elements < 2 * mode + 1)
    throw core::InputError("shooting_elements",
                           fmt::format("clearance mode {} needs at least {} intervals (got {})",
                                       mode, 2 * mode + 1, options.elements));
  const double length = setup.material.length;
  const double strain =
      (1 + scene.positive("start_offset")) * (2 * mode - 1) * setup.right.gap / length;
  const double start_energy = 0.5 * setup.material.axial_stiffness() * length * strain * strain;
  std::vector<double> kinks = family.kinks(start_energy);
  kinks.back() = length;  // its node: N - 1; the others below it, strictly increasing
  options.knot_nodes = nearest_knot_nodes(options.elements, length, kinks);
  for (int j = mode - 1; j >= 0; --j)
    options.knot_nodes[j] =
        std::min(options.knot_nodes[j],
                 j == mode - 1 ? options.elements - 1 : options.knot_nodes[j + 1] - 1);
  knot_nodes_from_scene(scene, options);
  const long test_elements = scene.integer("test_elements", -1);
  options.test_elements =
      static_cast<int>(test_elements < 0 ? 2 * options.state_size() : test_elements);
  check_memory(scene, options);
  options.amplitude_units = scene.flag("amplitude_units");

  auto problem = std::make_unique<ContactBarOrbitProblem>(setup, shooting_solver(scene), options);
  problem->set_monodromy_options(monodromy_options(scene));
  cli::TraceSetup s;
  // Where the back wall joins (gap_back > gap) the branch has a corner: u0(E) stays the same
  // family of tents while T(E) changes slope, so every step across it turns by the corner's
  // angle (35 degrees for mode 1 at 20 intervals). The turn check is raised to 60 degrees
  // unless the scene gives it; each point is still checked by the exact oracle.
  const bool turn_given = !scene.values()["max_turn_degrees"].defaulted();
  const auto units = options.amplitude_units ? amplitude_unit_options(scene) : nullptr;
  s.branch_options = [units, turn_given](continuation::ContinuationOptions& o,
                                         core::NewtonOptions& newton) {
    if (units) units(o, newton);
    if (!turn_given) o.branch_points.max_turn_degrees = 60;
  };
  s.guess = problem->clearance_guess(mode, start_energy);
  check_time_step(setup.material, s.guess[problem->period_index()], options.steps_per_period);
  s.direction = problem->clearance_guess(mode, start_energy * 1.02) - s.guess;
  s.reject_point = mode_check(scene, problem.get(), 4 * problem->state_size());
  s.describe_point = closed_form_error([family](double e) { return family.frequency(e); });
  const ContactBarOrbitProblem* p = problem.get();
  s.write_extra_outputs = [p, family](const std::filesystem::path& out,
                                      const continuation::Branch& b) {
    // Per point: the closed form at the point's own energy, the exact-oracle return error and
    // the contact phases on each wall with their durations, from an exact simulation.
    const exact_bar::ExactBarSolver oracle;
    core::Table check({"point", "energy", "frequency", "closed_form_frequency", "relative_error",
                       "return_error_u", "return_error_v", "front_phases", "back_phases",
                       "front_contact", "closed_form_front_contact", "back_contact",
                       "closed_form_back_contact", "min_back_gap", "one_sided_relative_error"});
    // Mode J of the one-sided bar (the back wall removed): where no orbit reaches the back
    // wall the two must agree.
    const ContactFamily one_sided(p->setup_template().material, p->setup_template().right.gap,
                                  family.mode());
    for (const auto& point : b.points) {
      const double energy = point.observable("energy");
      const double w = point.observable("frequency");
      const double exact = family.frequency(energy);
      const ReturnError re = return_error(*p, point.x, oracle);
      const double period = point.x[p->period_index()];
      const ContactStructure cs = contact_structure(p->setup_at(point.x), period);
      check.add_row({static_cast<double>(point.index), energy, w, exact, std::abs(w / exact - 1),
                     re.displacement, re.velocity, static_cast<double>(cs.contact_phases),
                     static_cast<double>(cs.back_contact_phases), cs.contact_time,
                     family.front_contact(energy), cs.back_contact_time,
                     family.back_contact(energy), cs.min_back_gap,
                     std::abs(w / one_sided.frequency(energy) - 1)});
    }
    check.write_csv(out / "closed_form_check.csv");
  };
  s.problem = std::move(problem);
  return s;
}

cli::TraceSetup setup_trace(const core::Scene& scene, const std::string& branch) {
  if (!subharmonic_branch(branch).kind.empty()) return setup_subharmonic(scene, branch);
  // A subharmonic key given to a mode would be ignored in silence.
  const po::options_description subharmonic = subharmonic_keys();
  for (const auto& option : subharmonic.options()) {
    const std::string& key = option->long_name();
    if (scene.has(key) && !scene.values()[key].defaulted())
      throw core::InputError(key, fmt::format("applies to the subharmonic branches only (this "
                                              "trace follows {})",
                                              branch));
  }
  const int mode = mode_number(branch);
  bar::BarSetup setup = bar_from_scene(scene);  // u0, v0: the orbit's own
  check_orbit_ends(setup, "the contact-bar modes", true);
  check_simulation_keys(scene);
  if (setup.right.type == bar::EndType::clearance) return setup_clearance_mode(scene, setup, mode);
  const ContactFamily family(setup.material, setup.right.gap, mode);
  const std::shared_ptr<const bar::BarSolver> solver = shooting_solver(scene);

  OrbitOptions options = shooting_grid(scene);
  const long knots = scene.integer("free_knots", -1);
  options.free_knots = knots < 0 ? mode - 1 : static_cast<int>(knots);
  if (mode >= 3) {
    // J - 1 kinks, each on a free knot whose reference node is the nearest to it at the start
    // (README.md of orbits/, 'Mode J'); segments of at least L / J need two intervals each.
    if (options.elements < 2 * mode)
      throw core::InputError("shooting_elements",
                             fmt::format("mode {} needs at least {} intervals (got {})", mode,
                                         2 * mode, options.elements));
    if (options.free_knots == mode - 1) {
      const double s0 = (mode * (1 + scene.positive("start_offset")) + mode - 1) * setup.right.gap /
                        setup.material.length;
      options.knot_nodes = nearest_knot_nodes(
          options.elements, setup.material.length,
          family.kinks(0.5 * setup.material.axial_stiffness() * setup.material.length * s0 * s0));
    }
  }
  knot_nodes_from_scene(scene, options);
  const long test_elements = scene.integer("test_elements", -1);
  options.test_elements = static_cast<int>(
      test_elements < 0 ? 2 * (options.elements + options.free_knots) : test_elements);
  check_memory(scene, options);
  // A followed family's probes and paths are measured in units of the gap: with follow the gap
  // stays the unit. (Branch-point detection works in either: its samples are kept in the unit
  // scale, continuation/README.md, section 'Branch points'.)
  options.amplitude_units = scene.flag("amplitude_units") && scene.text("follow") == "none";

  auto problem = std::make_unique<ContactBarOrbitProblem>(setup, solver, options);
  problem->set_monodromy_options(monodromy_options(scene));
  const double ratio = 1 + scene.positive("start_offset");

  cli::TraceSetup s;
  if (options.amplitude_units) s.branch_options = amplitude_unit_options(scene);
  // A followed family attached to the mode is a family of warps of the mode's u0, bounded by
  // the warps whose slope vanishes on an interval (orbits/README.md, 'Attached families: the
  // law'). A path that stalls there has reached the family's boundary: a planned end.
  if (scene.text("follow") != "none")
    s.branch_options = [](continuation::ContinuationOptions& o, core::NewtonOptions&) {
      o.boundary = {"min_slope", 1e-3};
    };
  s.guess = problem->contact_family_guess(mode, ratio);
  check_time_step(setup.material, s.guess[problem->period_index()], options.steps_per_period);
  // Energy grows along the family: the direction of the contact family's own tangent, which the
  // first step follows (start_along_direction). The first orbit may sit on a branch point (end
  // amplitude 1.25 g0 is T = 3.8 L/c), where the Jacobian's null space holds the attached
  // family too.
  s.direction = problem->contact_family_guess(mode, ratio * 1.01) -
                problem->contact_family_guess(mode, ratio);
  s.branch_options = [given = s.branch_options](continuation::ContinuationOptions& o,
                                                core::NewtonOptions& newton) {
    if (given) given(o, newton);
    o.start_along_direction = true;
  };
  // Exact oracle sampled on 4x as many intervals as unknowns (finer than the default test
  // grid): a spurious root of the projected equations is not a root of these.
  s.reject_point = mode_check(scene, problem.get(), 4 * problem->state_size());
  describe_mode(s, problem.get(), family);
  s.problem = std::move(problem);
  return s;
}

// The continuum's own continuation settings (problems/contact_bar/orbits/README.md, section
// 'Subharmonic continuum'):
//  - the first step along the closed-form direction (start_along_direction);
//  - ds = ds_max = 1/40 of the closed-form path length in the scaled step norm, so every
//    energy has about 40 members (the path grows like sqrt(E) / g0 in that norm), unless the
//    scene gives ds or ds_max;
//  - a window on the shape from shape_end = 1e-6 L / (D L) (D L: the members' kink range,
//    (1 - 3b) L for mode 2) to 1 (to 1 - shape_end when the branch goes up from a first member
//    below 1/2): the shape-0 limit has
//    its second kink at x = L, where the two-knot chart degenerates (the forward-difference
//    step of the last knot, 1.5e-8 L, crosses L once L - k2 is smaller), so the branch lands
//    on the member with L - k2 = 1e-6 L, whose contact phase at t = 0 lasts 2e-6 L / c, and
//    ends there with bound_reached (a complete branch; the limit itself: grazing_limits.hpp).
std::function<void(continuation::ContinuationOptions&, core::NewtonOptions&)> continuum_options(
    const core::Scene& scene, const ContactBarOrbitProblem& problem, double energy, double shape,
    double toward) {
  const bar::Material& material = problem.setup_template().material;
  const double g0 = problem.displacement_scale();
  // 1e-6 L of kink travel over D L: the two contact phases of a member last 2 D L / c together.
  const SubharmonicMember middle =
      subharmonic_member(material, g0, energy, 0.5, problem.options().subharmonic_mode);
  const double shape_end = 1e-6 * 2 * material.length /
                           ((middle.first_contact + middle.second_contact) * material.wave_speed());
  // The closed-form path length from `shape` to the end, in the loop's scaled unknowns: 40
  // steps to twice shape_end, so that no planned member falls on the bound itself (a member on
  // it leaves no landing ahead of it).
  const core::Vector scale =
      problem.typical_scale().cwiseAbs().cwiseQuotient(problem.step_weights());
  const double last = toward < 0 ? 2 * shape_end : 1 - 2 * shape_end;
  double length = 0;
  core::Vector previous = problem.subharmonic_guess(energy, shape).cwiseQuotient(scale);
  const int samples = 200;
  for (int i = 1; i <= samples; ++i) {
    const core::Vector z = problem.subharmonic_guess(energy, shape + (last - shape) * i / samples)
                               .cwiseQuotient(scale);
    length += (z - previous).norm();
    previous = z;
  }
  const bool ds_given = !scene.values()["ds"].defaulted();
  const bool ds_max_given = !scene.values()["ds_max"].defaulted();
  return [=](continuation::ContinuationOptions& options, core::NewtonOptions&) {
    options.start_along_direction = true;
    const double step = length / 40;
    if (!ds_given) options.ds = ds_max_given ? std::min(step, options.ds_max) : step;
    if (!ds_max_given) options.ds_max = std::max(step, options.ds);
    // Upwards (a first member below 1/2) the curve ends at the limit shape 1 itself, which no
    // step crosses: the window closes just before it, and limits.csv has the limit.
    options.bounds.push_back({"shape", shape_end, toward < 0 ? 1.0 : 1 - shape_end});
  };
}

// Where a subharmonic branch starts: the members' energy (continuum) or the backbone's first
// energy near the mode-2 grazing energy (end amplitude (1 + start_offset) g0), and the shape.
struct SubharmonicStart {
  int mode = 2;  // J: the continuum of mode J over two periods
  bool manifold = false, continuum = false;
  double energy = 0;        // of the continuum's members
  double shape = 0;         // kept (subharmonic) or of the first member (continuum)
  double start_energy = 0;  // of the first point
  SubharmonicMember first;  // the closed-form member there
};

SubharmonicStart subharmonic_start(const core::Scene& scene, const SubharmonicBranch& branch,
                                   const bar::Material& material, double g0) {
  SubharmonicStart st;
  st.mode = branch.mode;
  const double j = st.mode;
  // The manifold's seed is a member of the continuum at sqrt(energy_min energy_max) (manifold.hpp).
  st.manifold = branch.kind == "subharmonic_manifold";
  st.continuum = branch.kind == "subharmonic_continuum" || st.manifold;
  st.energy = scene.non_negative("energy");
  // Default: strain (2J + 1) g0 / L, above the grazing strain (2J - 1) g0 / L (mode 2: 5 g0 / L).
  if (st.energy == 0)
    st.energy = 0.5 * material.axial_stiffness() * std::pow((2 * j + 1) * g0, 2) / material.length;
  if (st.manifold) st.energy = manifold_seed_energy(scene);
  const double shape_key = scene.number("shape");
  if (shape_key != -1 && !(shape_key > 0 && shape_key <= 1))
    throw core::InputError("shape", fmt::format("must be in (0, 1], or -1 for the branch's "
                                                "default (got {})",
                                                shape_key));
  st.shape = shape_key > 0 ? shape_key : (st.continuum && !st.manifold ? 1.0 : 0.3);
  const double ratio = 1 + scene.positive("start_offset");
  // End amplitude ratio g0 of mode J at strain s: sL = (J ratio + J - 1) g0 (family.hpp).
  st.start_energy = st.continuum ? st.energy
                                 : 0.5 * material.axial_stiffness() *
                                       std::pow((j * ratio + j - 1) * g0, 2) / material.length;
  st.first = subharmonic_member(material, g0, st.start_energy, st.shape, st.mode);
  return st;
}

// The subharmonic chart: started on the wall, two free knots (or more) at the first member's
// kinks, the path row fixing the energy (continuum) or the shape.
OrbitOptions subharmonic_chart(const core::Scene& scene, const bar::Material& material,
                               const SubharmonicStart& st) {
  OrbitOptions options = shooting_grid(scene);
  options.start_on_wall = true;
  options.subharmonic_mode = st.mode;
  const long knots = scene.integer("free_knots", -1);
  options.free_knots = knots < 0 ? st.mode : static_cast<int>(knots);
  if (st.mode == 2 && options.free_knots < 2)
    throw core::InputError("free_knots", "the subharmonic members have two kinks: >= 2 or -1");
  if (st.mode > 2 && options.free_knots != st.mode)
    throw core::InputError("free_knots", fmt::format("the members of subharmonic{} have {} kinks, "
                                                     "one per knot: {} or -1",
                                                     st.mode, st.mode, st.mode));
  if (options.elements < 2 * st.mode)
    throw core::InputError("shooting_elements",
                           fmt::format("must be >= {} for the {} kinks of the subharmonic{} "
                                       "members (got {})",
                                       2 * st.mode, st.mode, st.mode, options.elements));
  // Knot 1 on the node nearest the first kink; the last knot on node N - 1: beyond the second
  // kink u0 is linear up to L for every member, and that segment shrinks to nothing at the
  // shape-0 limit, where interior nodes would be free of the residual (spurious roots).
  // Further knots (free_knots > 2) spread between the two.
  // Mode J > 2: the first J - 1 knots on the nodes nearest the first J - 1 kinks.
  const SubharmonicMember& first = st.first;
  std::vector<double> at{first.kinks[0]};
  for (int j = 1; j + 1 < options.free_knots; ++j)
    at.push_back(st.mode > 2 ? first.kinks[static_cast<std::size_t>(j)]
                             : first.kinks[0] + (first.kinks[1] - first.kinks[0]) * j /
                                                    (options.free_knots - 1));
  options.knot_nodes = nearest_knot_nodes(options.elements, material.length, at);
  options.knot_nodes.push_back(options.elements - 1);
  if (options.knot_nodes.size() >= 2 &&
      options.knot_nodes[options.knot_nodes.size() - 2] >= options.elements - 1)
    throw core::InputError("shooting_elements", "too few elements for the free knots");
  const long test_elements = scene.integer("test_elements", -1);
  options.test_elements =
      static_cast<int>(test_elements < 0 ? 2 * options.state_size() : test_elements);
  check_memory(scene, options);
  if (st.continuum)
    options.fixed_energy = st.energy;
  else
    options.fixed_shape = st.shape;
  return options;
}

// The subharmonic branches' outputs beside the branch (write_subharmonic_outputs) and, for
// the continuum, limits.csv: both grazing limits at this energy, located by NLopt
// (grazing_limits.hpp) on the continuum's grid and time step.
std::function<void(const std::filesystem::path&, const continuation::Branch&)> subharmonic_outputs(
    const core::Scene& scene, const ContactBarOrbitProblem* p, const ContactFamily& mode2,
    const SubharmonicStart& st) {
  const bool dimension_check = scene.flag("dimension_check");
  const double rank_threshold = scene.positive("rank_threshold");
  const bool continuum = st.continuum;
  const double energy = st.energy;
  const int mode = st.mode;
  return [p, mode2, dimension_check, rank_threshold, continuum, energy, mode](
             const std::filesystem::path& out, const continuation::Branch& b) {
    write_subharmonic_outputs(*p, mode2, b, out, dimension_check ? rank_threshold : std::nan(""));
    if (!continuum) return;
    GrazingLimitOptions o;
    o.elements = p->options().elements;
    o.steps_per_period = p->options().steps_per_period;
    o.mode = mode;
    const GrazingLimits g = grazing_limits(p->setup_template(), p->solver(), energy, o);
    grazing_limit_table(g).write_csv(out / "limits.csv");
    for (const GrazingLimit& l : g.limits)
      fmt::print(
          "grazing limit {} (NLopt): {} contact phase(s), {} grazing instant(s), vanishing phase "
          "{:.2e} s, residual {:.1e}, exact return {:.1e}, {} ({:.2f} s)\n",
          l.name, l.structure.contact_phases, l.structure.grazing_instants, l.phase_duration,
          l.residual, l.return_error, l.message, l.seconds);
    fmt::print("grazing limits: shape_1 simulated by T{} = {:.9g} s vs shape_0: {:.2e} relative\n",
               mode, g.half_period, g.shift_distance);
  };
}

// The subharmonic branches (problems/contact_bar/orbits/README.md, section 'Subharmonic
// continuum'): mode 2 taken over two periods, T = 2 T2, started at rest at the centre of a contact
// phase (start_on_wall), two free knots at its two kinks. The periodic orbits form a 2D manifold
// (energy x shape); a path on it is picked by one path row: the shape (subharmonic: the backbone at
// constant shape) or the energy (subharmonic_continuum: the members at one energy, from a grazing
// limit on).
cli::TraceSetup setup_subharmonic(const core::Scene& scene, const std::string& branch) {
  bar::BarSetup setup = bar_from_scene(scene);
  const SubharmonicBranch which = subharmonic_branch(branch);
  if (which.mode % 2 != 0)
    throw core::InputError(
        "branch", fmt::format("{}: mode {} has no subharmonic continuum over two periods (an odd "
                              "mode's shift by 2L/c locks its two contact phases T_{} apart; "
                              "problems/contact_bar/orbits/README.md, 'Subharmonic continuum of "
                              "mode J')",
                              branch, which.mode, which.mode));
  check_orbit_ends(setup, "the subharmonic branches");
  check_simulation_keys(scene);
  const bar::Material& material = setup.material;
  const ContactFamily mode2(material, setup.right.gap, which.mode);
  const SubharmonicStart st = subharmonic_start(scene, which, material, setup.right.gap);
  const OrbitOptions options = subharmonic_chart(scene, material, st);

  auto problem = std::make_unique<ContactBarOrbitProblem>(setup, shooting_solver(scene), options);
  problem->set_monodromy_options(monodromy_options(scene));
  cli::TraceSetup s;
  s.guess = problem->subharmonic_guess(st.start_energy, st.shape);
  check_time_step(material, s.guess[problem->period_index()], options.steps_per_period);
  if (st.continuum) {
    // Towards the other grazing limit: the shape decreases from 1 (increases from below 1/2).
    // The closed-form direction of the family: the first step follows it, since the start at
    // a grazing limit is a nonsmooth boundary point where the finite-difference tangent mixes
    // the free and the contact side.
    const double toward = st.shape > 0.5 ? -1.0 : 1.0;
    s.direction = problem->subharmonic_guess(st.energy, st.shape + toward * 1e-4) - s.guess;
    s.branch_options = continuum_options(scene, *problem, st.energy, st.shape, toward);
  } else {
    s.direction = problem->subharmonic_guess(st.start_energy * 1.01, st.shape) - s.guess;
  }
  // 1000 intervals: finer than any knot segment the branch keeps (a coarser check grid lets
  // spurious roots through near the shape-0 limit).
  s.reject_point = return_check(scene, problem.get(), 1000);
  s.describe_point = [mode2](const continuation::BranchPoint& point) {
    const double exact = 2 * mode2.period(point.observable("energy"));
    return fmt::format("T / (2 T{}) - 1 = {:.2e}, shape {:.4f}", mode2.mode(),
                       point.observable("period") / exact - 1, point.observable("shape"));
  };
  s.write_extra_outputs = subharmonic_outputs(scene, problem.get(), mode2, st);
  problem->set_path_rows(scene.flag("path_rows"));
  if (!scene.flag("path_rows"))
    s.check_for_trace = [] {
      throw core::InputError("path_rows",
                             "false leaves F alone, a 2D manifold with no curve to "
                             "trace: it is for `backbone inspect`");
    };
  if (st.manifold) {
    add_manifold_outputs(scene, s, *problem);
    s.covered_dimension = 2;
  }
  s.problem = std::move(problem);
  return s;
}

}  // namespace

// With the fronts representation, fronts.csv beside the branch: per point the isolated
// multipliers' matrix K's checks and its Jordan defect (monodromy.hpp; README.md of orbits/,
// 'Stability').
void add_front_report(cli::TraceSetup& s, bool tdbem_check, int growth_periods) {
  const auto* p = dynamic_cast<const ContactBarOrbitProblem*>(s.problem.get());
  if (!p || p->monodromy_options().representation != MonodromyOptions::Representation::fronts)
    return;
  s.write_extra_outputs = [p, tdbem_check, growth_periods,
                           inner = std::move(s.write_extra_outputs)](
                              const std::filesystem::path& out, const continuation::Branch& b) {
    if (inner) inner(out, b);
    std::vector<std::string> columns{"point",
                                     "energy",
                                     "period",
                                     "ok",
                                     "fronts",
                                     "max_modulus_minus_one",
                                     "determinant",
                                     "jordan_defect",
                                     "time_shift_error",
                                     "value_leak",
                                     "isometry_error",
                                     "return_error",
                                     "grazing_instants",
                                     "closings_on_fronts"};
    if (tdbem_check)
      columns.insert(columns.end(), {"tdbem_ok", "tdbem_kink", "tdbem_k_difference",
                                     "tdbem_multiplier_difference"});
    if (growth_periods > 0)
      columns.insert(columns.end(), {"growth_largest", "growth_modulus", "growth_power"});
    core::Table table(columns);
    // Progress: the perturbed orbits take seconds per point on fine grids, after the loop.
    const auto started = std::chrono::steady_clock::now();
    auto said = started;
    if (growth_periods > 0 || tdbem_check)
      fmt::print("fronts.csv: K of {} points{}{}\n", b.points.size(),
                 tdbem_check ? ", the TD-BEM's K" : "",
                 growth_periods > 0
                     ? fmt::format(", perturbed orbits over {} periods", growth_periods)
                     : "");
    std::size_t done = 0;
    for (const auto& point : b.points) {
      const auto now = std::chrono::steady_clock::now();
      if (now - said > std::chrono::seconds(10)) {
        said = now;
        fmt::print("  fronts.csv: {} of {} points in {:.0f} s\n", done, b.points.size(),
                   std::chrono::duration<double>(now - started).count());
        std::fflush(stdout);
      }
      ++done;
      const exact_bar::FrontMonodromy m = orbit_front_monodromy(*p, point.x);
      // Grazings and closings on fronts, by the exact solver (kinks, where K takes the march's
      // choice: exact_bar/README.md, 'Tangent').
      const bar::BarSetup setup = p->setup_at(point.x);
      const ContactStructure structure = setup.right.has_wall() && setup.right.gap > 0
                                             ? contact_structure(setup, p->period(point.x))
                                             : ContactStructure{};
      if (!m.ok) fmt::print("  fronts.csv: point {} has no K: {}\n", point.index, m.message);
      const double nan = std::numeric_limits<double>::quiet_NaN();
      double excess = nan, det = nan, defect = nan;
      if (m.ok) {
        Eigen::VectorXcd mu;
        if (front_eigenvalues(m.K, mu)) {
          excess = -1;
          for (const auto& z : mu) excess = std::max(excess, std::abs(z) - 1);
          defect = jordan_defect(m.K, mu);
        } else {
          fmt::print("  fronts.csv: point {}: K's eigenvalues did not converge\n", point.index);
        }
        det = m.K.determinant();
      }
      std::vector<double> row{static_cast<double>(point.index),
                              point.observable("energy"),
                              p->period(point.x),
                              m.ok ? 1.0 : 0.0,
                              static_cast<double>(m.K.rows()),
                              excess,
                              det,
                              defect,
                              m.ok ? m.time_shift_error : nan,
                              m.ok ? m.value_leak : nan,
                              m.ok ? m.isometry_error : nan,
                              m.ok ? m.return_error : nan,
                              structure.ok ? structure.grazing_instants : nan,
                              structure.ok ? structure.closings_on_fronts : nan};
      // On a kink of the period map, K is one side's: where the TD-BEM's K was taken, as the
      // stability summary counts them (its one-sided differences apart by over 1e-3); else
      // wherever the exact orbit grazes a wall or closes on one as a front arrives, where a kink
      // can be.
      bool on_kink =
          structure.ok && (structure.grazing_instants > 0 || structure.closings_on_fronts > 0);
      if (tdbem_check) {
        const TdbemFronts t = orbit_tdbem_front_monodromy(*p, point.x);
        on_kink = t.ok ? t.kink > 1e-3 : on_kink;
        const bool both = m.ok && t.ok && t.K.rows() == m.K.rows();
        if (!t.ok)
          fmt::print("  fronts.csv: point {} has no TD-BEM K: {}\n", point.index, t.message);
        // On a kink the exact K takes the march's choice (exact_bar/README.md, 'Tangent'): it
        // is set against the TD-BEM's nearest of its central and one-sided differences.
        const Eigen::MatrixXd* nearest = &t.K;
        if (both)
          for (const Eigen::MatrixXd* side : {&t.K_forward, &t.K_backward})
            if ((*side - m.K).cwiseAbs().maxCoeff() < (*nearest - m.K).cwiseAbs().maxCoeff())
              nearest = side;
        row.insert(row.end(), {t.ok ? 1.0 : 0.0, t.ok ? t.kink : nan,
                               both ? (*nearest - m.K).cwiseAbs().maxCoeff() : nan,
                               both ? multiplier_distance(*nearest, m.K) : nan});
      }
      if (growth_periods > 0) {
        // The perturbed orbit itself, no linearization (monodromy.hpp, perturbation_growth: the
        // paper scene's 40 intervals, seed 7): the one check of a point on a kink, where K is
        // one side's. The draw and its opposite, one on each side of a grazing.
        // The worse of the two draws: the larger of their largest distances, and the larger of
        // their powers of k that take the largest distance up to k_h (the last sample at k <=
        // periods / 2) to the largest of all: 0 bounded, 1 a linear drift (a Jordan block),
        // (periods - k_h) ln|mu| / ln(periods / k_h) for an exponential one (3 for |mu| = 1.005
        // over 1000 periods).
        const double T = p->period(point.x);
        double largest = 0, power = -std::numeric_limits<double>::infinity();
        for (double size : {1e-6, -1e-6}) {
          const PerturbationGrowth g = perturbation_growth(setup, T, growth_periods, size, 40, 7);
          if (!g.ok) {
            largest = power = nan;
            break;
          }
          int half = 1;           // the last sample at k <= periods / 2
          double first_half = 1;  // the largest distance up to it (1 at k = 0)
          for (const auto& [k, d] : g.history)
            if (2 * k <= growth_periods) half = k, first_half = std::max(first_half, d);
          largest = std::max(largest, g.largest);
          power = half < growth_periods
                      ? std::max(power, std::log(g.largest / first_half) /
                                            std::log(static_cast<double>(growth_periods) / half))
                      : nan;
        }
        if (on_kink)
          fmt::print(
              "  fronts.csv: point {} on a kink: a perturbation grows at most {:.3g}-fold "
              "over {} periods, like k^{:.2f} at the end\n",
              point.index, largest, growth_periods, power);
        row.insert(row.end(), {largest, std::pow(largest, 1.0 / growth_periods), power});
      }
      table.add_row(row);
    }
    table.write_csv(out / "fronts.csv");
  };
}

namespace {

// The stability keys apply with --stability true, and the grid's with the grid representation:
// one given where it does nothing is refused, lest a run be read as what it did not compute.
void check_stability_keys(const core::Scene& scene) {
  auto given = [&](const char* key) { return !scene.values()[key].defaulted(); };
  const bool stability = scene.flag("stability");
  const bool grid =
      parse_representation("stability_representation", scene.text("stability_representation")) ==
      MonodromyOptions::Representation::grid;
  for (const char* key : {"stability_representation", "stability_elements", "stability_courant",
                          "stability_step", "stability_growth_periods"})
    if (!stability && given(key)) throw core::InputError(key, "applies with --stability true");
  for (const char* key : {"stability_elements", "stability_courant", "stability_step"})
    if (!grid && given(key))
      throw core::InputError(key,
                             "applies with --stability_representation grid (the fronts' K "
                             "has no grid)");
  if (grid && given("stability_growth_periods"))
    throw core::InputError("stability_growth_periods",
                           "applies with --stability_representation fronts");
}

// The grid monodromy's cost per point, before any work: 4 N simulations of N intervals over the
// period T at c dt = stability_courant dx, about 4 N^2 c T / (courant dx) element-steps (measured
// on mode 1: 4.1e9 in 13 s at 200 intervals, 3.3e10 in 62 s at 400), against max_stability_work;
// the TD-BEM's tangent does the same work in one march, cheaper by a constant. Its memory: each
// end's window of about N / courant knots carries four vectors of 2N doubles, and the window's
// array may hold as much again: 256 N^2 / courant bytes, against max_memory.
void check_grid_monodromy_work(const core::Scene& scene, const cli::TraceSetup& s) {
  const auto* p = dynamic_cast<const ContactBarOrbitProblem*>(s.problem.get());
  if (!p || p->monodromy_options().representation != MonodromyOptions::Representation::grid) return;
  const MonodromyOptions& o = p->monodromy_options();
  const double n = o.elements > 0 ? o.elements : p->options().elements + p->options().free_knots;
  const bar::Material& material = p->setup_template().material;
  const double period = s.guess[p->period_index()];
  const double steps = period * material.wave_speed() * n / (o.courant * material.length);
  const double work = 4 * n * n * steps;
  const double limit = scene.positive("max_stability_work");
  const auto* tdbem = dynamic_cast<const TdbemSolver*>(&p->solver());
  if (tdbem && tdbem->method() == ContactMethod::event) {
    const auto [limit_gb, limit_origin] = memory_limit(scene);
    const double need_gb = 256 * n * n / o.courant / 1e9;
    if (need_gb > limit_gb)
      throw core::InputError(
          o.elements > 0 ? "stability_elements" : "shooting_elements",
          fmt::format("the grid monodromy of {:.0f} intervals carries the march's tangent in "
                      "{:.0f} directions, about {:.3g} GB, above max_memory {:.3g} GB{}: fewer "
                      "intervals, a larger stability_courant, or a larger max_memory",
                      n, 2 * n, need_gb, limit_gb, limit_origin));
  }
  if (work <= limit) return;
  throw core::InputError(
      o.elements > 0 ? "stability_elements" : "shooting_elements",
      fmt::format("the grid monodromy of {:.0f} intervals marches 4 x {:.0f} simulations of {:.3g} "
                  "steps, {:.3g} element-steps per point, above max_stability_work {:.3g}: "
                  "fewer intervals, a larger stability_courant, or a larger max_stability_work",
                  n, n, steps, work, limit));
}

}  // namespace

cli::TraceSetup setup_trace_with_reports(const core::Scene& scene, const std::string& branch) {
  const bool tdbem_check = scene.flag("stability_tdbem_check");
  if (tdbem_check) {
    // Each key's own check first (a typo names its key), then what the TD-BEM's K needs.
    const bool fronts =
        parse_representation("stability_representation", scene.text("stability_representation")) ==
        MonodromyOptions::Representation::fronts;
    const bool tdbem = scene.choice("shooting_solver", {"tdbem", "exact"}) == "tdbem";
    const bool event = contact_method_from_scene(scene) == ContactMethod::event;
    const char* missing = !scene.flag("stability") ? "stability true"
                          : !fronts                ? "stability_representation fronts"
                          : !tdbem                 ? "shooting_solver tdbem"
                          : !event                 ? "contact event"
                                                   : nullptr;
    if (missing)
      throw core::InputError(
          "stability_tdbem_check",
          fmt::format("needs {} (the TD-BEM's own K from the orbit's fronts)", missing));
  }
  check_stability_keys(scene);
  cli::TraceSetup s = setup_trace(scene, branch);
  const int growth_periods = static_cast<int>(scene.integer("stability_growth_periods", 0, 10000));
  if (scene.flag("stability")) {
    add_front_report(s, tdbem_check, growth_periods);
    check_grid_monodromy_work(scene, s);
  }
  return s;
}

cli::ProblemPlugin trace_plugin() {
  cli::ProblemPlugin p;
  p.name = "contact_bar";
  p.summary = "elastic bar fixed at x = 0, rigid wall at gap g0 beyond x = L (Signorini contact)";
  p.scene_keys = &trace_keys;
  p.branches = {"mode1", "mode2", "subharmonic", "subharmonic_continuum", "subharmonic_manifold"};
  p.branch_family = [](const std::string& name) {
    return mode_number(name) >= 1 || !subharmonic_branch(name).kind.empty();
  };
  p.branch_family_text =
      "modeJ for every J >= 1; subharmonicJ, subharmonic_continuumJ and subharmonic_manifoldJ "
      "for every even J >= 4";
  p.setup = &setup_trace_with_reports;
  p.simulate_keys = &simulate_keys;
  p.simulate = &simulate_scene;
  p.units = {{"period", "s"},
             {"frequency", "rad/s"},
             {"energy", "J"},
             {"end_amplitude", "m"},
             {"knot", "m"}};
  return p;
}

}  // namespace backbone::contact_bar
