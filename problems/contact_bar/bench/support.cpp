#include "problems/contact_bar/bench/support.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <limits>

#include "continuation/cli/bench_report.hpp"
#include "continuation/cli/scene_options.hpp"
#include "core/errors.hpp"
#include "core/orbits/periodic_orbit.hpp"
#include "core/solvers/newton.hpp"
#include "problems/contact_bar/bench/peers.hpp"
#include "problems/contact_bar/orbits/family.hpp"
#include "problems/contact_bar/solver/scene.hpp"

namespace backbone::contact_bar::bench {

core::Scene read_paper_scene(const cli::ProblemPlugin& plugin,
                             const std::vector<std::string>& args) {
  namespace po = boost::program_options;
  po::options_description keys = plugin.scene_keys();
  keys.add(cli::continuation_keys(keys));
  const std::filesystem::path paper = contact_bar_peers_folder().parent_path().parent_path() /
                                      "scenes" / "paper.ini";  // bench/peers
  return core::read_scene(keys, paper.string(), args, po::options_description());
}

PaperMode1 paper_mode1() {
  PaperMode1 m;
  m.eps = -0.01;
  const double gap = 1e-3;
  m.setup.left = {bar::EndType::fixed, 0};
  m.setup.right = {bar::EndType::contact, gap};
  m.setup.u0 = bar::PiecewiseLinear({0.0, 1.0}, {0.0, m.eps});
  const bar::Material& material = m.setup.material;
  // Potential energy of u0 = eps x at rest: EA L eps^2 / 2.
  const double energy = m.eps * m.eps / 2 * material.axial_stiffness() * material.length;
  m.episode = mode1_contact_episode(material, gap, energy);
  return m;
}

double median(std::vector<double> values) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

InProcessTrace trace_in_process(const cli::ProblemPlugin& plugin, const core::Scene& scene,
                                const std::string& branch) {
  cli::RunSettings run = cli::read_run_settings(scene);
  cli::TraceSetup setup = plugin.setup(scene, branch);
  setup.apply_branch_options(run.options, run.newton_options);
  const auto corrector = core::make_corrector(run.newton, run.newton_options);
  auto* periodic = dynamic_cast<core::PeriodicOrbitProblem*>(setup.problem.get());
  if (!periodic)
    throw core::InputError("branch", fmt::format("{} is not a periodic-orbit problem", branch));
  periodic->set_formulation(run.formulation);
  if (run.newton == "kinsol" && periodic->num_equations() != periodic->num_unknowns() - 1)
    throw core::InputError("newton", "kinsol solves square systems only: use test_elements 0");
  const core::Vector direction =
      setup.direction.size()
          ? setup.direction
          : core::Vector::Unit(periodic->num_unknowns(), periodic->period_index());
  continuation::ContinuationHooks hooks;
  hooks.reject_point = setup.reject_point;
  hooks.describe_branch_point = setup.describe_branch_point;  // as trace's (when detecting)

  InProcessTrace t;
  const double cpu_start = process_cpu_seconds();
  const auto wall_start = std::chrono::steady_clock::now();
  t.traced = cli::run_continuation(*periodic, setup.guess, direction, run, *corrector, hooks);
  t.cpu_seconds = process_cpu_seconds() - cpu_start;
  t.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return t;
}

std::vector<double> mode1_frequency_errors(const core::Scene& scene,
                                           const continuation::Branch& branch) {
  const bar::BarSetup bar = bar_from_scene(scene);
  const ContactFamily family(bar.material, bar.right.gap, 1);
  std::vector<double> errors;
  for (const continuation::BranchPoint& p : branch.points)
    errors.push_back(
        std::abs(p.observable("frequency") / family.frequency(p.observable("energy")) - 1));
  return errors;
}

double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double seconds_of(const std::function<void()>& run) {
  const auto start = std::chrono::steady_clock::now();
  run();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double best_seconds(const std::function<void()>& run, double single) {
  double best = seconds_of(run);
  for (int k = 1; k < 3 && best < single; ++k) best = std::min(best, seconds_of(run));
  return best;
}

void report_plot(const core::PlotResult& result, const std::filesystem::path& png) {
  if (result.ok)
    fmt::print("  wrote {}\n", png.string());
  else
    fmt::print("  figure skipped: {}\n", result.message);
}

void plot(const std::filesystem::path& png, const std::string& script, core::PlotSize size) {
  report_plot(core::render_png(png, script, size), png);
}

std::filesystem::path write_table(const core::Table& table, const std::filesystem::path& out,
                                  const std::string& name, int digits) {
  const std::filesystem::path csv = out / (name + ".csv");
  table.write_csv(csv);
  fmt::print("{}", table.aligned(digits));
  return csv;
}

std::string peer_figure_script(const std::filesystem::path& csv, const PeerFigure& f) {
  return fmt::format(
      "set termoption noenhanced\nset logscale xy\nset grid\nset format y '%.0e'\n"
      "set xlabel '{2}'\nset ylabel '{3}'\nset title '{4}'\nset key center right noenhanced\n"
      "plot {0} using (strcol(1) eq '{7}' ? ${5} : NaN):(${6} > {1} ? ${6} : {1}) with "
      "linespoints pt 7 ps 1.5 title '{8}', "
      "{0} using (strcol(1) eq '{9}' ? ${5} : NaN):(${6} > {1} ? ${6} : {1}) with "
      "linespoints pt 5 ps 1.5 title '{10}'\n",
      core::gnuplot_quote(csv), plot_floor, f.xlabel, f.ylabel, f.title, f.x_column, f.y_column,
      f.peer_tool, f.peer_title, f.backbone_tool, f.backbone_title);
}

void report_peer_case(const std::filesystem::path& out, const std::string& name,
                      const core::Table& table, const PeerFigure& figure,
                      const std::string& verdict, const std::string& section) {
  const std::filesystem::path csv = write_table(table, out, name, 3);
  plot(out / (name + ".png"), peer_figure_script(csv, figure));
  fmt::print("  {}\n", verdict);
  cli::write_bench_section(out, name, section);
}

}  // namespace backbone::contact_bar::bench
