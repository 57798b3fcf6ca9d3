// Bench case branch_point_cost (bench.hpp): what detecting branch points adds to the mode-1 trace
// of the paper scene (`--branch mode1 --shooting_elements N --energy_max 1e-2`, N = 100 and
// 200), against the accuracy of what it finds. Three runs in-process, as `backbone trace` runs
// them (the continuation alone: no process start, output files or figure), alternated round by
// round so that the machine's drifts of speed fall on all three alike, and their medians
// compared:
//   plain              no detection;
//   detect             detection, the candidates located and verified on a second thread
//                      (the default, continuation/README.md 'Branch points');
//   detect_one_thread  the same on the loop's thread (--locate_in_background false).
// Accuracy: every point's closed-form frequency error (mode 1 stays mode 1), and each verified
// candidate's period against the value it approaches, the nearest of 3.6, 3.5, 3.25 and 3.2 L/c
// (problems/contact_bar/orbits/README.md, 'Dimension changes': the attached families sit at these
// periods; the CLI test asserts T = 3.2 from the closed form).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "continuation/cli/bench_report.hpp"
#include "continuation/cli/plugin.hpp"
#include "core/errors.hpp"
#include "core/io/table.hpp"
#include "problems/contact_bar/bench/cases.hpp"
#include "problems/contact_bar/bench/support.hpp"
#include "problems/contact_bar/cli/trace.hpp"

namespace backbone::contact_bar {

namespace {

struct Variant {
  std::string name;
  std::vector<std::string> keys;  // on top of the mode-1 trace's keys
  std::vector<double> wall, cpu;
  bench::InProcessTrace last;
  std::vector<double> errors;  // closed-form frequency errors of the last run
};

// |T / T_r - 1| for the nearest T_r of the attached families' periods.
double period_offset(double period) {
  double best = std::numeric_limits<double>::infinity();
  for (double t : {3.6, 3.5, 3.25, 3.2}) best = std::min(best, std::abs(period / t - 1));
  return best;
}

// BACKBONE_BRANCH_POINT_COST_RUNS, default 5; InputError outside 1..100.
long branch_point_cost_rounds() {
  const char* runs_env = std::getenv("BACKBONE_BRANCH_POINT_COST_RUNS");
  const long rounds = runs_env && *runs_env ? std::strtol(runs_env, nullptr, 10) : 5;
  if (rounds < 1 || rounds > 100)
    throw core::InputError("BACKBONE_BRANCH_POINT_COST_RUNS",
                           fmt::format("must be in 1..100 (got '{}')", runs_env));
  return rounds;
}

// The three variants at one grid, run round by round in turn.
std::array<Variant, 3> run_variants(const cli::ProblemPlugin& plugin, int elements, long rounds) {
  std::array<Variant, 3> variants;
  variants[0].name = "plain";
  variants[1].name = "detect";
  variants[1].keys = {"--detect_branch_points", "true"};
  variants[2].name = "detect_one_thread";
  variants[2].keys = {"--detect_branch_points", "true", "--locate_in_background", "false"};
  for (long round = 0; round < rounds; ++round)
    for (Variant& v : variants) {
      std::vector<std::string> args = {"--shooting_elements", std::to_string(elements),
                                       "--energy_max", "1e-2"};
      args.insert(args.end(), v.keys.begin(), v.keys.end());
      const core::Scene scene = bench::read_paper_scene(plugin, args);
      v.last = bench::trace_in_process(plugin, scene, "mode1");
      v.wall.push_back(v.last.wall_seconds);
      v.cpu.push_back(v.last.cpu_seconds);
      if (round == 0) v.errors = bench::mode1_frequency_errors(scene, v.last.traced.branch);
    }
  return variants;
}

// One variant's medians against the plain one's, and what its verified candidates found.
struct VariantSummary {
  bool complete = false;
  int verified = 0;
  double worst_offset = std::nan("");    // of the verified candidates' periods
  double wall = 0, cpu = 0;              // medians
  double added_wall = 0, added_cpu = 0;  // percent over plain
  double worst_error = 0;
};

VariantSummary summarize(const Variant& v, double plain_wall, double plain_cpu) {
  const continuation::Branch& b = v.last.traced.branch;
  VariantSummary s;
  s.complete = b.reason == continuation::StopReason::bound_reached;
  for (const continuation::BranchPointReport& r : b.branch_points) {
    if (!r.verified()) continue;
    ++s.verified;
    double period = std::nan("");
    for (const auto& [name, value] : r.observables)
      if (name == "period") period = value;
    const double offset = period_offset(period);
    s.worst_offset = std::isnan(s.worst_offset) ? offset : std::max(s.worst_offset, offset);
  }
  s.wall = bench::median(v.wall), s.cpu = bench::median(v.cpu);
  s.added_wall = 100 * (s.wall / plain_wall - 1), s.added_cpu = 100 * (s.cpu / plain_cpu - 1);
  s.worst_error =
      v.errors.empty() ? std::nan("") : *std::max_element(v.errors.begin(), v.errors.end());
  return s;
}

// The variant's row of the CSV, its line on stdout and its row of the section's table.
void report_variant(core::Table& table, std::string& rows, int elements, long rounds,
                    const Variant& v, const VariantSummary& s) {
  const continuation::Branch& b = v.last.traced.branch;
  table.add_cells({double(elements), v.name, double(rounds), double(b.points.size()),
                   s.complete ? 1.0 : 0.0, s.wall, *std::min_element(v.wall.begin(), v.wall.end()),
                   s.cpu, s.added_wall, s.added_cpu, double(b.branch_points.size()),
                   double(s.verified), s.worst_offset, s.worst_error});
  fmt::print(
      "  N = {:<4} {:<18} {} points{}  wall {:.3f} s ({:+.0f} %)  CPU {:.3f} s ({:+.0f} %)  {} "
      "candidates, {} verified, worst verified period offset {:.1e}, worst closed-form error "
      "{:.1e}\n",
      elements, v.name, b.points.size(), s.complete ? "" : " (stopped early: " + b.message + ")",
      s.wall, s.added_wall, s.cpu, s.added_cpu, b.branch_points.size(), s.verified, s.worst_offset,
      s.worst_error);
  rows += fmt::format(
      "| {} | {} | {} | {:.3f} | {:+.0f} % | {:.3f} | {:+.0f} % | {} / {} | {} | {:.1e} |\n",
      elements, v.name, b.points.size(), s.wall, s.added_wall, s.cpu, s.added_cpu, s.verified,
      b.branch_points.size(),
      std::isnan(s.worst_offset) ? std::string("-") : fmt::format("{:.1e}", s.worst_offset),
      s.worst_error);
}

// What detection adds at one grid, for the section.
std::string grid_verdict(int elements, const std::array<Variant, 3>& variants, double plain_wall,
                         double plain_cpu, bool first) {
  const double added = 100 * (bench::median(variants[1].wall) / plain_wall - 1);
  return fmt::format(
      "{}At N = {} detection adds {:.0f} % to the wall time ({}), {:.0f} % "
      "to the CPU time ({:.0f} % on one thread).",
      first ? "" : " ", elements, added,
      added <= 25 ? "within a 25 % budget" : "above a 25 % budget",
      100 * (bench::median(variants[1].cpu) / plain_cpu - 1),
      100 * (bench::median(variants[2].cpu) / plain_cpu - 1));
}

std::string branch_point_cost_section(long rounds, const std::string& rows,
                                      const std::string& verdicts) {
  return fmt::format(
      "## Mode 1 with branch-point detection: what it adds (`branch_point_cost`)\n\n"
      "`trace problems/contact_bar/scenes/paper.ini --branch mode1 --shooting_elements N "
      "--energy_max 1e-2`, without and with `--detect_branch_points true` (candidates located "
      "and verified on a second thread, or with `--locate_in_background false` on the "
      "loop's), run in-process (the continuation alone), {} rounds alternated, medians. "
      "Period offset: of each verified candidate from the nearest of 3.6, 3.5, 3.25, 3.2 "
      "L/c; closed-form error: the worst |omega / omega(E) - 1| over mode 1's points.\n\n"
      "| N | run | points | wall s | added | CPU s | added | verified / candidates | worst "
      "period offset | worst closed-form error |\n|---|---|---|---|---|---|---|---|---|---|\n"
      "{}\n{} The second core takes the location and verification off the loop's path; it "
      "does not make them cheaper. What the loop itself adds is the tangent predictor that "
      "detection keeps (continuation/README.md, 'Predictors'): the points column above "
      "counts its steps against the plain trace's.\n",
      rounds, rows, verdicts);
}

}  // namespace

int bench_branch_point_cost(const std::filesystem::path& out) {
  const long rounds = branch_point_cost_rounds();
  const cli::ProblemPlugin plugin = trace_plugin();
  fmt::print(
      "bench branch_point_cost: mode 1 of the paper scene to E = 1e-2 at 100 and 200 intervals, "
      "without and with branch-point detection, {} rounds alternated "
      "(BACKBONE_BRANCH_POINT_COST_RUNS), continuation in-process\n",
      rounds);
  int status = 0;
  core::Table table({"N", "variant", "rounds", "points", "complete", "wall_median", "wall_min",
                     "cpu_median", "added_wall_percent", "added_cpu_percent", "candidates",
                     "verified", "worst_verified_period_offset", "worst_closed_form_error"});
  std::string rows, verdicts;
  for (const int elements : {100, 200}) {
    const std::array<Variant, 3> variants = run_variants(plugin, elements, rounds);
    const double plain_wall = bench::median(variants[0].wall);
    const double plain_cpu = bench::median(variants[0].cpu);
    for (const Variant& v : variants) {
      const VariantSummary s = summarize(v, plain_wall, plain_cpu);
      if (!s.complete) status = 1;
      report_variant(table, rows, elements, rounds, v, s);
    }
    verdicts += grid_verdict(elements, variants, plain_wall, plain_cpu, verdicts.empty());
  }
  std::filesystem::create_directories(out);
  table.write_csv(out / "branch_point_cost.csv");
  fmt::print("  wrote {}\n", (out / "branch_point_cost.csv").string());
  cli::write_bench_section(out, "branch_point_cost",
                           branch_point_cost_section(rounds, rows, verdicts));
  return status;
}

}  // namespace backbone::contact_bar
