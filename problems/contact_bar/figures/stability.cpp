#include "problems/contact_bar/figures/stability.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <string>

#include "core/io/plot.hpp"
#include "core/io/scene.hpp"
#include "core/io/table.hpp"
#include "problems/contact_bar/figures/modes.hpp"
#include "problems/contact_bar/orbits/family.hpp"
#include "problems/contact_bar/orbits/monodromy.hpp"
#include "problems/contact_bar/solver/scene.hpp"

namespace backbone::contact_bar {

namespace fs = std::filesystem;

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double largest(const std::vector<double>& v) {
  double m = std::nan("");
  for (double x : v)
    if (!std::isnan(x) && !(x <= m)) m = x;
  return m;
}

}  // namespace

int write_stability_summary(const fs::path& out) {
  const fs::path folder = out / "stability";
  std::vector<fs::path> runs;
  if (fs::exists(folder))
    for (const auto& entry : fs::directory_iterator(folder)) {
      if (fs::exists(entry.path() / "branch.csv") && fs::exists(entry.path() / "multipliers.csv"))
        runs.push_back(entry.path());
      // The families a run followed (--follow), with their own multipliers.
      if (entry.is_directory())
        for (const fs::path& followed : followed_branches(entry.path()))
          if (fs::exists(followed / "multipliers.csv")) runs.push_back(followed);
    }
  if (runs.empty()) {
    fmt::print("[figures] stability_summary skipped: no trace with --stability true in {}\n",
               folder.string());
    return 0;
  }
  std::sort(runs.begin(), runs.end());
  core::Table summary({"run", "branch", "elements", "courant", "points", "unstable_points",
                       "undecided_points", "max_modulus_worst", "max_modulus_median",
                       "trivial_distance_worst", "trivial_distance_median",
                       "real_negative_modulus_worst", "complex_modulus_worst"});
  std::string curves;
  for (const fs::path& run : runs) {
    const core::Table branch = core::Table::read_csv(run / "branch.csv");
    const core::Table multipliers = core::Table::read_csv(run / "multipliers.csv");
    const std::vector<double> stable = branch.column("stable");
    int unstable = 0, undecided = 0;
    for (double s : stable) {
      unstable += s == 0 ? 1 : 0;
      undecided += s < 0 ? 1 : 0;
    }
    const std::vector<double> re = multipliers.column("re"), im = multipliers.column("im"),
                              modulus = multipliers.column("modulus"),
                              trivial = multipliers.column("trivial");
    std::vector<double> negative, complex;
    for (std::size_t i = 0; i < re.size(); ++i) {
      if (trivial[i] != 0) continue;
      if (im[i] == 0 && re[i] < 0) negative.push_back(modulus[i]);
      if (im[i] != 0) complex.push_back(modulus[i]);
    }
    const bool followed = run.filename().string().rfind("branch_point_", 0) == 0;
    const fs::path scene_dir = followed ? run.parent_path() : run;
    const std::string name = followed
                                 ? scene_dir.filename().string() + "/" + run.filename().string()
                                 : run.filename().string();
    const std::string elements = scene_value(scene_dir / "scene.ini", "shooting_elements");
    const std::string courant = scene_value(scene_dir / "scene.ini", "stability_courant");
    summary.add_cells({name, name.substr(0, name.find('_')),
                       elements.empty() ? std::nan("") : std::stod(elements),
                       courant.empty() ? std::nan("") : std::stod(courant), double(stable.size()),
                       double(unstable), double(undecided),
                       largest(branch.column("max_multiplier_modulus")),
                       median(branch.column("max_multiplier_modulus")),
                       largest(branch.column("trivial_multiplier_distance")),
                       median(branch.column("trivial_multiplier_distance")), largest(negative),
                       largest(complex)});
    curves +=
        fmt::format("{}{} using 'energy':'max_multiplier_modulus' with linespoints title '{}'",
                    curves.empty() ? "plot " : ", ", core::gnuplot_quote(run / "branch.csv"), name);
  }
  summary.write_csv(folder / "summary.csv");
  fmt::print("[figures] wrote {}\n{}", (folder / "summary.csv").string(), summary.aligned(4));
  const core::PlotResult r = core::render_png(
      folder / "max_modulus.png",
      "set datafile separator ','\nset key autotitle columnhead noenhanced\nset grid\nset logscale "
      "x\nset format x '%.0e'\n"
      "set xlabel 'energy [J]'\nset ylabel 'largest non-trivial |mu|'\nset key outside right\n"
      "set title 'Bar modes: the largest Floquet multiplier by run (grid, c dt / dx)'\n" +
          curves + "\n");
  if (!r.ok) fmt::print("[figures] max_modulus.png skipped: {}\n", r.message);
  return 0;
}

int write_perturbation_growth(const fs::path& out) {
  // The paper scene's bar (problems/contact_bar/scenes/paper.ini).
  const core::Scene scene = core::read_scene(
      scene_keys(), core::shipped_path("problems/contact_bar/scenes/paper.ini").string(), {},
      boost::program_options::options_description());
  bar::BarSetup setup = setup_from_scene(scene);
  core::Table table(
      {"mode", "energy", "period", "periods", "largest", "at_500", "last", "modulus_bound"});
  constexpr int periods = 1000;
  for (int mode : {1, 2, 3}) {
    const ContactFamily family(setup.material, setup.right.gap, mode);
    for (double factor : {2.0, 20.0, 200.0}) {
      const double energy = factor * family.grazing_energy();
      setup.u0 = family.u0(energy);
      const PerturbationGrowth g =
          perturbation_growth(setup, family.period(energy), periods, 1e-6, 40, 7);
      double at_half = 0;
      for (const auto& [k, d] : g.history)
        if (k <= periods / 2) at_half = std::max(at_half, d);
      table.add_row({double(mode), energy, family.period(energy), double(periods),
                     g.ok ? g.largest : std::nan(""), at_half, g.last,
                     std::pow(g.largest, 1.0 / periods)});
    }
  }
  fs::create_directories(out / "stability");
  table.write_csv(out / "stability" / "perturbation_growth.csv");
  fmt::print("[figures] wrote {}\n{}", (out / "stability" / "perturbation_growth.csv").string(),
             table.aligned(4));
  return 0;
}

std::vector<cli::ProblemJob> stability_figure_jobs() {
  return {{"stability_summary",
           "stability/summary.csv and max_modulus.png from the traces in OUT/stability",
           write_stability_summary},
          {"perturbation_growth",
           "stability/perturbation_growth.csv: random perturbations of modes 1 to 3 over 1000 "
           "periods by the exact solver",
           write_perturbation_growth}};
}

}  // namespace backbone::contact_bar
