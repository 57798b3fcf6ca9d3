#include "problems/contact_bar/figures/resonance.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <numeric>
#include <string>

#include "core/io/plot.hpp"
#include "core/io/scene.hpp"
#include "core/io/table.hpp"
#include "problems/contact_bar/figures/modes.hpp"
#include "problems/contact_bar/solver/scene.hpp"
#include "problems/exact_bar/exact_bar_solver.hpp"

namespace backbone::contact_bar {

namespace fs = std::filesystem;

namespace {

// The main job's mode-1 trace with --follow (plugin.cpp, reproduce step mode1_resonances): at
// 40 intervals, where the family attached at T = 3.2 L/c is resolved.
constexpr const char* resonances_folder = "mode1_resonances";
// The orbit the paper's "about 12 times" most likely describes (figures/README.md): the family
// of resonance order q = 12 attached at T = 24/7 L/c, followed at 70 intervals (reproduce step
// mode1_resonance_twelve). Figs. 10 and 11 are drawn from it when it is there.
constexpr const char* twelve_folder = "mode1_resonance_twelve";
constexpr double twelve_order = 12;
// Mode 1 with branch-point detection on fine steps (reproduce step mode1_law): the located
// candidates against the law (mode1_law.csv).
constexpr const char* law_folder = "mode1_law";

// The followed branches of the q = 12 family in OUT/mode1_resonance_twelve (the rows of its
// branch_points.csv with resonance_order 12 to 1e-3), else those of OUT/mode1_resonances.
std::vector<fs::path> figure_branches(const fs::path& out) {
  const fs::path twelve = out / twelve_folder;
  std::vector<fs::path> chosen;
  if (fs::exists(twelve / "branch_points.csv")) {
    const core::Table points = core::Table::read_csv(twelve / "branch_points.csv");
    const auto order = points.column("resonance_order");
    for (std::size_t i = 0; i < order.size(); ++i) {
      const fs::path dir = twelve / fmt::format("branch_point_{}", i + 1);
      if (std::abs(order[i] - twelve_order) < 1e-3 && fs::exists(dir / "branch.csv"))
        chosen.push_back(dir);
    }
  }
  return chosen.empty() ? followed_branches(out / resonances_folder) : chosen;
}

// The amplitude of harmonic k (k omega, omega = 2 pi / T) of u samples over one period (the
// last sample closes the period and is left out), k = 1 .. kmax.
std::vector<double> harmonics(const std::vector<double>& u, int kmax) {
  const std::size_t n = u.size() - 1;
  std::vector<double> a(static_cast<std::size_t>(kmax) + 1, 0.0);
  for (int k = 1; k <= kmax; ++k) {
    double re = 0, im = 0;
    for (std::size_t j = 0; j < n; ++j) {
      const double phase = 2 * std::numbers::pi * k * static_cast<double>(j) / n;
      re += u[j] * std::cos(phase);
      im -= u[j] * std::sin(phase);
    }
    a[static_cast<std::size_t>(k)] = 2 * std::hypot(re, im) / static_cast<double>(n);
  }
  return a;
}

}  // namespace

int draw_resonant_end(const fs::path& out, const fs::path& scene_path) {
  const std::vector<fs::path> attached = figure_branches(out);
  if (attached.empty()) {
    fmt::print("[figures] resonant_end skipped: no followed branch in {} (trace --follow)\n",
               (out / resonances_folder).string());
    return 0;
  }
  const core::Scene scene = core::read_scene(scene_keys(), scene_path.string(), {},
                                             boost::program_options::options_description());
  bar::BarSetup s = setup_from_scene(scene);
  const double L = s.material.length, c = s.material.wave_speed(), g0 = s.right.gap;
  std::string plot =
      "set grid\nset xlabel 't / T'\nset ylabel 'u(L,t) [m]'\nset key outside right\n";
  std::string curves, spectra;
  for (const fs::path& dir : attached) {
    std::vector<double> attached_end;
    // The highest-energy orbit of the followed branch, and mode 1 at its period: the closed form
    // u0 = eps x with T = (3 L + g0 / |eps|) / c (problems/contact_bar/orbits/README.md, 'Mode 1').
    const auto orbit = load_traced_orbit(dir, 1e300, L);
    if (!orbit) continue;
    const double eps = -g0 / (c * orbit->period - 3 * L);
    bar::SimulationOptions o;
    o.t_end = orbit->period;
    o.dt = orbit->period / 4000;
    o.history_samples = 4001;
    o.energy = false;
    const std::string k = dir.filename().string().substr(13);  // "branch_point_K" -> K
    for (const bool resonant : {true, false}) {
      s.u0 = resonant ? orbit->u0 : bar::PiecewiseLinear({0.0, L}, {0.0, eps * L});
      s.v0 = bar::PiecewiseLinear::zero(L);
      const fs::path csv =
          out / fmt::format("resonant_end_{}_{}.csv", k, resonant ? "attached" : "mode1");
      const bar::History h = exact_bar::ExactBarSolver().simulate(s, o);
      h.to_table().write_csv(csv);
      if (resonant) {
        attached_end = h.u_contact;
      } else if (attached_end.size() == h.u_contact.size()) {
        // What the attached orbit adds at the end, u_attached(L, t) - u_mode1(L, t) (same
        // period, same u0(L)), in harmonics of the orbit's own frequency: its content sits
        // around the resonance order q (figures/README.md).
        std::vector<double> added(h.u_contact.size());
        for (std::size_t j = 0; j < added.size(); ++j) added[j] = attached_end[j] - h.u_contact[j];
        const std::vector<double> a = harmonics(added, 40);
        core::Table spectrum({"harmonic", "amplitude"});
        for (int j = 1; j <= 40; ++j)
          spectrum.add_row({static_cast<double>(j), a[static_cast<std::size_t>(j)]});
        const fs::path spectrum_csv = out / fmt::format("resonant_end_{}_spectrum.csv", k);
        spectrum.write_csv(spectrum_csv);
        spectra += fmt::format(
            "{}{} using 'harmonic':'amplitude' with impulses lw 4 title 'attached at branch "
            "point {}, T = {:.6g} s'",
            spectra.empty() ? "plot " : ", ", core::gnuplot_quote(spectrum_csv), k, orbit->period);
      }
      curves += fmt::format(
          "{}{} using (column('t')/{}):'u_contact' with lines lw {} title '{}'",
          curves.empty() ? "plot " : ", ", core::gnuplot_quote(csv), orbit->period,
          resonant ? 1.5 : 3,
          resonant ? fmt::format("attached at branch point {} (E = {:.3g} J)", k, orbit->energy)
                   : fmt::format("mode 1 at T = {:.6g} s", orbit->period));
    }
  }
  if (curves.empty()) return 0;
  plot += "set title 'Contacting-end displacement over one period, exact oracle (Fig. 11)'\n" +
          curves + "\n";
  const fs::path png = out / "resonant_end.png";
  render_figure(png, plot, 1200, 700);
  if (spectra.empty()) return 0;
  const fs::path spectrum_png = out / "resonant_end_spectrum.png";
  render_figure(
      spectrum_png,
      "set title 'What the attached orbit adds at the contacting end, u_{attached}(L,t) - "
      "u_{mode 1}(L,t): amplitude of each harmonic k {/Symbol w} = 2{/Symbol p}k/T (exact "
      "oracle)'\nset xlabel 'harmonic k'\n"
      "set ylabel 'amplitude [m]'\nset logscale y\nset format y '10^{%L}'\nset grid\n"
      "set xrange [0:41]\nset key top right\n" +
          spectra + "\n",
      1200, 600);
  return 0;
}

int draw_resonant_spacetime(const fs::path& out, const fs::path& scene_path) {
  const std::vector<fs::path> attached = figure_branches(out);
  if (attached.empty()) {
    fmt::print("[figures] resonant_spacetime skipped: no followed branch in {} (trace --follow)\n",
               (out / resonances_folder).string());
    return 0;
  }
  const core::Scene scene = core::read_scene(scene_keys(), scene_path.string(), {},
                                             boost::program_options::options_description());
  bar::BarSetup s = setup_from_scene(scene);
  // The highest-energy orbit of the first followed branch: u(x, t) at 121 instants of one
  // period on 200 intervals, exact oracle.
  const auto orbit = load_traced_orbit(attached.front(), 1e300, s.material.length);
  if (!orbit) return 0;
  s.u0 = orbit->u0;
  s.v0 = bar::PiecewiseLinear::zero(s.material.length);
  bar::SnapshotRequest request;
  request.elements = 200;
  std::string text = "t,x,u\n";
  const exact_bar::ExactBarSolver oracle;
  for (int k = 0; k <= 120; ++k) {
    const double t = orbit->period * k / 120;
    const bar::FieldSnapshot f = oracle.snapshot(s, t, request);
    if (!f.ok) {
      fmt::print(stderr, "[figures] resonant_spacetime: exact oracle failed at t = {}: {}\n", t,
                 f.message);
      return 1;
    }
    for (std::size_t i = 0; i < f.x.size(); ++i)
      text += fmt::format("{:.9g},{:.9g},{:.9g}\n", t, f.x[i], f.u[i]);
    text += "\n";  // gnuplot grid block separator
  }
  const fs::path csv = out / "resonant_spacetime.csv";
  core::write_text_atomically(csv, text);
  const std::string plot = fmt::format(
      "set title 'Internally resonant orbit (branch point {}) over one period (exact oracle): E = "
      "{:.3g} J, "
      "T = {:.6g} s'\n"
      "set xlabel 'x [m]'\nset ylabel 't [s]'\nset zlabel 'u [m]' rotate parallel\n"
      "set pm3d depthorder\nset palette rgbformulae 33,13,10\nset view 55,35\n"
      "set key top left\nset ticslevel 0\n"
      "splot {} using 'x':'t':'u' with pm3d title 'u(x,t)'\n",
      attached.front().filename().string().substr(13), orbit->energy, orbit->period,
      core::gnuplot_quote(csv));
  const fs::path png = out / "resonant_spacetime.png";
  render_figure(png, plot, 1100, 800);
  return 0;
}

int draw_attached_branches(const fs::path& out) {
  const fs::path mode1 = out / resonances_folder;
  if (!fs::exists(mode1 / "branch.csv")) {
    fmt::print("[figures] attached_branches skipped: no {}\n", (mode1 / "branch.csv").string());
    return 0;
  }
  const std::vector<fs::path> attached = followed_branches(mode1);
  if (attached.empty()) {
    fmt::print("[figures] attached_branches skipped: no followed branch in {} (trace --follow)\n",
               mode1.string());
    return 0;
  }
  std::string plot =
      "set title 'Mode 1 and the branches attached at its branch points (internal resonances)'\n"
      "set xlabel 'frequency {/Symbol w} [rad/s]'\nset ylabel 'energy E [J]'\n"
      "set logscale y\nset format y '10^{%L}'\nset grid\nset key outside right\n";
  plot += fmt::format(
      "plot {} using 'frequency':'energy' with linespoints pt 7 ps 0.5 lw 2 lc rgb 'blue' "
      "title 'mode 1'",
      core::gnuplot_quote(mode1 / "branch.csv"));
  if (fs::exists(mode1 / "branch_points.csv"))
    plot += fmt::format(
        ", {} using 'frequency':(column('verified') == 1 ? "
        "column('energy') : NaN) with points pt 6 ps 2 lc rgb 'black' title 'verified branch "
        "points'",
        core::gnuplot_quote(mode1 / "branch_points.csv"));
  for (const fs::path& dir : attached)
    plot += fmt::format(
        ", {} using 'frequency':'energy' with linespoints pt 5 ps 0.5 title "
        "'attached at branch point {}'",
        core::gnuplot_quote(dir / "branch.csv"),
        dir.filename().string().substr(13));  // "branch_point_K" -> K
  const fs::path png = out / "attached_branches.png";
  render_figure(png, plot + "\n", 1200, 700);
  return 0;
}

int write_law_table(const fs::path& out) {
  const fs::path dir = out / law_folder;
  if (!fs::exists(dir / "branch_points.csv") || !fs::exists(dir / "scene.ini")) {
    fmt::print("[figures] mode1_law skipped: no {}\n", (dir / "branch_points.csv").string());
    return 0;
  }
  // The run's resolved scene (its bar, and the grid and energy bound the step set) and its
  // first point's energy, where the branch starts.
  const fs::path scene = dir / "scene.ini";
  double L = 0, c = 0, g0 = 0, ea = 0, e_max = 0;
  int n = 0;
  try {
    auto number = [&](const char* key) { return std::stod(scene_value(scene, key)); };
    L = number("length");
    c = std::sqrt(number("youngs_modulus") / number("density"));
    g0 = number("gap");
    ea = number("youngs_modulus") * number("area");
    n = std::stoi(scene_value(scene, "shooting_elements"));
    e_max = number("energy_max");
  } catch (const std::exception&) {
    fmt::print(stderr,
               "[figures] mode1_law: {} lacks length, youngs_modulus, density, gap, "
               "area, shooting_elements or energy_max\n",
               scene.string());
    return 1;
  }
  const std::vector<double> branch_energy =
      core::Table::read_csv(dir / "branch.csv").column("energy");
  if (branch_energy.empty()) {
    fmt::print(stderr, "[figures] mode1_law: {} has no point\n", (dir / "branch.csv").string());
    return 1;
  }
  const double e_min = branch_energy.front();
  const core::Table points = core::Table::read_csv(dir / "branch_points.csv");
  const auto period = points.column("period"), energy = points.column("energy");
  const auto verified = points.column("verified"), dimension = points.column("dimension");
  // Every p/q of the law whose family this grid holds (p | 2N, 2N/p >= 3), T in (3, 4) L/c,
  // between the branch's first energy and energy_max (orbits/README.md, 'Attached families:
  // the law'), against the candidate located within 1e-4 L/c of it.
  core::Table table({"p", "q", "period_law", "energy_law", "dimension_law", "period_found",
                     "energy_found", "verified", "dimension_found", "period_error",
                     "energy_error"});
  double worst_period = 0, worst_energy = 0;
  int predicted = 0, found = 0;
  std::vector<bool> matched(period.size(), false);
  for (int p = 1; 2 * n / p >= 3; ++p) {
    if ((2 * n) % p != 0) continue;
    for (int q = (3 * p) / 2 + 1; 2 * q < 4 * p; ++q) {
      if (std::gcd(p, q) != 1) continue;
      const double t = 2.0 * q / p * L / c, k = 2.0 * q - 3.0 * p;
      const double e = ea * p * p * g0 * g0 / (2 * L * k * k);
      if (e < e_min || e > e_max) continue;
      ++predicted;
      const double nan = std::nan("");
      std::vector<double> row{static_cast<double>(p),
                              static_cast<double>(q),
                              t,
                              e,
                              std::ceil(static_cast<double>(n) / p) - 1,
                              nan,
                              nan,
                              0,
                              nan,
                              nan,
                              nan};
      for (std::size_t i = 0; i < period.size(); ++i)
        if (std::abs(period[i] - t) < 1e-4 * L / c) {
          matched[i] = true;
          row[5] = period[i];
          row[6] = energy[i];
          row[7] = verified[i];
          row[8] = dimension[i];
          row[9] = std::abs(period[i] / t - 1);
          row[10] = std::abs(energy[i] / e - 1);
          if (verified[i] == 1) {
            ++found;
            worst_period = std::max(worst_period, row[9]);
            worst_energy = std::max(worst_energy, row[10]);
          }
        }
      table.add_row(row);
    }
  }
  table.write_csv(out / "mode1_law.csv");
  const auto off_law = std::count(matched.begin(), matched.end(), false);
  fmt::print(
      "[figures] mode1_law.csv: {} families of the law on {} intervals between {:.3g} and {:.3g} "
      "J, {} located and verified (worst relative difference: period {:.1e}, energy {:.1e}), "
      "{} candidates off the law\n",
      predicted, n, e_min, e_max, found, worst_period, worst_energy, off_law);
  return 0;
}

std::vector<cli::ProblemJob> resonance_figure_jobs() {
  return {{"attached_branches",
           "attached_branches.png: mode 1 with its followed attached branches (Fig. 4 d)",
           draw_attached_branches},
          {"resonant_spacetime",
           "resonant_spacetime.png: u(x, t) over one period of an attached orbit (Fig. 10)",
           [](const fs::path& out) {
             return draw_resonant_spacetime(out, "problems/contact_bar/scenes/paper.ini");
           }},
          {"mode1_law",
           "mode1_law.csv: the families the law of the attached periods predicts on mode 1 "
           "against those located and verified (OUT/mode1_law)",
           write_law_table},
          {"resonant_end",
           "resonant_end.png: contacting end of an attached orbit beside mode 1 at its period "
           "(Fig. 11)",
           [](const fs::path& out) {
             return draw_resonant_end(out, "problems/contact_bar/scenes/paper.ini");
           }}};
}

}  // namespace backbone::contact_bar
