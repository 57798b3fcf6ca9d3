#include "continuation/cli/trace_run.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "continuation/branch.hpp"
#include "continuation/branch_points/follow.hpp"
#include "continuation/cli/progress.hpp"
#include "continuation/cli/stability_report.hpp"
#include "continuation/orbit_bifurcations/doubling.hpp"
#include "core/errors.hpp"
#include "core/io/output_folder.hpp"
#include "core/io/scene_ini.hpp"
#include "core/io/table.hpp"
#include "core/stability/floquet.hpp"

namespace backbone::cli {

namespace {

// The scene key a side of a bound came from (continuation::Bound), else its observable's name.
std::string bound_key(const continuation::Bound& b, bool max_side) {
  const std::string& key = max_side ? b.max_key : b.min_key;
  return key.empty() ? b.observable : key;
}

// The value of observable `name` at the start; InputError naming `key` when the problem has no
// observable of that name.
double observable_at_start(const core::Observables& at_start, const std::string& name,
                           const std::string& key, const core::Problem& problem) {
  std::vector<std::string> names;
  for (const auto& [observable, value] : at_start) {
    if (observable == name) return value;
    names.push_back(observable);
  }
  throw core::InputError(key, fmt::format("'{}' is not an observable of {} (its observables: {})",
                                          name, problem.name(), fmt::join(names, ", ")));
}

// Every bound names an observable of the problem, and a fresh start lies inside every bound: a
// start outside would end the branch at its first point.
void check_bounds(const core::Problem& problem, const core::Observables& at_start,
                  const continuation::ContinuationOptions& options, bool restarting) {
  for (const continuation::Bound& b : options.bounds) {
    const double start =
        observable_at_start(at_start, b.observable, bound_key(b, std::isfinite(b.max)), problem);
    if (restarting || !std::isfinite(start)) continue;
    // A start on a bound (within rounding of the guess) is a branch's own end, as at a grazing
    // limit; one beyond it by more is outside the window.
    const auto beyond = [start](double bound, double sign) {
      return sign * (start - bound) > 1e-6 * std::max(std::abs(start), std::abs(bound));
    };
    if (beyond(b.min, -1) || beyond(b.max, 1)) {
      const bool below = beyond(b.min, -1);
      throw core::InputError(
          bound_key(b, !below),
          fmt::format("the starting orbit's {} {:.6g} lies {} {:g}: the branch would end at its "
                      "first point",
                      b.observable, start, below ? "below" : "above", below ? b.min : b.max));
    }
  }
}

// The natural methods' parameter: the period of a periodic-orbit problem, or an observable.
void check_natural_parameter(const RunSettings& run, const core::Problem& problem,
                             const core::Observables& at_start, bool periodic) {
  if (run.options.method == continuation::Method::arclength) return;
  if (periodic && run.natural_parameter == "period") return;
  observable_at_start(at_start, run.natural_parameter, "natural_parameter", problem);
}

// A resumed run appends rows to the saved branch.csv: its columns must be the ones this run
// writes (another version, or another problem, wrote other ones).
void check_saved_columns(const std::filesystem::path& dir, const core::Observables& at_start,
                         bool with_multipliers) {
  continuation::BranchPoint point;
  point.observables = at_start;
  if (with_multipliers) point.floquet = core::undecided_floquet(0);
  continuation::Branch one;
  one.points.push_back(point);
  const std::vector<std::string> expected = continuation::branch_table(one).columns();
  const std::vector<std::string> saved = core::Table::read_csv(dir / "branch.csv").columns();
  if (saved != expected)
    throw core::InputError(
        "resume", fmt::format("'{}' has the columns {}, this run writes {}: resume it with the "
                              "version that wrote it, or --start DIR:K into a new folder",
                              (dir / "branch.csv").string(), fmt::join(saved, ","),
                              fmt::join(expected, ",")));
}

}  // namespace

TraceRun prepare_trace(const ProblemPlugin& entry, core::Scene scene_in,
                       std::filesystem::path resume) {
  TraceRun t;
  t.entry = &entry;
  t.resume = std::move(resume);
  t.scene = std::move(scene_in);
  const core::Scene& scene = t.scene;
  t.branch_name = scene.has("branch") ? scene.text("branch") : entry.branches.at(0);
  if (!entry.has_branch(t.branch_name))
    throw core::InputError("branch", fmt::format("'{}' is not a branch of {} (known: {})",
                                                 t.branch_name, entry.name, entry.branch_list()));
  t.out =
      scene.has("out") ? scene.text("out") : fmt::format("out/{}_{}", entry.name, t.branch_name);
  core::check_output_folder("out", t.out);
  t.run = read_run_settings(scene);
  continuation::ContinuationOptions& options = t.run.options;
  const long start_direction = scene.integer("direction", -1);
  if (start_direction != 1 && start_direction != -1)
    throw core::InputError("direction", fmt::format("must be 1 or -1 (got {})", start_direction));
  if (!scene.values()["direction"].defaulted() && !scene.has("start") && t.resume.empty())
    throw core::InputError("direction",
                           "applies with --start DIR:K or --resume DIR only (the way "
                           "the saved branch goes on)");

  t.setup = entry.setup(scene, t.branch_name);
  if (t.setup.check_for_trace) t.setup.check_for_trace();
  if (!t.setup.problem) throw core::InputError("problem", "setup returned no problem");
  const core::Problem& problem = *t.setup.problem;
  t.setup.apply_branch_options(options, t.run.newton_options);
  t.corrector = core::make_corrector(t.run.newton, t.run.newton_options);
  t.follow_corrector = core::make_corrector(
      t.run.newton, continuation::follow_newton_options(t.run.newton_options, options));
  t.periodic = dynamic_cast<core::PeriodicOrbitProblem*>(t.setup.problem.get());
  if (t.periodic) t.periodic->set_formulation(t.run.formulation);
  t.direction = t.setup.direction;
  if (t.direction.size() == 0)
    t.direction =
        core::Vector::Unit(problem.num_unknowns(),
                           t.periodic ? t.periodic->period_index() : problem.num_unknowns() - 1);

  const std::string restart_key = t.resume.empty() ? "start" : "resume";
  if (!t.resume.empty()) {
    t.lock = std::make_unique<core::FolderLock>("resume", t.resume);
    continuation::check_saved_files(t.resume, "resume");
    const int last = continuation::repair_branch_files(t.resume, "resume");
    int from = -1;
    // A detecting resume along the branch takes up the saved candidates, from the point where
    // the list is complete, when that point's state continues this run bit for bit; else it
    // goes on from the last point, and branch_points.csv's saved rows are merged.
    if (options.branch_points.detect && start_direction > 0)
      if (auto r = continuation::branch_point_resume(t.resume, last, problem, "resume")) {
        const continuation::RestartPoint at =
            continuation::restart_point(t.resume, r->point, options, "resume");
        if (at.state && continuation::state_mismatch(*at.state, problem, options).empty()) {
          from = r->point;
          t.saved_branch_points = std::move(r->saved);
          if (from < last) t.resume_drops_after = last;
        }
      }
    t.restart = continuation::restart_point(t.resume, from, options, "resume");
    // Killed or interrupted after its last point (during its outputs or follows): those are
    // done again, from a branch that holds the last point (not written again:
    // TraceReport::on_point).
    const std::string status = core::read_text_value(t.resume / "summary.txt", "status");
    t.restart->loop_complete = t.restart->index + 1 == options.max_points &&
                               (status == "running" || status == "interrupted");
    t.restart->record_saved_point = t.restart->loop_complete;  // else it is in the files
  } else if (scene.has("start")) {
    const auto [dir, point] = continuation::parse_saved_point(scene.text("start"), "start");
    continuation::check_saved_files(dir, "start");
    std::error_code same_error;
    if (std::filesystem::equivalent(dir, t.out, same_error))
      throw core::InputError("out", fmt::format("'{}' is the folder --start reads from: its "
                                                "points would be overwritten (write elsewhere, "
                                                "or --resume {} to go on in it)",
                                                t.out.string(), dir.string()));
    t.restart = continuation::restart_point(dir, point, options, "start");
  }
  if (t.restart)
    continuation::take_up(*t.restart, restart_key, static_cast<int>(start_direction), problem,
                          options, t.setup.guess, t.direction);
  if (t.restart && t.resume.empty()) {  // --start: a new branch counts its own refusals
    t.restart->rejected_corrections = 0;
    if (t.restart->state) {
      auto own = std::make_shared<continuation::LoopState>(*t.restart->state);
      own->rejected_corrections = 0;
      t.restart->state = std::move(own);
    }
  }
  const core::Observables at_start = problem.observables(t.setup.guess);
  if (t.restart && !t.resume.empty())
    check_saved_columns(t.resume, at_start,
                        options.stability && dynamic_cast<const core::FloquetProblem*>(&problem));

  const int n = problem.num_unknowns(), m = problem.num_equations();
  if (m != n - 1 && t.corrector->name() == "kinsol")
    throw core::InputError("newton", fmt::format("kinsol solves square systems only; this {} "
                                                 "residual has {} equations for {} unknowns "
                                                 "(use newton = eigen, least squares)",
                                                 entry.name, m, n));
  check_bounds(problem, at_start, options, t.restart.has_value());
  check_natural_parameter(t.run, problem, at_start, t.periodic != nullptr);
  if (t.restart && !t.resume.empty() && !t.restart->note.empty()) {
    // The saved states belong to another run's loop: the folder keeps none of them.
    continuation::forget_saved_states(t.resume);
    fmt::print(stderr,
               "backbone trace: the saved loop states do not fit this run ({}); "
               "the last point is corrected again and state.txt keeps no other run's states\n",
               t.restart->note);
  }
  // A consistent overdetermined system (m > n - 1) still has curves of solutions.
  t.expected_dimension =
      t.setup.covered_dimension > 0 ? t.setup.covered_dimension : n - std::min(m, n - 1);
  return t;
}

void print_trace_header(TraceRun& t) {
  if (!t.scene.has("branch"))
    fmt::print("branch {}: the first of {}'s branches ({}; choose with --branch NAME)\n",
               t.branch_name, t.entry->name, fmt::join(t.entry->branches, ", "));
  const continuation::ContinuationOptions& options = t.options();
  const core::Problem& problem = t.problem();
  fmt::print("{} / {}: {} equations in {} unknowns, expected manifold dimension {}{}\n",
             t.entry->name, t.branch_name, problem.num_equations(), problem.num_unknowns(),
             t.expected_dimension,
             t.setup.covered_dimension > 0
                 ? " (covered by the problem's own outputs from the corrected start below)"
                 : "");
  const auto& restart = t.restart;
  fmt::print("  {} continuation, {} predictor, newton {}, {}{}{}{}\n",
             continuation::to_string(options.method), continuation::to_string(options.predictor),
             t.corrector->name(),
             t.periodic ? fmt::format("formulation {}, ", core::scene_name(t.run.formulation)) : "",
             "jacobian " + t.problem().jacobian_description() + ", ",
             fmt::format("ds {:g} in [{:g}, {:g}], at most {} points", options.ds, options.ds_min,
                         options.ds_max, options.max_points),
             restart ? fmt::format(", restarting from point {} ({})", restart->index,
                                   restart->state ? "its saved loop state"
                                                  : "corrected again: " + (restart->note.empty()
                                                                               ? "no saved state"
                                                                               : restart->note))
                     : "");
  if (restart && restart->loop_complete)
    fmt::print(
        "  the saved branch has its {} points: its outputs, stability and follows are done "
        "again\n",
        options.max_points);
  if (t.resume_drops_after >= 0)
    fmt::print(
        "  points {} to {} are traced again, from the last point whose branch points had all "
        "been located (branch_points.txt)\n",
        restart->index + 1, t.resume_drops_after);
}

namespace {
TraceRun& locked(TraceRun& t) {
  if (!t.lock) t.lock = std::make_unique<core::FolderLock>("out", t.out);
  return t;
}

// The files of a resumed run cut after its restart point when it lies before their last point
// (TraceRun::resume_drops_after), before the writer appends to them.
TraceRun& cut(TraceRun& t) {
  if (t.resume_drops_after >= 0)
    continuation::repair_branch_files(t.resume, "resume", t.restart->index);
  return t;
}
}  // namespace

TraceReport::TraceReport(TraceRun& t)
    : t_(cut(locked(t))),
      writer_(t.out, t.periodic, t.restart.has_value() && !t.resume.empty()),
      progress_(t.options()) {
  if (!t.options().branch_points.detect) return;
  // The list holds every candidate of the branch from a fresh start or a taken-up list only. A
  // resume that took none up keeps none: a later resume merges branch_points.csv's rows.
  keep_list_ = t.resume.empty() || t.saved_branch_points.has_value();
  if (!keep_list_) {
    std::filesystem::remove(t.out / "branch_points.txt");
    return;
  }
  if (t.saved_branch_points) located_ = *t.saved_branch_points;
  located_.write(t.out);
}

continuation::ContinuationHooks TraceReport::hooks(const std::optional<StopSignals>& stop) {
  continuation::ContinuationHooks hooks;
  hooks.cancel_requested = [&stop] { return stop.has_value() && stop->requested(); };
  hooks.on_point = [this](const continuation::BranchPoint& p) { on_point(p); };
  hooks.reject_point = t_.setup.reject_point;
  hooks.describe_branch_point = t_.setup.describe_branch_point;
  // Located candidates as they come (located on the detector's thread, reported on the loop's a
  // few points after the bracket that holds them; continuation/README.md, 'Branch points'),
  // between the point lines, and kept in branch_points.txt.
  hooks.on_branch_point = [this](const continuation::BranchPointReport& r) {
    if (keep_list_) {
      located_.reports.push_back(r);
      located_.write(t_.out);
    }
    progress_.finish();
    fmt::print("  {}\n", branch_point_line(r));
    std::fflush(stdout);
  };
  hooks.on_brackets_settled = [this](int settled) {
    if (!keep_list_) return;
    located_.settled = settled;
    located_.write(t_.out);
  };
  hooks.on_attempt = [this](const continuation::StepAttempt& a) {
    if (a.rejection.empty()) return;
    fmt::print("  point {:4d}  rejected at ds {:.3g}: {}\n", a.point, a.ds, a.rejection);
  };
  return hooks;
}

namespace {
// A summary count, "-" when the run has none of that kind.
std::string count_text(long n) {
  return n < 0 ? "-" : std::to_string(n);
}
}  // namespace

std::string TraceReport::summary(const std::string& status, const continuation::Branch* branch,
                                 int switch_index) const {
  const core::Problem& problem = t_.problem();
  return fmt::format(
      "problem {}\nbranch {}\nstatus {}\nequations {}\nunknowns {}\nexpected_dimension {}\n"
      "method {}\nnewton {}\nformulation {}\njacobian {}\npoints {}\nrejected_corrections {}\n"
      "switch_index {}\nstop_reason {}\nmessage {}\ndimension_rechecked {}\n"
      "dimension_unconfirmed {}\ndimension_above_expected {}\n{}branch_points_located {}\n"
      "branch_points_verified {}\n",
      t_.entry->name, t_.branch_name, status, problem.num_equations(), problem.num_unknowns(),
      t_.expected_dimension, continuation::to_string(t_.run.options.method), t_.corrector->name(),
      t_.periodic ? core::scene_name(t_.run.formulation) : "-", problem.jacobian_description(),
      points_in_files, branch ? count_text(branch->rejected_corrections) : "-", switch_index,
      branch ? continuation::to_string(branch->reason) : "-", branch ? branch->message : "-",
      dimension_flags_[1], dimension_flags_[2], dimension_above_,
      stability_.empty() ? continuation::stability_counts(nullptr) : stability_,
      count_text(branch_points_[0]), count_text(branch_points_[1]));
}

void TraceReport::count_branch_points(const core::Table& branch_points_csv) {
  const std::vector<double> verified = branch_points_csv.column("verified");
  branch_points_[0] = static_cast<long>(verified.size());
  branch_points_[1] = std::count(verified.begin(), verified.end(), 1.0);
}

void TraceReport::count_points(const core::Table& branch_csv) {
  stability_ = continuation::stability_counts(&branch_csv);
  const std::vector<double> flags = branch_csv.column("dimension_flag");
  const std::vector<double> dimensions = branch_csv.column("dimension");
  std::fill(std::begin(dimension_flags_), std::end(dimension_flags_), 0);
  dimension_above_ = 0;
  for (std::size_t i = 0; i < flags.size(); ++i) {
    const int flag = static_cast<int>(flags[i]);
    if (flag >= 0 && flag < 3) ++dimension_flags_[flag];
    if (dimensions[i] > t_.expected_dimension) ++dimension_above_;
  }
}

void TraceReport::on_point(const continuation::BranchPoint& p) {
  if (t_.restart && !t_.resume.empty() && p.index == t_.restart->index) return;  // in the files
  writer_.append(p);
  if (p.dimension_flag != continuation::DimensionFlag::as_verified)
    fmt::print(stderr, "backbone trace: point {}: {}\n", p.index,
               continuation::dimension_warning(p));
  // A verified dimension above the expected one is a finding, not noise: other families pass
  // through the point (continuation/README.md, 'What a branch records'). Said where it changes;
  // summary.txt counts such points (count_points).
  if (p.dimension > t_.expected_dimension) {
    if (p.dimension != last_dimension_)
      fmt::print(stderr,
                 "backbone trace: point {}: verified dimension {} where the branch expects {} "
                 "({} of {} candidate directions re-corrected): other families of solutions pass "
                 "through here\n",
                 p.index, p.dimension, t_.expected_dimension, p.dimension,
                 p.rank ? p.rank->nullity : -1);
  }
  if (p.dimension >= 0) last_dimension_ = p.dimension;
  progress_.finish();  // the point's line replaces the progress line, which follows it
  fmt::print("  {}{}\n", point_line(p),
             t_.setup.describe_point ? "  " + t_.setup.describe_point(p) : "");
  std::fflush(stdout);
  progress_.update(p);
}

namespace {

// Every period doubling of `found` followed onto the branch of twice the period, into
// out/period_doubling_K/ (K: 1-based among the period doublings), with its own stability.
bool follow_doublings(TraceRun& t, const std::vector<continuation::OrbitBifurcation>& found,
                      core::Corrector& corrector, const continuation::ContinuationHooks& hooks) {
  bool complete = true;
  int k = 0;
  for (const continuation::OrbitBifurcation& b : found) {
    if (b.type != "period_doubling") continue;
    const std::filesystem::path dir = t.out / fmt::format("period_doubling_{}", ++k);
    std::filesystem::remove_all(dir);
    continuation::ContinuationOptions o = t.options();
    o.max_points = t.run.follow.max_points;
    std::unique_ptr<continuation::BranchWriter> writer;
    continuation::ContinuationHooks h = hooks;
    h.on_point = [&](const continuation::BranchPoint& p) {
      if (!writer) writer = std::make_unique<continuation::BranchWriter>(dir, nullptr);
      writer->append(p);
    };
    const continuation::DoubledBranch d =
        continuation::follow_period_doubling(t.problem(), b, corrector, o, h);
    fmt::print("  followed period doubling {}: {} points ({})\n", k, d.branch.points.size(),
               d.message);
    if (d.branch.points.empty() || d.branch.ended_early()) complete = false;
    if (d.branch.points.empty()) continue;
    continuation::plot_branch(dir, core::Table::read_csv(dir / "branch.csv"),
                              fmt::format("{} / period doubling {} ({} points)", t.entry->name, k,
                                          d.branch.points.size()),
                              t.entry->units, t.entry->branch_axes);
    report_stability(*d.problem, d.branch, o.floquet, corrector, dir);
  }
  return complete;
}

}  // namespace

void add_saved_branch_points(const TraceRun& t, continuation::Branch& branch) {
  if (!t.saved_branch_points) return;
  const auto& saved = t.saved_branch_points->reports;
  branch.branch_points.insert(branch.branch_points.begin(), saved.begin(), saved.end());
  branch.branch_points_from = 0;  // every candidate of the branch is in the list
}

bool write_outputs_and_follow(TraceRun& t, TraceReport& report, const continuation::Branch& traced,
                              const continuation::ContinuationHooks& hooks) {
  const continuation::ContinuationOptions& options = t.options();
  // A stop request (SIGINT, SIGTERM) skips the stages not yet begun: --resume does them.
  const auto stopping = [&hooks] { return hooks.cancel_requested && hooks.cancel_requested(); };
  // A resumed loop that added no point (its first step reached a bound): the branch is the saved
  // points, whose outputs a killed run may not have written.
  continuation::Branch saved;
  if (traced.points.empty() && !t.resume.empty() && t.restart) {
    saved = continuation::whole_branch(
        t.out, t.problem(), traced, options.stability && !stopping() ? &options.floquet : nullptr);
    if (saved.branch_points_from < 0) saved.branch_points_from = t.restart->index + 1;
  }
  const continuation::Branch& branch = saved.points.empty() ? traced : saved;
  bool followed_complete = true;
  if (options.branch_points.detect) {
    const auto verified =
        std::count_if(branch.branch_points.begin(), branch.branch_points.end(),
                      [](const continuation::BranchPointReport& r) { return r.verified(); });
    fmt::print("branch points located {}: {} ({} verified; branch_points.csv)\n",
               t.resume.empty() || t.saved_branch_points ? "on this branch" : "by this run",
               branch.branch_points.size(), verified);
  }
  const continuation::FollowSelection& selection = t.run.follow.selection;
  if (selection.kind == continuation::FollowSelection::Kind::one &&
      selection.k > static_cast<int>(branch.branch_points.size())) {
    fmt::print(stderr,
               "backbone trace: --follow {}: {} {} located branch points (branch_points.csv), "
               "nothing to follow\n",
               selection.k,
               t.resume.empty() || t.saved_branch_points ? "the branch has" : "this run has",
               branch.branch_points.size());
    followed_complete = false;
  }
  if (branch.points.empty()) return followed_complete;
  const core::Table table = core::Table::read_csv(t.out / "branch.csv");
  report.points_in_files = table.rows();
  report.count_points(table);  // the whole branch, a resumed run's saved points included
  if (t.setup.covered_dimension == 0)
    continuation::plot_branch(
        t.out, table,
        fmt::format("{} / {} ({} points)", t.entry->name, t.branch_name, table.rows()),
        t.entry->units, t.entry->branch_axes);
  continuation::write_after_run(t.out, t.problem(), branch, !t.resume.empty(),
                                options.branch_points.detect,
                                stopping() ? nullptr : t.setup.write_extra_outputs);
  if (options.branch_points.detect)
    report.count_branch_points(core::Table::read_csv(t.out / "branch_points.csv"));
  if (stopping()) {
    fmt::print(
        "stop requested: the problem's outputs over the whole branch, its stability and "
        "the follows are left to --resume\n");
    return false;
  }
  if (options.stability) {
    const continuation::Branch whole =
        t.resume.empty() ? branch
                         : continuation::whole_branch(t.out, t.problem(), branch, &options.floquet);
    const auto corrector = core::make_corrector(t.run.newton, t.run.newton_options);
    const auto found = report_stability(t.problem(), whole, options.floquet, *corrector, t.out);
    if (selection.doublings)
      followed_complete = follow_doublings(t, found, *corrector, hooks) && followed_complete;
  }
  for (const auto& f : continuation::follow_branch_points(
           t.problem(), branch, t.run.follow, *t.follow_corrector, options, hooks, t.out,
           t.setup.write_extra_outputs, t.entry->units)) {
    fmt::print("  followed {}\n", continuation::follow_line(f));
    followed_complete = followed_complete && !f.branch.points.empty() && !f.branch.ended_early();
  }
  return followed_complete;
}

}  // namespace backbone::cli
