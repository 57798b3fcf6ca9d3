// `backbone trace SCENE --branch NAME [--out DIR] [--key value ...]`: follows a family of
// solutions (a nonlinear mode) by continuation and writes DIR/branch.csv, DIR/orbits.csv,
// DIR/branch.png and DIR/summary.txt.
//
// The scene's `problem` key picks a TraceProblem (trace_registry.hpp). Continuation settings
// are scene keys too (defaults < scene file < command line); a problem that declares one of
// them itself sets its default. Bad input throws core::InputError before anything is written
// (exit 2). A branch that ends early keeps and writes its points (exit 0, reason printed and in
// summary.txt); exit 1 only when no point converged.
#include <fmt/format.h>

#include <boost/make_shared.hpp>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>

#include "continuation/natural.hpp"
#include "continuation/pseudo_arclength.hpp"
#include "continuation/switching.hpp"
#include "core/errors.hpp"
#include "core/periodic_orbit.hpp"
#include "core/plot.hpp"
#include "core/scene.hpp"
#include "core/table.hpp"
#include "drivers/commands.hpp"
#include "drivers/trace_registry.hpp"

namespace backbone::drivers {
namespace {

namespace po = boost::program_options;
namespace cont = backbone::continuation;

po::options_description driver_keys() {
  po::options_description keys("trace");
  keys.add_options()                                                                             //
      ("branch", po::value<std::string>(), "branch to follow (the problem lists its branches)")  //
      ("out", po::value<std::string>(), "output directory (default out/PROBLEM_BRANCH)")         //
      ("help", "describe the command, the problem's keys and the continuation keys");
  return keys;
}

// Continuation keys, minus any the problem declares itself (it then owns their default).
po::options_description continuation_keys(const po::options_description& problem_keys) {
  po::options_description keys("continuation");
  const auto add = [&](const char* name, const po::value_semantic* value, const char* help) {
    if (problem_keys.find_nothrow(name, false)) {
      delete value;
      return;
    }
    keys.add(boost::make_shared<po::option_description>(name, value, help));
  };
  const double inf = std::numeric_limits<double>::infinity();
  add("method", po::value<std::string>()->default_value("arclength"),
      "arclength (pseudo-arclength, passes folds), natural, or natural_then_arclength "
      "(natural until it stalls, then arclength: the paper's strategy)");
  add("predictor", po::value<std::string>()->default_value("tangent"), "tangent or secant");
  add("newton", po::value<std::string>()->default_value("eigen"), "corrector: eigen or kinsol");
  add("formulation", po::value<std::string>()->default_value("regular"),
      "shooting residual: regular (v(T/2) = 0) or paper (u0 - u(T) = 0)");
  add("ds", po::value<double>()->default_value(0.01), "first step (Euclidean, in unknowns)");
  add("ds_min", po::value<double>()->default_value(1e-8), "smallest step before giving up");
  add("ds_max", po::value<double>()->default_value(0.5), "largest step");
  add("max_points", po::value<long>()->default_value(200), "points on the branch, first included");
  add("energy_min", po::value<double>()->default_value(-inf), "stop below this energy");
  add("energy_max", po::value<double>()->default_value(inf), "stop above this energy");
  add("period_min", po::value<double>()->default_value(-inf), "stop below this period");
  add("period_max", po::value<double>()->default_value(inf), "stop above this period");
  add("bound", po::value<std::vector<std::string>>()->composing(),
      "NAME:MIN:MAX, stop when observable NAME leaves [MIN, MAX] (empty = unbounded; repeatable)");
  add("rank_check_every", po::value<long>()->default_value(1),
      "verified rank report every k points (0: never)");
  add("rank_threshold", po::value<double>()->default_value(1e-8),
      "rank report: singular values below this times the largest count as zero (candidates; "
      "verify then keeps only the real directions)");
  add("verify", po::value<bool>()->default_value(true),
      "re-correct along candidate null directions (verified dimension)");
  add("newton_tolerance", po::value<double>()->default_value(1e-10), "||F||_inf to converge");
  add("newton_max_iterations", po::value<long>()->default_value(25), "Newton iterations per point");
  add("natural_parameter", po::value<std::string>()->default_value("period"),
      "natural method: the period unknown or an observable name");
  add("natural_direction", po::value<long>()->default_value(1), "natural method: +1 or -1");
  return keys;
}

double bound_value(const std::string& text, double fallback, const std::string& spec) {
  if (text.empty()) return fallback;
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    if (used == text.size() && !std::isnan(v)) return v;
  } catch (const std::exception&) {
  }
  throw core::InputError("bound", fmt::format("'{}' is not NAME:MIN:MAX with numbers", spec));
}

cont::ContinuationOptions read_options(const core::Scene& scene) {
  cont::ContinuationOptions o;
  o.method = cont::parse_method(scene.text("method"));
  o.predictor = cont::parse_predictor(scene.text("predictor"));
  o.ds = scene.positive("ds");
  o.ds_min = scene.positive("ds_min");
  o.ds_max = scene.positive("ds_max");
  o.max_points = static_cast<int>(scene.integer("max_points", 1));
  o.rank_check_every = static_cast<int>(scene.integer("rank_check_every", 0));
  o.verify = scene.flag("verify");
  o.rank.relative_threshold = scene.positive("rank_threshold");
  if (!(o.rank.relative_threshold < 1))
    throw core::InputError("rank_threshold",
                           fmt::format("must be in (0, 1) (got {})", o.rank.relative_threshold));
  for (const char* name : {"energy", "period"}) {
    const double lo = scene.values()[std::string(name) + "_min"].as<double>();
    const double hi = scene.values()[std::string(name) + "_max"].as<double>();
    if (std::isnan(lo) || std::isnan(hi))
      throw core::InputError(std::string(name) + "_min", "must be a number");
    if (std::isfinite(lo) || std::isfinite(hi)) o.bounds.push_back({name, lo, hi});
  }
  if (scene.has("bound")) {
    for (const std::string& spec : scene.values()["bound"].as<std::vector<std::string>>()) {
      const auto first = spec.find(':');
      const auto second = first == std::string::npos ? first : spec.find(':', first + 1);
      if (second == std::string::npos)
        throw core::InputError("bound", fmt::format("'{}' is not NAME:MIN:MAX", spec));
      cont::Bound b;
      b.observable = spec.substr(0, first);
      b.min = bound_value(spec.substr(first + 1, second - first - 1),
                          -std::numeric_limits<double>::infinity(), spec);
      b.max = bound_value(spec.substr(second + 1), std::numeric_limits<double>::infinity(), spec);
      o.bounds.push_back(b);
    }
  }
  o.validate();
  return o;
}

std::string known_problems() {
  std::string list;
  for (const auto& [name, p] : trace_problems()) list += (list.empty() ? "" : ", ") + name;
  return list.empty() ? "none registered" : list;
}

void print_help(const TraceProblem* problem) {
  fmt::print("usage: backbone trace SCENE [--branch NAME] [--out DIR] [--key value ...]\n\n");
  fmt::print("problems (scene key `problem`):\n");
  for (const auto& [name, p] : trace_problems()) {
    std::string branches;
    for (const auto& b : p.branches) branches += (branches.empty() ? "" : ", ") + b;
    fmt::print("  {:<14} {} (branches: {})\n", name, p.summary, branches);
  }
  std::ostringstream text;
  text << "\n" << driver_keys() << "\n";
  if (problem) {
    const po::options_description keys = problem->scene_keys();
    text << keys << "\n" << continuation_keys(keys);
  } else {
    text << continuation_keys(po::options_description());
  }
  fmt::print("{}\n", text.str());
}

// The figure: frequency against energy (log axis) when the problem reports them, else the
// first two observables.
void write_figure(const std::filesystem::path& out, const core::Table& table,
                  const std::string& title) {
  const auto& columns = table.columns();
  const auto column_of = [&](const std::string& name) {
    for (std::size_t i = 0; i < columns.size(); ++i)
      if (columns[i] == name) return static_cast<int>(i) + 1;
    return 0;
  };
  int x = column_of("energy"), y = column_of("frequency");
  bool log_x = x > 0 && y > 0;
  if (!log_x) {
    x = 2;
    y = 3;
  }
  if (static_cast<int>(columns.size()) < std::max(x, y)) return;
  const std::string script = fmt::format(
      "set datafile separator ','\nset key top left\nset grid\n{}"
      "set xlabel '{}'\nset ylabel '{}'\nset title '{}' noenhanced\n"
      "plot {} using {}:{} skip 1 with linespoints pt 7 ps 0.6 title 'branch'\n",
      log_x ? "set logscale x\nset format x '10^{%L}'\n" : "", columns[x - 1],
      columns[y - 1] + (columns[y - 1] == "frequency" ? " [rad/time]" : ""), title,
      core::gnuplot_quote(out / "branch.csv"), x, y);
  core::PlotResult r = core::render_png(out / "branch.png", script);
  if (!r.ok) fmt::print(stderr, "figure skipped: {}\n", r.message);
}

core::Table orbit_table(const core::PeriodicOrbitProblem& problem, const cont::Branch& branch) {
  core::Table t({"point", "x", "u0"});
  core::Vector coordinates, values;
  for (const auto& p : branch.points) {
    problem.initial_state_samples(p.x, coordinates, values);
    for (Eigen::Index i = 0; i < values.size(); ++i)
      t.add_row({static_cast<double>(p.index), coordinates[i], values[i]});
  }
  return t;
}

int run_trace(const std::vector<std::string>& args) {
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    print_help(nullptr);
    if (args.empty()) throw core::InputError("SCENE", "a scene file is required");
    return core::exit_ok;
  }
  const std::string scene_path = args[0];
  const std::string problem_name = core::scene_problem_name(scene_path);
  const auto found = trace_problems().find(problem_name);
  if (found == trace_problems().end())
    throw core::InputError("problem", fmt::format("'{}' cannot be traced (known: {})", problem_name,
                                                  known_problems()));
  const TraceProblem& entry = found->second;
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  for (const auto& a : rest)
    if (a == "--help" || a == "-h") {
      print_help(&entry);
      return core::exit_ok;
    }

  po::options_description keys = entry.scene_keys();
  keys.add(continuation_keys(keys));
  const core::Scene scene = core::read_scene(keys, scene_path, rest, driver_keys());
  const std::string branch_name = scene.has("branch") ? scene.text("branch") : entry.branches.at(0);
  if (std::find(entry.branches.begin(), entry.branches.end(), branch_name) ==
      entry.branches.end()) {
    std::string list;
    for (const auto& b : entry.branches) list += (list.empty() ? "" : ", ") + b;
    throw core::InputError("branch", fmt::format("'{}' is not a branch of {} (known: {})",
                                                 branch_name, problem_name, list));
  }
  const std::filesystem::path out =
      scene.has("out") ? scene.text("out") : fmt::format("out/{}_{}", problem_name, branch_name);
  const cont::ContinuationOptions options = read_options(scene);
  core::NewtonOptions newton_options;
  newton_options.residual_tolerance = scene.positive("newton_tolerance");
  newton_options.max_iterations = static_cast<int>(scene.integer("newton_max_iterations", 1));
  auto corrector = core::make_corrector(scene.text("newton"), newton_options);
  const core::ShootingFormulation formulation = core::parse_formulation(scene.text("formulation"));
  const long natural_direction = scene.integer("natural_direction", -1);
  if (natural_direction != 1 && natural_direction != -1)
    throw core::InputError("natural_direction",
                           fmt::format("must be 1 or -1 (got {})", natural_direction));

  TraceSetup setup = entry.setup(scene, branch_name);
  if (!setup.problem) throw core::InputError("problem", "setup returned no problem");
  const core::Problem& problem = *setup.problem;
  auto* periodic = dynamic_cast<core::PeriodicOrbitProblem*>(setup.problem.get());
  if (periodic) periodic->set_formulation(formulation);
  core::Vector direction = setup.direction;
  if (direction.size() == 0) {
    direction = core::Vector::Unit(
        problem.num_unknowns(), periodic ? periodic->period_index() : problem.num_unknowns() - 1);
  }

  const int n = problem.num_unknowns(), m = problem.num_equations();
  if (m != n - 1 && corrector->name() == "kinsol")
    throw core::InputError("newton", fmt::format("kinsol solves square systems only; this {} "
                                                 "residual has {} equations for {} unknowns "
                                                 "(use newton = eigen, least squares)",
                                                 problem_name, m, n));
  // A consistent overdetermined system (m > n - 1) still has curves of solutions.
  const int expected_dimension = n - std::min(m, n - 1);
  fmt::print("{} / {}: {} equations in {} unknowns, expected manifold dimension {}\n", problem_name,
             branch_name, m, n, expected_dimension);
  fmt::print("  {} continuation, {} predictor, newton {}, {}{}\n", cont::to_string(options.method),
             cont::to_string(options.predictor), corrector->name(),
             periodic ? fmt::format("formulation {}, ", core::to_string(formulation)) : "",
             fmt::format("ds {:g} in [{:g}, {:g}], at most {} points", options.ds, options.ds_min,
                         options.ds_max, options.max_points));

  cont::ContinuationHooks hooks;
  hooks.on_point = [&](const cont::BranchPoint& p) {
    std::string observables;
    for (const auto& [key, value] : p.observables)
      observables += fmt::format(" {} {:.10g}", key, value);
    fmt::print("  point {:4d}{}  dim {}  |F| {:.1e}  newton {}  ds {:.3g}  {:.3f} s{}\n", p.index,
               observables, p.dimension, p.residual, p.newton_iterations, p.step_size, p.seconds,
               setup.describe_point ? "  " + setup.describe_point(p) : "");
    std::fflush(stdout);
  };

  long rejected = 0;
  hooks.reject_point = setup.reject_point;
  hooks.on_attempt = [&](const cont::StepAttempt& a) {
    if (a.rejection.empty()) return;
    ++rejected;
    fmt::print("  point {:4d}  rejected at ds {:.3g}: {}\n", a.point, a.ds, a.rejection);
  };

  cont::Branch branch;
  int switch_index = -1;
  if (options.method == cont::Method::arclength) {
    branch = cont::pseudo_arclength(problem, setup.guess, direction, *corrector, options, hooks);
  } else {
    const std::string name = scene.text("natural_parameter");
    cont::NaturalParameter parameter =
        (periodic && name == "period")
            ? cont::NaturalParameter::of_unknown(periodic->period_index(), "period",
                                                 static_cast<double>(natural_direction))
            : cont::NaturalParameter::of_observable(name, static_cast<double>(natural_direction));
    if (options.method == cont::Method::natural) {
      branch = cont::natural(problem, setup.guess, parameter, *corrector, options, hooks);
    } else {
      cont::SwitchingBranch s =
          cont::natural_then_arclength(problem, setup.guess, parameter, *corrector, options, hooks);
      branch = std::move(s.branch);
      switch_index = s.switch_index;
    }
  }

  std::string summary = fmt::format(
      "problem {}\nbranch {}\nequations {}\nunknowns {}\nexpected_dimension {}\nmethod {}\n"
      "newton {}\nformulation {}\npoints {}\nrejected_corrections {}\nswitch_index {}\n"
      "stop_reason {}\nmessage {}\n",
      problem_name, branch_name, m, n, expected_dimension, cont::to_string(options.method),
      corrector->name(), periodic ? core::to_string(formulation) : "-", branch.points.size(),
      rejected, switch_index, cont::to_string(branch.reason), branch.message);
  fmt::print("stopped: {} ({})\n", cont::to_string(branch.reason), branch.message);
  if (branch.points.empty()) {
    core::write_text_atomically(out / "summary.txt", summary);
    return core::exit_numerical_failure;
  }
  const core::Table table = cont::branch_table(branch);
  table.write_csv(out / "branch.csv");
  if (periodic) orbit_table(*periodic, branch).write_csv(out / "orbits.csv");
  write_figure(out, table,
               fmt::format("{} / {} ({} points)", problem_name, branch_name, branch.points.size()));
  if (setup.write_extra_outputs) setup.write_extra_outputs(out, branch);
  core::write_text_atomically(out / "summary.txt", summary);
  fmt::print("wrote {}\n", out.string());
  return core::exit_ok;
}

}  // namespace
}  // namespace backbone::drivers

static const bool registered = backbone::drivers::register_command(
    {"trace", "SCENE [--branch NAME] [--out DIR] [--key value ...]",
     "follow a nonlinear mode (branch of periodic orbits) by continuation",
     backbone::drivers::run_trace});
