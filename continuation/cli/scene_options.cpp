#include "continuation/cli/scene_options.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <boost/make_shared.hpp>
#include <cmath>
#include <limits>

#include "continuation/methods/natural.hpp"
#include "continuation/methods/pseudo_arclength.hpp"
#include "core/errors.hpp"
#include "core/jacobians/finite_difference.hpp"

namespace backbone::cli {

using namespace continuation;  // the algorithms whose settings and points this file handles

namespace po = boost::program_options;

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
  add("predictor", po::value<std::string>()->default_value("auto"),
      "tangent, secant, quadratic (the tangent plus the curvature seen from the previous point) "
      "or auto: quadratic, tangent when branch points are detected (continuation/README.md, "
      "'Predictors')");
  add("newton", po::value<std::string>()->default_value("eigen"), "corrector: eigen or kinsol");
  add("formulation", po::value<std::string>()->default_value("regular"),
      "shooting residual: regular (v(T/2) = 0) or paper (u0 - u(T) = 0)");
  add("ds", po::value<double>()->default_value(0.01),
      "first step, in unknowns divided by their typical scale (dimensionless, in [ds_min, "
      "ds_max])");
  add("ds_min", po::value<double>()->default_value(1e-8),
      "smallest step (dimensionless, in (0, ds]): the run stops when a step this small fails");
  add("ds_max", po::value<double>()->default_value(0.5), "largest step (dimensionless, >= ds)");
  add("max_points", po::value<long>()->default_value(200),
      "points on the branch, first included (>= 1)");
  add("energy_min", po::value<double>()->default_value(-inf),
      "stop below this energy (the problem's energy unit; -inf: no bound)");
  add("energy_max", po::value<double>()->default_value(inf),
      "stop above this energy (the problem's energy unit; inf: no bound)");
  add("period_min", po::value<double>()->default_value(-inf),
      "stop below this period (the problem's time unit; -inf: no bound)");
  add("period_max", po::value<double>()->default_value(inf),
      "stop above this period (the problem's time unit; inf: no bound)");
  add("bound", po::value<std::vector<std::string>>()->composing(),
      "NAME:MIN:MAX, stop when observable NAME leaves [MIN, MAX] (an empty MIN or MAX: no bound "
      "on that side; an empty value: no bound; repeatable)");
  add("rank_check_every", po::value<long>()->default_value(1),
      "verified rank report every k points (k >= 0; 0: never)");
  add("rank_threshold", po::value<double>()->default_value(1e-8),
      "rank report: singular values below this times the largest count as zero, in (0, 1) "
      "(candidates; verify then keeps only the real directions)");
  add("verify", po::value<bool>()->default_value(true),
      "re-correct along candidate null directions (verified dimension)");
  add("stability", po::value<bool>()->default_value(true),
      "Floquet multipliers of every point when the problem gives its monodromy (branch.csv's "
      "stable column, multipliers.csv), and the bifurcations of the orbits (bifurcations.csv)");
  add("floquet_tolerance", po::value<double>()->default_value(1e-6),
      "a multiplier with |mu| > 1 + this is unstable, in (0, 0.1)");
  add("floquet_trivial_tolerance", po::value<double>()->default_value(1e-4),
      "the trivial multipliers (+1 by construction) must lie within this of +1, in (0, 0.5); "
      "else the point's stability is undecided (-1)");
  add("detect_branch_points", po::value<bool>()->default_value(false),
      "arclength: evaluate the branch-point test function at every point, locate and verify "
      "candidates (trace writes branch_points.csv)");
  add("locate_in_background", po::value<bool>()->default_value(true),
      "locate and verify branch-point candidates on a second thread while the trace goes on "
      "(problems with core::Problem::clone; the same rows either way)");
  add("follow", po::value<std::string>()->default_value("none"),
      "arclength: none, all, doubling or K: switch onto the family attached at every verified "
      "(or the K-th, 1-based row of branch_points.csv) branch point and trace it towards growing "
      "energy into DIR/branch_point_K/ (implies detect_branch_points); all and doubling also "
      "switch at every period doubling of the orbits onto the branch of twice the period, into "
      "DIR/period_doubling_K/");
  add("follow_max_points", po::value<long>()->default_value(30),
      "points of each followed branch (>= 1; with the energy bound)");
  add("max_probes", po::value<long>()->default_value(24),
      "branch points: candidate directions probed at a located point (1 to 10000); with more "
      "candidates the attached dimension is a lower bound (branch_points.csv: candidates, "
      "probed)");
  add("max_turn_degrees", po::value<double>()->default_value(20),
      "arclength: refuse a correction whose step turns by more than this many degrees (>= 0) "
      "from the predictor direction (it landed on another family); 0: off");
  add("newton_tolerance", po::value<double>()->default_value(1e-10),
      "||F||_inf to converge, in the residual's units (> 0)");
  add("newton_max_iterations", po::value<long>()->default_value(25),
      "Newton iterations per point (>= 1)");
  add("newton_reuse_jacobian", po::value<bool>()->default_value(false),
      "eigen corrector: after a fresh Jacobian, take chord steps on its factorization while each "
      "cuts ||F|| tenfold (one residual each), else a fresh Jacobian");
  add("newton_jacobian_check", po::value<double>()->default_value(1e-2),
      "eigen corrector: accept a compressed Jacobian whose check error is below this fraction, "
      "in [0, 1), of each row (the answer is judged by F alone); rank reports keep the pattern's "
      "own; 0: the pattern's own everywhere");
  add("chord_corrections", po::value<bool>()->default_value(true),
      "arclength: start each correction (and each rank-verification probe) with chord steps on "
      "the previous point's Jacobian, a fresh Jacobian only when they contract too slowly");
  add("natural_parameter", po::value<std::string>()->default_value("period"),
      "natural method: the period unknown or an observable name");
  add("natural_direction", po::value<long>()->default_value(1), "natural method: +1 or -1");
  add("threads", po::value<long>()->default_value(1),
      "threads for the finite-difference Jacobian columns, 1 to 256 (same branch, bit for bit)");
  return keys;
}

namespace {

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

void read_bounds(const core::Scene& scene, ContinuationOptions& o) {
  for (const char* name : {"energy", "period"}) {
    for (const char* side : {"_min", "_max"}) {
      const std::string key = std::string(name) + side;
      if (std::isnan(scene.values()[key].as<double>()))
        throw core::InputError(key, "must be a number (got nan)");
    }
    const double lo = scene.values()[std::string(name) + "_min"].as<double>();
    const double hi = scene.values()[std::string(name) + "_max"].as<double>();
    if (std::isfinite(lo) || std::isfinite(hi))
      o.bounds.push_back({name, lo, hi, std::string(name) + "_min", std::string(name) + "_max"});
  }
  if (!scene.has("bound")) return;
  for (const std::string& spec : scene.values()["bound"].as<std::vector<std::string>>()) {
    if (spec.empty()) continue;  // no bound (a scene.ini may keep an empty `bound =`)
    const auto first = spec.find(':');
    const auto second = first == std::string::npos ? first : spec.find(':', first + 1);
    if (second == std::string::npos)
      throw core::InputError("bound", fmt::format("'{}' is not NAME:MIN:MAX", spec));
    Bound b;
    b.observable = spec.substr(0, first);
    b.min_key = b.max_key = "bound";
    b.min = bound_value(spec.substr(first + 1, second - first - 1),
                        -std::numeric_limits<double>::infinity(), spec);
    b.max = bound_value(spec.substr(second + 1), std::numeric_limits<double>::infinity(), spec);
    if (!(b.min < b.max))
      throw core::InputError("bound", fmt::format("'{}': MIN must be below MAX", spec));
    o.bounds.push_back(b);
  }
}

}  // namespace

RunSettings read_run_settings(const core::Scene& scene) {
  RunSettings run;
  ContinuationOptions& o = run.options;
  o.method = parse_method(scene.text("method"));
  const std::string predictor =
      scene.choice("predictor", {"auto", "tangent", "secant", "quadratic"});
  o.ds = scene.positive("ds");
  o.ds_min = scene.positive("ds_min");
  o.ds_max = scene.positive("ds_max");
  o.max_points = static_cast<int>(scene.integer("max_points", 1));
  o.rank_check_every = static_cast<int>(scene.integer("rank_check_every", 0));
  o.verify = scene.flag("verify");
  o.stability = scene.flag("stability");
  o.floquet.tolerance = scene.number("floquet_tolerance");
  o.floquet.trivial_tolerance = scene.number("floquet_trivial_tolerance");
  o.rank.relative_threshold = scene.positive("rank_threshold");
  if (!(o.rank.relative_threshold < 1))
    throw core::InputError("rank_threshold",
                           fmt::format("must be in (0, 1) (got {})", o.rank.relative_threshold));
  run.follow.selection = parse_follow(scene.text("follow"));
  run.follow.max_points = static_cast<int>(scene.integer("follow_max_points", 1));
  o.branch_points.detect = scene.flag("detect_branch_points") ||
                           run.follow.selection.kind != FollowSelection::Kind::none;
  // The detector samples its test function at the points and is sized for the tangent
  // predictor's steps, which the quadratic one lengthens (continuation/README.md, 'Predictors').
  o.predictor = predictor != "auto"      ? parse_predictor(predictor)
                : o.branch_points.detect ? Predictor::tangent
                                         : Predictor::quadratic;
  o.branch_points.max_turn_degrees = scene.non_negative("max_turn_degrees");
  o.branch_points.max_probes = static_cast<int>(scene.integer("max_probes", 1, 10000));
  o.branch_points.background = scene.flag("locate_in_background");
  read_bounds(scene, o);
  o.validate();
  // Branch points are detected along a pseudo-arclength loop (the natural loop has no tangent to
  // border J with); natural_then_arclength detects once it switches.
  if (o.method == Method::natural && o.branch_points.detect)
    throw core::InputError(
        run.follow.selection.kind != FollowSelection::Kind::none ? "follow"
                                                                 : "detect_branch_points",
        "needs method arclength or natural_then_arclength (branch points are detected along "
        "the arclength loop)");
  run.newton = scene.choice("newton", {"eigen", "kinsol"});
  run.newton_options.residual_tolerance = scene.positive("newton_tolerance");
  // A probe of the rank verification is a solution by the same standard as a point of the
  // branch: a stricter one refuses probes on the solution set wherever the residual's round-off
  // exceeds it, and a point the branch runs through would verify as dimension 0.
  o.verification.residual_tolerance =
      std::max(o.verification.residual_tolerance, run.newton_options.residual_tolerance);
  run.newton_options.max_iterations = static_cast<int>(scene.integer("newton_max_iterations", 1));
  run.newton_options.reuse_jacobian = scene.flag("newton_reuse_jacobian");
  run.newton_options.jacobian_check_tolerance = scene.non_negative("newton_jacobian_check");
  if (!(run.newton_options.jacobian_check_tolerance < 1))
    throw core::InputError(
        "newton_jacobian_check",
        fmt::format("must be in [0, 1) (got {})", run.newton_options.jacobian_check_tolerance));
  o.chord_corrections = scene.flag("chord_corrections");
  run.formulation = core::parse_formulation(scene.text("formulation"));
  run.natural_parameter = scene.text("natural_parameter");
  const long direction = scene.integer("natural_direction", -1);
  if (direction != 1 && direction != -1)
    throw core::InputError("natural_direction", fmt::format("must be 1 or -1 (got {})", direction));
  run.natural_direction = static_cast<double>(direction);
  run.threads = static_cast<int>(scene.integer("threads", 1, core::max_jacobian_threads));
  return run;
}

SwitchingBranch run_continuation(const core::Problem& problem, const core::Vector& guess,
                                 const core::Vector& direction, const RunSettings& settings,
                                 core::Corrector& corrector, const ContinuationHooks& hooks,
                                 const RestartPoint* restart) {
  const ContinuationOptions& options = settings.options;
  // The run's thread count, restored on the way out (also when a callback throws).
  struct ThreadsForThisRun {
    int previous = core::default_jacobian_threads();
    explicit ThreadsForThisRun(int threads) { core::set_default_jacobian_threads(threads); }
    ~ThreadsForThisRun() { core::set_default_jacobian_threads(previous); }
  } threads(settings.threads);
  const LoopState* from = restart ? restart->state.get() : nullptr;
  const bool record = restart && restart->record_saved_point;
  const BranchStart start =
      restart ? BranchStart{restart->index, restart->arclength, -1, restart->rejected_corrections}
              : BranchStart{};
  if (options.method == Method::arclength)
    return {from ? pseudo_arclength(problem, *from, record, corrector, options, hooks)
                 : pseudo_arclength(problem, guess, direction, corrector, options, hooks, start),
            -1};
  const auto* periodic = dynamic_cast<const core::PeriodicOrbitProblem*>(&problem);
  const NaturalParameter parameter =
      (periodic && settings.natural_parameter == "period")
          ? NaturalParameter::of_unknown(periodic->period_index(), "period",
                                         settings.natural_direction)
          : NaturalParameter::of_observable(settings.natural_parameter, settings.natural_direction);
  if (options.method == Method::natural)
    return {from ? natural(problem, *from, record, parameter, corrector, options, hooks)
                 : natural(problem, guess, parameter, corrector, options, hooks, start),
            -1};
  return from ? natural_then_arclength(problem, *from, record, parameter, corrector, options, hooks)
              : natural_then_arclength(problem, guess, parameter, corrector, options, hooks, start);
}

std::optional<std::string> given_on_command_line(const std::vector<std::string>& words,
                                                 const std::string& key) {
  const std::string flag = "--" + key;
  for (std::size_t i = 0; i < words.size(); ++i) {
    if (words[i] == flag) return i + 1 < words.size() ? words[i + 1] : std::string();
    if (words[i].rfind(flag + "=", 0) == 0) return words[i].substr(flag.size() + 1);
  }
  return std::nullopt;
}

po::options_description trace_keys_beyond(const ProblemPlugin& plugin,
                                          const po::options_description& keys) {
  po::options_description extra("keys of a trace's scene (unused here)");
  if (!plugin.can_trace()) return extra;
  po::options_description trace = plugin.scene_keys();
  trace.add(continuation_keys(trace));
  for (const auto& option : trace.options())
    if (!keys.find_nothrow(option->long_name(), false)) extra.add(option);
  return extra;
}

}  // namespace backbone::cli
