#include "problems/contact_bar/figures/clearance.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/io/plot.hpp"
#include "core/io/scene.hpp"
#include "core/io/table.hpp"
#include "problems/contact_bar/figures/modes.hpp"
#include "problems/contact_bar/orbits/family.hpp"
#include "problems/contact_bar/solver/scene.hpp"

namespace backbone::contact_bar {

namespace {

namespace fs = std::filesystem;
using core::Table;

// The branches the main job traces (plugin.cpp), in drawing order.
struct ClearanceBranch {
  const char* folder;
  int mode;
  const char* colour;
};
constexpr ClearanceBranch branches[] = {{"clearance_mode1", 1, "black"},
                                        {"clearance_mode2", 2, "blue"},
                                        {"clearance_asym_mode1", 1, "dark-red"},
                                        {"clearance_asym_mode2", 2, "dark-green"}};

bar::BarSetup branch_bar(const fs::path& dir) {
  const core::Scene scene = core::read_scene(scene_keys(), (dir / "scene.ini").string(), {},
                                             boost::program_options::options_description());
  return bar_from_scene(scene);
}

double worst(const std::vector<double>& v) {
  double w = 0;
  for (double x : v) w = std::max(w, std::isnan(x) ? INFINITY : x);
  return w;
}

}  // namespace

int draw_clearance(const fs::path& out) {
  Table summary({"branch", "mode", "gap", "gap_back", "points", "energy_first", "energy_last",
                 "worst_relative_error", "worst_return_error", "points_one_front_phase",
                 "points_one_back_phase", "points_without_back_phase",
                 "worst_one_sided_relative_error", "back_grazing_energy"});
  std::string curves, labels;
  double e_max = 1e-2, w_min = INFINITY, w_max = 0;
  bar::Material material;
  double gap = 0;
  int drawn = 0;
  for (const ClearanceBranch& b : branches) {
    const fs::path dir = out / b.folder;
    if (!fs::exists(dir / "closed_form_check.csv") || !fs::exists(dir / "scene.ini")) continue;
    const bar::BarSetup s = branch_bar(dir);
    material = s.material;
    gap = s.right.gap;
    const ClearanceMode family(s.material, s.right.gap, s.right.gap_back, b.mode);
    const Table check = Table::read_csv(dir / "closed_form_check.csv");
    const auto energy = check.column("energy"), w = check.column("frequency");
    if (energy.empty()) continue;
    const auto front = check.column("front_phases"), back = check.column("back_phases");
    const auto one_sided = check.column("one_sided_relative_error");
    std::vector<double> returns;
    for (const char* c : {"return_error_u", "return_error_v"})
      for (double r : check.column(c)) returns.push_back(r);
    int one_front = 0, one_back = 0, no_back = 0;
    double worst_one_sided = 0;
    for (std::size_t i = 0; i < energy.size(); ++i) {
      one_front += front[i] == 1;
      one_back += back[i] == 1;
      if (back[i] == 0) {
        ++no_back;
        worst_one_sided = std::max(worst_one_sided, one_sided[i]);
      }
      e_max = std::max(e_max, energy[i]);
      w_min = std::min(w_min, w[i]);
      w_max = std::max(w_max, w[i]);
    }
    summary.add_row(b.folder,
                    {double(b.mode), s.right.gap, s.right.gap_back, double(energy.size()),
                     energy.front(), energy.back(), worst(check.column("relative_error")),
                     worst(returns), double(one_front), double(one_back), double(no_back),
                     no_back > 0 ? worst_one_sided : std::nan(""), family.back_grazing_energy()});
    // The closed form from grazing to the last point, every traced point on it.
    Table closed({"energy", "frequency"});
    const double e_graze = family.grazing_energy();
    for (int i = 0; i <= 400; ++i) {
      const double e = e_graze * std::pow(energy.back() / e_graze, i / 400.0) * (1 + 1e-12);
      closed.add_row({e, family.frequency(e)});
    }
    const fs::path csv = out / fmt::format("clearance_backbones_{}.csv", b.folder);
    closed.write_csv(csv);
    const std::string name =
        fmt::format("mode {}, back wall {:g} gap behind", b.mode, s.right.gap_back / s.right.gap);
    curves += fmt::format(
        "{}{} using 'frequency':'energy' with lines lw 2 lc rgb '{}' title '{}, closed form', "
        "{} using 'frequency':'energy' with points pt 7 ps 0.6 lc rgb '{}' title '{}, TD-BEM "
        "shooting ({} points)'",
        curves.empty() ? "plot " : ", ", core::gnuplot_quote(csv), b.colour, name,
        core::gnuplot_quote(dir / "branch.csv"), b.colour, name, energy.size());
    if (s.right.gap_back > s.right.gap)
      labels += fmt::format(
          "set arrow from graph 0, first {0:.9g} to graph 1, first {0:.9g} nohead dt 3 lc rgb "
          "'{1}'\nset label 'back wall joins mode {2}' at graph 0.01, first {0:.9g} offset 0,0.5 "
          "font ',9' tc rgb '{1}'\n",
          family.back_grazing_energy(), b.colour, b.mode);
    ++drawn;
  }
  if (drawn == 0) {
    fmt::print("[figures] clearance: no OUT/clearance_* branch, skipped\n");
    return 0;
  }
  // The one-sided modes 1 and 2 for comparison (the back wall removed).
  for (int mode : {1, 2}) {
    const ContactFamily family(material, gap, mode);
    Table closed({"energy", "frequency"});
    const double e_graze = family.grazing_energy();
    for (int i = 0; i <= 400; ++i) {
      const double e = e_graze * std::pow(e_max / e_graze, i / 400.0) * (1 + 1e-12);
      closed.add_row({e, family.frequency(e)});
      w_max = std::max(w_max, family.frequency(e));
    }
    const fs::path csv = out / fmt::format("clearance_backbones_one_sided_mode{}.csv", mode);
    closed.write_csv(csv);
    curves += fmt::format(
        ", {} using 'frequency':'energy' with lines lw 1 dt 2 lc rgb 'gray40' title 'mode {}, "
        "one wall (closed form)'",
        core::gnuplot_quote(csv), mode);
  }
  summary.write_csv(out / "clearance_summary.csv");
  fmt::print("[figures] wrote {}\n{}", (out / "clearance_summary.csv").string(),
             summary.aligned(4));
  // The long TD-BEM simulations: the largest relative energy change over each history.
  Table drift({"run", "rows", "t_end", "energy", "max_relative_drift"});
  for (const auto& entry : fs::directory_iterator(out)) {
    const std::string run = entry.path().filename().string();
    if (run.rfind("clearance_drift_", 0) != 0 || !fs::exists(entry.path() / "history.csv"))
      continue;
    const Table h = Table::read_csv(entry.path() / "history.csv");
    const auto e = h.column("energy"), t = h.column("t");
    if (e.empty()) continue;
    double largest = 0;
    for (double x : e) largest = std::max(largest, std::abs(x - e.front()) / std::abs(e.front()));
    drift.add_row(run, {double(e.size()), t.back(), e.front(), largest});
  }
  if (drift.rows() > 0) {
    drift.write_csv(out / "clearance_energy_drift.csv");
    fmt::print("[figures] wrote {}\n{}", (out / "clearance_energy_drift.csv").string(),
               drift.aligned(4));
  }
  const std::string plot = fmt::format(
      "set title 'Modes 1 and 2 of a bar whose end moves between two walls (gap = {} m in "
      "front; c = {} m/s, L = {} m)'\n"
      "set xlabel 'frequency {{/Symbol w}} [rad/s]'\nset ylabel 'energy E [J]'\n"
      "set logscale y\nset format y '10^{{%L}}'\nset grid\nset key below maxrows 5\n"
      "set xrange [{}:{}]\n{}{}\n",
      gap, material.wave_speed(), material.length, 0.9 * w_min, 1.05 * w_max, labels, curves);
  const fs::path png = out / "clearance_backbones.png";
  render_figure(png, plot, 1400, 900);
  return 0;
}

std::vector<cli::ProblemJob> clearance_figure_jobs() {
  return {{"clearance",
           "clearance_backbones.png, clearance_summary.csv and clearance_energy_drift.csv from "
           "OUT/clearance_*",
           draw_clearance}};
}

}  // namespace backbone::contact_bar
