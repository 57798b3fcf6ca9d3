#include "problems/impact_oscillator/figures.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>

#include "continuation/outputs.hpp"
#include "core/io/plot.hpp"
#include "core/io/table.hpp"
#include "problems/impact_oscillator/impact_oscillator.hpp"

namespace backbone::impact_oscillator {

namespace {

namespace fs = std::filesystem;
using core::Table;

constexpr double nan = std::numeric_limits<double>::quiet_NaN();

struct Case {
  const char* name;  // dissipative or elastic
  double restitution;
};
constexpr Case cases[] = {{"dissipative", 0.8}, {"elastic", 1.0}};

fs::path folder(const fs::path& out) {
  return out / "impact_oscillator";
}

// The branches of one case that exist: up, down and the period-2 branch (period_doubling_1 of
// down), each with its name.
std::vector<std::pair<std::string, fs::path>> branches_of(const fs::path& out, const Case& c) {
  std::vector<std::pair<std::string, fs::path>> found;
  const fs::path up = folder(out) / fmt::format("{}_up", c.name);
  const fs::path down = folder(out) / fmt::format("{}_down", c.name);
  for (const auto& [name, dir] :
       {std::pair{std::string("up"), up}, std::pair{std::string("down"), down},
        std::pair{std::string("period2"), down / "period_doubling_1"}})
    if (fs::exists(dir / "branch.csv")) found.emplace_back(name, dir);
  return found;
}

// A folder without the impact oscillator's branches: nothing to draw, not a failure (figures
// draws every problem's figures from whatever was traced).
int skipped(const fs::path& out) {
  fmt::print("[figures] no impact oscillator branches in {}: skipped\n", folder(out).string());
  return 0;
}

void report(const core::PlotResult& r, const fs::path& png) {
  if (r.ok)
    fmt::print("[figures] wrote {}\n", png.string());
  else
    fmt::print(stderr, "[figures] {}\n", r.message);
}

int draw_diagram(const fs::path& out) {
  if (!fs::is_directory(folder(out))) return skipped(out);
  std::string data, plots;
  int panel = 0;
  std::string script =
      "set multiplot layout 1,2\nset grid\nset key bottom left\n"
      "set xlabel 'wall sigma'\nset ylabel 'impact velocity'\n";
  bool any = false;
  for (const Case& c : cases) {
    const auto branches = branches_of(out, c);
    if (branches.empty()) continue;
    any = true;
    std::string plot = "plot ";
    for (const auto& [name, dir] : branches) {
      const Table table = Table::read_csv(dir / "branch.csv");
      const std::string prefix = fmt::format("{}_{}_", c.name, name);
      data += continuation::stability_datablocks(table, "wall", "impact_velocity", prefix);
      const char* colour = name == "period2" ? "#2ca02c" : "#1f77b4";
      const std::string label = name == "period2" ? "period 2" : "period 1";
      const bool titled = name != "down";  // one key entry per family
      plot += fmt::format(
          "${0}stable with lines lw 2 lc rgb '{1}' title '{2}', "
          "${0}unstable with lines lw 2 dt 2 lc rgb '{1}' title '{3}', "
          "${0}undecided with lines lw 1 dt 3 lc rgb 'gray40' notitle, "
          "'{4}' using 'wall':'impact_velocity' with points pt 7 ps 0.4 lc rgb 'black' notitle, ",
          prefix, colour, titled ? label + " stable" : "", titled ? label + " unstable" : "",
          (dir / "branch.csv").string());
      if (fs::exists(dir / "bifurcations.csv") &&
          Table::read_csv(dir / "bifurcations.csv").rows() > 0)
        plot += fmt::format(
            "'{0}' using 'wall':'impact_velocity' with points pt 6 ps 2 lw 2 lc rgb '#d62728' "
            "notitle, '{0}' using 'wall':'impact_velocity':1 with labels offset 0,1.2 font ',9' "
            "noenhanced notitle, ",
            (dir / "bifurcations.csv").string());
    }
    plot.resize(plot.size() - 2);
    script += fmt::format("set title 'omega 2.8, r = {}: period 1 and period 2' noenhanced\n{}\n",
                          c.restitution, plot);
    ++panel;
  }
  if (!any) {
    fmt::print(stderr, "[figures] impact_diagram: no branch in {}\n", folder(out).string());
    return 1;
  }
  const fs::path png = folder(out) / "bifurcation_diagram.png";
  report(core::render_png(png, data + script + "unset multiplot\n", {1600, 700}), png);
  return 0;
}

// Rows of multipliers.csv for one point (re, im) as a data block.
std::string multiplier_block(const fs::path& dir, int point, const std::string& name) {
  const Table m = Table::read_csv(dir / "multipliers.csv");
  const auto points = m.column("point"), re = m.column("re"), im = m.column("im");
  std::string block = fmt::format("${} << EOD\nre,im\n", name);
  int rows = 0;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (static_cast<int>(points[i]) == point) {
      block += fmt::format("{:.17g},{:.17g}\n", re[i], im[i]);
      ++rows;
    }
  if (rows == 0) block += "nan,nan\n";
  return block + "EOD\n";
}

int draw_multipliers(const fs::path& out) {
  if (!fs::is_directory(folder(out))) return skipped(out);
  const Case& c = cases[0];
  const fs::path up = folder(out) / fmt::format("{}_up", c.name);
  const fs::path down = folder(out) / fmt::format("{}_down", c.name);
  if (!fs::exists(up / "multipliers.csv") || !fs::exists(down / "multipliers.csv")) {
    fmt::print(stderr, "[figures] impact_multipliers: no multipliers.csv in {}\n",
               folder(out).string());
    return 1;
  }
  std::string data = multiplier_block(up, 0, "at_zero");
  const Table d = Table::read_csv(down / "branch.csv");
  data += multiplier_block(down, static_cast<int>(d.column("point").back()), "at_end");
  std::string plots =
      "$at_zero using 're':'im' with points pt 7 ps 1.6 lc rgb '#1f77b4' title 'sigma = 0', "
      "$at_end using 're':'im' with points pt 5 ps 1.4 lc rgb '#9467bd' title 'sigma = -0.2', ";
  // The located period doubling: its multipliers from bifurcations.csv.
  if (fs::exists(down / "bifurcations.csv")) {
    const Table b = Table::read_csv(down / "bifurcations.csv");
    data += "$doubling << EOD\nre,im\n";
    for (std::size_t i = 0; i < b.rows(); ++i)
      if (b.text_column("type")[i] == "period_doubling")
        for (int k = 0; k < 2; ++k)
          data += fmt::format("{:.17g},{:.17g}\n", b.column(fmt::format("multiplier_{}_re", k))[i],
                              b.column(fmt::format("multiplier_{}_im", k))[i]);
    data += "nan,nan\nEOD\n";
    plots +=
        "$doubling using 're':'im' with points pt 9 ps 1.8 lc rgb '#d62728' "
        "title 'period doubling', ";
  }
  const fs::path period2 = down / "period_doubling_1";
  if (fs::exists(period2 / "multipliers.csv")) {
    data += multiplier_block(period2, 0, "period2");
    plots +=
        "$period2 using 're':'im' with points pt 11 ps 1.6 lc rgb '#2ca02c' "
        "title 'period 2, first point', ";
  }
  plots.resize(plots.size() - 2);
  const std::string script =
      data +
      "set size ratio -1\nset grid\nset key outside right\n"
      "set xlabel 'Re mu'\nset ylabel 'Im mu'\nset xrange [-3.5:1.5]\n"
      "set yrange [-1.5:1.5]\nset parametric\nset trange [0:2*pi]\n"
      "set title 'Floquet multipliers, omega 2.8, r = 0.8'\n"
      "plot cos(t), sin(t) with lines lc rgb 'gray50' title 'unit circle', " +
      plots + "\n";
  const fs::path png = folder(out) / "multipliers.png";
  report(core::render_png(png, script, {1100, 650}), png);
  return 0;
}

int write_summary(const fs::path& out) {
  if (!fs::is_directory(folder(out))) return skipped(out);
  Table summary({"restitution", "points", "worst_det_error", "worst_velocity_error",
                 "multiplier_0_at_zero", "multiplier_1_at_zero", "doubling_wall",
                 "doubling_wall_closed_form", "doubling_velocity", "doubling_velocity_closed_form",
                 "grazing_wall", "grazing_wall_exact", "period2_points", "period2_stable_points",
                 "period2_worst_period_error", "period2_worst_det_error"});
  const double omega = 2.8, T = 2 * std::numbers::pi / omega;
  bool any = false;
  for (const Case& c : cases) {
    const auto branches = branches_of(out, c);
    if (branches.empty()) continue;
    any = true;
    const double r = c.restitution;
    double points = 0, det = 0, velocity = 0, mu0 = nan, mu1 = nan;
    double doubling = nan, doubling_velocity = nan, grazing = nan;
    double p2_points = 0, p2_stable = 0, p2_period = 0, p2_det = 0;
    for (const auto& [name, dir] : branches) {
      const Table b = Table::read_csv(dir / "branch.csv");
      const auto walls = b.column("wall"), v = b.column("impact_velocity"),
                 dets = b.column("monodromy_determinant"), stable = b.column("stable"),
                 periods = b.column("period");
      if (name == "period2") {
        p2_points = static_cast<double>(b.rows());
        for (std::size_t i = 0; i < b.rows(); ++i) {
          p2_stable += stable[i] == 1;
          p2_period = std::max(p2_period, std::abs(periods[i] - 2 * T));
          p2_det = std::max(p2_det, std::abs(dets[i] - std::pow(r, 4)));
        }
        continue;
      }
      points += static_cast<double>(b.rows());
      for (std::size_t i = 0; i < b.rows(); ++i) {
        det = std::max(det, std::abs(dets[i] - r * r));
        if (const auto exact = period_one_orbit(omega, r, walls[i]))
          velocity = std::max(velocity, std::abs(v[i] - exact->impact_velocity));
      }
      if (name == "up") {
        const Table m = Table::read_csv(dir / "multipliers.csv");
        mu0 = m.column("re")[0];
        mu1 = m.column("re")[1];
      }
      if (!fs::exists(dir / "bifurcations.csv")) continue;
      const Table f = Table::read_csv(dir / "bifurcations.csv");
      for (std::size_t i = 0; i < f.rows(); ++i) {
        const std::string type = f.text_column("type")[i];
        if (type == "period_doubling" && name == "down") {
          doubling = f.column("wall")[i];
          doubling_velocity = f.column("impact_velocity")[i];
        }
        if (type == "grazing" && name == "up") grazing = f.column("wall")[i];
      }
    }
    const double exact_doubling = period_doubling_wall(omega, r, -0.2, 0.0);
    const auto at_doubling = period_one_orbit(omega, r, exact_doubling);
    summary.add_row({r, points, det, velocity, mu0, mu1, doubling, exact_doubling,
                     doubling_velocity, at_doubling ? at_doubling->impact_velocity : nan, grazing,
                     1 / (omega * omega - 1), p2_points, p2_stable, p2_period, p2_det});
  }
  if (!any) {
    fmt::print(stderr, "[figures] impact_summary: no branch in {}\n", folder(out).string());
    return 1;
  }
  summary.write_csv(folder(out) / "summary.csv");
  fmt::print("[figures] wrote {}\n", (folder(out) / "summary.csv").string());
  return 0;
}

}  // namespace

std::vector<cli::ProblemJob> figure_jobs() {
  return {{"impact_diagram",
           "impact_oscillator/bifurcation_diagram.png: impact velocity against the wall, stable "
           "solid, unstable dashed, bifurcations marked",
           &draw_diagram},
          {"impact_multipliers",
           "impact_oscillator/multipliers.png: multipliers in the complex plane with the unit "
           "circle",
           &draw_multipliers},
          {"impact_summary", "impact_oscillator/summary.csv: the branches against the closed form",
           &write_summary}};
}

}  // namespace backbone::impact_oscillator
