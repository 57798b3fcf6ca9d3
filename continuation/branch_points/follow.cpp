#include "continuation/branch_points/follow.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "continuation/methods/pseudo_arclength.hpp"
#include "continuation/outputs.hpp"
#include "continuation/scaled_problem.hpp"
#include "core/errors.hpp"
#include "core/io/table.hpp"
#include "core/orbits/periodic_orbit.hpp"

namespace backbone::continuation {

namespace {}  // namespace

FollowSelection parse_follow(const std::string& text) {
  FollowSelection s;
  if (text == "none") return s;
  if (text == "all") {
    s.kind = FollowSelection::Kind::all;
    s.doublings = true;
    return s;
  }
  if (text == "doubling") {
    s.doublings = true;
    return s;
  }
  try {
    std::size_t used = 0;
    const long k = std::stol(text, &used);
    if (used == text.size() && k >= 1 && k <= std::numeric_limits<int>::max()) {
      s.kind = FollowSelection::Kind::one;
      s.k = static_cast<int>(k);
      return s;
    }
  } catch (const std::exception&) {
  }
  throw core::InputError(
      "follow",
      fmt::format("must be none, all, doubling or a row K >= 1 of branch_points.csv (got '{}')",
                  text));
}

std::optional<AttachedStart> attached_start(const core::Problem& problem,
                                            const BranchPointReport& report,
                                            const std::string& observable, int rank) {
  if (report.x.size() == 0 || rank < 0) return std::nullopt;
  const ScaledProblem scaled(problem);
  const core::Vector zx = scaled.to_scaled(report.x);
  const double fx = core::observable_value(problem.observables(report.x), observable);
  std::vector<AttachedStart> starts;
  for (std::size_t i = 0; i < report.attached_points.size(); ++i) {
    const core::Vector& y = report.attached_points[i];
    const double distance = (scaled.to_scaled(y) - zx).norm();
    const double change = core::observable_value(problem.observables(y), observable) - fx;
    if (!(distance > 0) || !std::isfinite(change)) continue;
    const double sign = change < 0 ? -1.0 : 1.0;
    starts.push_back({report.x + sign * (y - report.x), sign * (y - report.x), static_cast<int>(i),
                      std::abs(change) / distance});
  }
  std::stable_sort(
      starts.begin(), starts.end(),
      [](const AttachedStart& a, const AttachedStart& b) { return a.growth > b.growth; });
  if (rank >= static_cast<int>(starts.size())) return std::nullopt;
  return starts[static_cast<std::size_t>(rank)];
}

FollowedBranch follow_attached(const core::Problem& problem, const BranchPointReport& report,
                               const std::string& observable, core::Corrector& corrector,
                               const ContinuationOptions& options, const ContinuationHooks& hooks,
                               int start_rank) {
  FollowedBranch f;
  if (!report.verified()) {
    f.message = "not verified (no attached direction found by the probes): not followed";
    return f;
  }
  f.start = attached_start(problem, report, observable, start_rank);
  if (!f.start) {
    f.message = fmt::format("no probed point with a finite {}: not followed", observable);
    return f;
  }
  ContinuationOptions o = options;
  o.method = Method::arclength;
  o.branch_points.detect = false;
  // The followed family's first tangent comes from the Jacobian at its start (nearest the probe's
  // secant), whatever the traced branch's own first step did.
  o.start_along_direction = false;
  // A family of several dimensions is often followed along a face, where J is one side's.
  o.boundary.verify_inside = true;
  if (o.branch_points.max_turn_degrees > 0)
    o.branch_points.max_turn_degrees =
        std::max(o.branch_points.max_turn_degrees, follow_max_turn_degrees);
  f.branch = pseudo_arclength(problem, f.start->guess, f.start->direction, corrector, o, hooks);
  f.message = f.branch.message;
  return f;
}

core::NewtonOptions follow_newton_options(const core::NewtonOptions& newton,
                                          const ContinuationOptions& options) {
  core::NewtonOptions o = newton;
  o.rank_cutoff = std::max(o.rank_cutoff, options.rank.relative_threshold);
  return o;
}

std::vector<FollowedBranch> follow_branch_points(
    const core::Problem& problem, const Branch& branch, const FollowRun& run,
    core::Corrector& corrector, const ContinuationOptions& options, const ContinuationHooks& hooks,
    const std::filesystem::path& out,
    const std::function<void(const std::filesystem::path&, const Branch&)>& extra,
    const std::map<std::string, std::string>& units) {
  std::vector<FollowedBranch> followed;
  ContinuationOptions o = options;
  o.max_points = run.max_points;
  // The verified rank report (one probe per candidate direction, up to 19 at the contact bar's
  // T = 3.6 point at 100 intervals) cost 30-50 s per followed point there: every 10th point.
  if (o.rank_check_every > 0) o.rank_check_every = std::max(o.rank_check_every, 10);
  const auto* periodic = dynamic_cast<const core::PeriodicOrbitProblem*>(&problem);
  for (std::size_t i = 0; i < branch.branch_points.size(); ++i) {
    const int k = static_cast<int>(i) + 1;
    if (hooks.cancel_requested && hooks.cancel_requested()) break;  // the rest left as they are
    if (!run.selection.selects(k)) continue;
    const BranchPointReport& report = branch.branch_points[i];
    if (!report.verified() && run.selection.kind == FollowSelection::Kind::all) continue;
    const std::filesystem::path dir = out / fmt::format("branch_point_{}", k);
    std::filesystem::remove_all(dir);
    FollowedBranch f;
    if (!report.verified()) {  // only its summary.txt, no empty branch files
      std::filesystem::create_directories(dir);
      f = follow_attached(problem, report, run.observable, corrector, o, hooks);
    } else {
      // A start whose branch ends early, or at the family's boundary (a face of a family of
      // several dimensions, where another start may reach the budget), is retried from the next
      // fastest probe. The files hold the last attempt, or the first that ended at the
      // boundary when every later one ended early (its points kept and written again).
      auto attempt_from = [&](int attempt) {
        BranchWriter writer(dir, periodic);
        ContinuationHooks h = hooks;
        h.on_point = [&](const BranchPoint& p) { writer.append(p); };
        h.on_branch_point = nullptr;
        h.on_attempt = nullptr;
        FollowedBranch g =
            follow_attached(problem, report, run.observable, corrector, o, h, attempt);
        g.attempts = attempt + 1;
        return g;
      };
      const auto cancelled = [&] { return hooks.cancel_requested && hooks.cancel_requested(); };
      std::optional<FollowedBranch> at_boundary;
      int attempts = 0;
      for (int attempt = 0; attempt < std::max(1, run.start_attempts); ++attempt) {
        if (attempt > 0 && !attached_start(problem, report, run.observable, attempt)) break;
        f = attempt_from(attempt);
        attempts = attempt + 1;
        if (cancelled()) break;
        if (f.branch.reason == StopReason::boundary_reached) {
          if (!at_boundary) at_boundary = f;
          continue;
        }
        if (!f.branch.ended_early()) break;
      }
      if (f.branch.ended_early() && at_boundary && !cancelled()) {
        BranchWriter writer(dir, periodic);
        for (const BranchPoint& p : at_boundary->branch.points) writer.append(p);
        f = std::move(*at_boundary);
        f.attempts = attempts;
      }
    }
    f.branch_point = k;
    std::optional<core::Table> table;
    if (!f.branch.points.empty()) {
      table = core::Table::read_csv(dir / "branch.csv");
      plot_branch(dir, *table,
                  fmt::format("attached at branch point {} ({} points)", k, f.branch.points.size()),
                  units);
      if (extra) extra(dir, f.branch);
    }
    core::write_text_atomically(
        dir / "summary.txt",
        fmt::format(
            "branch_point {}\npoints {}\nstart_probe {}\nattempts {}\nstop_reason {}\nmessage "
            "{}\njacobian {}\ndimension_inside {}\n{}",
            k, f.branch.points.size(), f.start ? f.start->probe : -1, f.attempts,
            f.branch.points.empty() ? "-" : to_string(f.branch.reason), f.message,
            problem.jacobian_description(),
            std::count_if(
                f.branch.points.begin(), f.branch.points.end(),
                [](const BranchPoint& p) { return p.dimension_flag == DimensionFlag::inside; }),
            stability_counts(table ? &*table : nullptr)));
    followed.push_back(std::move(f));
  }
  return followed;
}

std::string follow_line(const FollowedBranch& f, const std::string& observable) {
  if (f.branch.points.empty()) return fmt::format("branch point {}: {}", f.branch_point, f.message);
  double e_lo = std::numeric_limits<double>::infinity(), e_hi = -e_lo;
  double t_lo = e_lo, t_hi = -e_lo;
  for (const BranchPoint& p : f.branch.points) {
    const double e = p.observable(observable), t = p.observable("period");
    e_lo = std::min(e_lo, e);
    e_hi = std::max(e_hi, e);
    t_lo = std::min(t_lo, t);
    t_hi = std::max(t_hi, t);
  }
  return fmt::format(
      "branch point {}: {} points, {} in [{:.4g}, {:.4g}], period varies by {:.2e} "
      "(relative), {} ({})",
      f.branch_point, f.branch.points.size(), observable, e_lo, e_hi,
      (t_hi - t_lo) / std::abs(t_lo), to_string(f.branch.reason), f.message);
}

}  // namespace backbone::continuation
