#include "problems/contact_bar/figures/modes.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>
#include <string>

#include "core/io/plot.hpp"
#include "core/io/scene.hpp"
#include "core/io/table.hpp"
#include "problems/contact_bar/orbits/family.hpp"
#include "problems/contact_bar/orbits/grazing_limits.hpp"
#include "problems/contact_bar/solver/scene.hpp"
#include "problems/contact_bar/solver/tdbem.hpp"
#include "problems/exact_bar/exact_bar_solver.hpp"
#include "problems/exact_bar/exact_solution.hpp"

namespace backbone::contact_bar {

namespace {

namespace fs = std::filesystem;
using core::Table;

// What the figures take from the scene.
struct FigureScene {
  bar::BarSetup setup;
  double dt = 0;
  int elements = 0;
};

FigureScene read_figure_scene(const FigureInputs& inputs) {
  const core::Scene scene = core::read_scene(contact_bar::scene_keys(), inputs.scene.string(), {},
                                             boost::program_options::options_description());
  return {setup_from_scene(scene), scene.positive("dt"),
          static_cast<int>(scene.integer("elements", 1))};
}

bool has_branch(const fs::path& dir) {
  return fs::exists(dir / "branch.csv");
}

// u(x, t) over one period of the orbit by TD-BEM snapshots (the field at one instant each):
// the gnuplot grid text (one t,x,u block per instant) and the snapshots themselves.
struct SpaceTime {
  std::string text = "t,x,u\n";
  std::vector<bar::FieldSnapshot> snapshots;
};

SpaceTime space_time(bar::BarSetup s, const TracedOrbit& orbit, double dt, int elements) {
  s.u0 = orbit.u0;
  s.v0 = bar::PiecewiseLinear::zero(s.material.length);
  const TdbemSolver tdbem(ContactMethod::event);
  bar::SnapshotRequest r;
  r.dt = std::min(dt, orbit.period / 400);
  r.elements = elements;
  const int instants = 120;
  SpaceTime st;
  for (int k = 0; k <= instants; ++k) {
    const double t = orbit.period * k / instants;
    bar::FieldSnapshot f = tdbem.snapshot(s, t, r);
    if (!f.ok) throw std::runtime_error(fmt::format("TD-BEM failed at t = {}: {}", t, f.message));
    for (std::size_t i = 0; i < f.x.size(); ++i)
      st.text += fmt::format("{:.9g},{:.9g},{:.9g}\n", t, f.x[i], f.u[i]);
    st.text += "\n";  // gnuplot grid block separator
    st.snapshots.push_back(std::move(f));
  }
  return st;
}

// Figs. 6, 7 for one branch; mode 2 marks its node x_n (node_of: where the traced u0 changes
// sign; ContactFamily::node is its closed form) and prints max_t |u(x_n, t)|.
void spacetime_figure(const fs::path& out, int mode, const FigureScene& scene,
                      const TracedOrbit& orbit) {
  const std::string name = fmt::format("mode{}", mode);
  const SpaceTime st = space_time(scene.setup, orbit, scene.dt, scene.elements);
  core::write_text_atomically(out / (name + "_spacetime.csv"), st.text);
  std::string marker, title_extra;
  const double x_node = node_of(orbit.u0);
  if (mode == 2 && std::isfinite(x_node)) {
    double max_abs = 0;
    for (const bar::FieldSnapshot& f : st.snapshots)
      max_abs = std::max(max_abs, std::abs(bar::PiecewiseLinear(f.x, f.u)(x_node)));
    const double closed_form =
        ContactFamily(scene.setup.material, scene.setup.right.gap, mode).node(orbit.energy);
    Table node({"t", "x", "u"});
    node.add_row({0.0, x_node, 0.0});
    node.add_row({orbit.period, x_node, 0.0});
    node.write_csv(out / (name + "_node.csv"));
    marker = fmt::format(
        ", {} using 'x':'t':'u' with lines lw 4 lc rgb 'red' title "
        "'node (u_0 = 0): x = {:.3g} m, max|u| = {:.2e} m'",
        core::gnuplot_quote(out / (name + "_node.csv")), x_node, max_abs);
    title_extra =
        fmt::format(", node at x = {:.3g} m (closed form 2bL = {:.3g} m)", x_node, closed_form);
  }
  const std::string plot = fmt::format(
      "set title '{} over one period (TD-BEM): E = {:.3g} J, T = {:.6g} s{}'\n"
      "set xlabel 'x [m]'\nset ylabel 't [s]'\nset zlabel 'u [m]' rotate parallel\n"
      "set pm3d depthorder\nset palette rgbformulae 33,13,10\nset view 55,35\n"
      "set key top left\nset ticslevel 0\n"
      "splot {} using 'x':'t':'u' with pm3d title 'u(x,t)'{}\n",
      fmt::format("Mode {}", mode), orbit.energy, orbit.period, title_extra,
      core::gnuplot_quote(out / (name + "_spacetime.csv")), marker);
  const fs::path png = out / (name + "_spacetime.png");
  render_figure(png, plot, 1100, 800);
}

}  // namespace

std::optional<TracedOrbit> load_traced_orbit(const fs::path& branch_dir, double target_energy,
                                             double length) {
  return load_traced_orbit_point(branch_dir, -1, target_energy, length);
}

std::optional<TracedOrbit> load_traced_orbit_point(const fs::path& branch_dir, int wanted,
                                                   double target_energy, double length) {
  if (!fs::exists(branch_dir / "branch.csv") || !fs::exists(branch_dir / "orbits.csv"))
    return std::nullopt;
  const Table branch = Table::read_csv(branch_dir / "branch.csv");
  const Table orbits = Table::read_csv(branch_dir / "orbits.csv");
  const auto point = branch.column("point"), energy = branch.column("energy"),
             period = branch.column("period");
  if (point.empty()) return std::nullopt;
  double lo = 1e300, hi = 0;
  for (double e : energy)
    if (e > 0) lo = std::min(lo, e), hi = std::max(hi, e);
  const double target = target_energy > 0 ? target_energy : std::sqrt(lo * hi);
  std::size_t best = 0;
  for (std::size_t i = 0; i < energy.size(); ++i)
    if (wanted >= 0
            ? point[i] == wanted
            : std::abs(std::log(energy[i] / target)) < std::abs(std::log(energy[best] / target)))
      best = i;
  if (wanted >= 0 && point[best] != wanted) return std::nullopt;
  std::vector<double> xs, us;
  const auto op = orbits.column("point"), ox = orbits.column("x"), ou = orbits.column("u0");
  for (std::size_t i = 0; i < op.size(); ++i) {
    if (op[i] != point[best]) continue;
    if (xs.empty() && ox[i] > 0) xs.push_back(0.0), us.push_back(0.0);  // fixed end
    xs.push_back(std::min(ox[i], length));
    us.push_back(ou[i]);
  }
  if (xs.size() < 2) return std::nullopt;
  return TracedOrbit{period[best], energy[best], bar::PiecewiseLinear(xs, us)};
}

// Fig. 4: frequency-energy backbones.
int draw_backbones(const fs::path& out, const FigureInputs& inputs) {
  const fs::path mode1 = out / "mode1", mode2 = out / "mode2";
  if (!has_branch(mode1) && !has_branch(mode2)) {
    fmt::print(stderr, "[figures] no branch found in {} or {}: run backbone trace first\n",
               mode1.string(), mode2.string());
    return 1;
  }
  const bar::BarSetup s = read_figure_scene(inputs).setup;
  const double L = s.material.length, c = s.material.wave_speed(), g0 = s.right.gap;
  double e_max = 1e-2;
  for (const fs::path& dir : {mode1, mode2})
    if (has_branch(dir))
      for (double e : Table::read_csv(dir / "branch.csv").column("energy"))
        e_max = std::max(e_max, e);
  // Closed forms of modes 1 and 2, from grazing up.
  const ContactFamily family1(s.material, g0, 1), family2(s.material, g0, 2);
  for (const ContactFamily* family : {&family1, &family2}) {
    Table closed({"energy", "frequency"});
    const double e_graze = family->grazing_energy();
    for (int i = 0; i <= 400; ++i) {
      const double e = e_graze * std::pow(e_max / e_graze, i / 400.0) * (1 + 1e-12);
      closed.add_row({e, family->frequency(e)});
    }
    closed.write_csv(out / fmt::format("backbone_mode{}_closed_form.csv", family->mode()));
  }
  const double w1 = family1.linear_frequency(), w2 = family2.linear_frequency();
  const double w_inf = family1.asymptotic_frequency(), w2_inf = family2.asymptotic_frequency();
  std::string plot = fmt::format(
      "set title 'Backbones of the contact bar (g_0 = {} m, c = {} m/s, L = {} m)'\n"
      "set xlabel 'frequency {{/Symbol w}} [rad/s]'\nset ylabel 'energy E [J]'\n"
      "set logscale y\nset format y '10^{{%L}}'\nset grid\nset key below maxrows 4\n"
      "set xrange [{}:{}]\n"
      "set arrow from {},graph 0 to {},graph 1 nohead lc rgb 'gray40' dt 2\n"
      "set arrow from {},graph 0 to {},graph 1 nohead lc rgb 'gray40' dt 2\n"
      "set arrow from {},graph 0 to {},graph 1 nohead lc rgb 'dark-red' dt 3\n"
      "set arrow from {},graph 0 to {},graph 1 nohead lc rgb 'dark-red' dt 3\n"
      "set label '8{{/Symbol p}}c/(5L)' at {},graph 0.95 rotate by 90 right font ',9'\n"
      "set label 'linear mode 1' at {},graph 0.95 rotate by 90 right font ',9'\n"
      "set label 'linear mode 2' at {},graph 0.95 rotate by 90 right font ',9'\n"
      "set label '2{{/Symbol p}}c/(3L)' at {},graph 0.95 rotate by 90 right font ',9'\n"
      "plot {} using 'frequency':'energy' with lines lw 2 lc rgb 'black' title 'mode 1, closed "
      "form', {} using 'frequency':'energy' with lines lw 2 lc rgb 'gray50' title 'mode 2, "
      "closed form'",
      g0, c, L, 0.9 * w1, 1.1 * w2_inf, w1, w1, w2, w2, w_inf, w_inf, w2_inf, w2_inf,
      w2_inf - 0.02 * w1, w1 - 0.02 * w1, w2 - 0.02 * w1, w_inf - 0.02 * w1,
      core::gnuplot_quote(out / "backbone_mode1_closed_form.csv"),
      core::gnuplot_quote(out / "backbone_mode2_closed_form.csv"));
  if (has_branch(mode1))
    plot += fmt::format(
        ", {} using 'frequency':'energy' with points pt 7 ps 0.6 lc rgb 'blue' "
        "title 'mode 1, TD-BEM shooting'",
        core::gnuplot_quote(mode1 / "branch.csv"));
  if (has_branch(mode2))
    plot += fmt::format(
        ", {} using 'frequency':'energy' with points pt 5 ps 0.6 lc rgb "
        "'dark-green' title 'mode 2, TD-BEM shooting'",
        core::gnuplot_quote(mode2 / "branch.csv"));
  // The subharmonic backbone (mode 2 over two periods, omega2 / 2): a band where its verified
  // dimension is 2 (at each of its points a continuum of shapes), points where it is not.
  const fs::path sub = out / "subharmonic";
  if (has_branch(sub)) {
    const Table b = Table::read_csv(sub / "branch.csv");
    const auto w = b.column("frequency"), e = b.column("energy"), d = b.column("dimension");
    Table band({"frequency", "energy", "frequency_2d", "frequency_other", "closed_form"});
    int two = 0;
    for (std::size_t i = 0; i < w.size(); ++i) {
      const bool is_2d = i < d.size() && d[i] == 2;
      two += is_2d ? 1 : 0;
      band.add_row({w[i], e[i], is_2d ? w[i] : std::nan(""), is_2d ? std::nan("") : w[i],
                    0.5 * family2.frequency(e[i])});
    }
    band.write_csv(out / "backbone_subharmonic.csv");
    plot += fmt::format(
        ", {} using 'frequency_2d':'energy' with lines lw 14 lc rgb '#A0FF8C00' title "
        "'subharmonic {{/Symbol w}}_2/2: 2D manifold ({} of {} points dimension 2)', {} using "
        "'frequency':'energy' with points pt 9 ps 0.6 lc rgb 'dark-orange' title 'subharmonic, "
        "TD-BEM shooting', {} using 'closed_form':'energy' with lines lw 1 lc rgb 'black' dt 2 "
        "title 'subharmonic, closed form {{/Symbol w}}_2(E)/2', {} using "
        "'frequency_other':'energy' with points pt 6 ps 1.2 lc rgb "
        "'black' title 'subharmonic, dimension not 2'",
        core::gnuplot_quote(out / "backbone_subharmonic.csv"), two, w.size(),
        core::gnuplot_quote(out / "backbone_subharmonic.csv"),
        core::gnuplot_quote(out / "backbone_subharmonic.csv"),
        core::gnuplot_quote(out / "backbone_subharmonic.csv"));
  }
  const fs::path png = out / "backbones.png";
  render_figure(png, plot + "\n", 1200, 850);
  return 0;
}

// Fig. 5: contacting-end displacement and contact force over one period of a mode-1 orbit.
int draw_mode1_contact(const fs::path& out, const FigureInputs& inputs) {
  const FigureScene scene = read_figure_scene(inputs);
  bar::BarSetup s = scene.setup;
  const auto orbit = load_traced_orbit(out / "mode1", inputs.energy, s.material.length);
  if (!orbit) {
    fmt::print("[figures] mode1_contact skipped: no orbit in {}\n", (out / "mode1").string());
    return 0;
  }
  s.u0 = orbit->u0;
  s.v0 = bar::PiecewiseLinear::zero(s.material.length);
  bar::SimulationOptions o;
  o.t_end = orbit->period;
  o.dt = std::min(scene.dt, orbit->period / 400);
  o.history_samples = 801;
  o.energy = false;
  const bar::History h = TdbemSolver(ContactMethod::event).simulate(s, o);
  const bar::History e = exact_bar::ExactBarSolver().simulate(s, o);
  h.to_table().write_csv(out / "mode1_contact_tdbem.csv");
  e.to_table().write_csv(out / "mode1_contact_exact.csv");
  const std::string exact_csv = core::gnuplot_quote(out / "mode1_contact_exact.csv");
  const std::string tdbem_csv = core::gnuplot_quote(out / "mode1_contact_tdbem.csv");
  const std::string plot = fmt::format(
      "set multiplot layout 2,1 title 'Mode 1 over one period: E = {:.3g} J, T = {:.6g} s'\n"
      "set grid\nset xlabel 't [s]'\nset ylabel 'u(L,t) [m]'\nset key bottom right\n"
      "set arrow from graph 0,first {} to graph 1,first {} nohead dt 2 lc rgb 'gray40'\n"
      "plot {} using 't':'u_contact' with lines lw 3 lc rgb 'gray70' title 'exact', "
      "{} using 't':'u_contact' with lines lw 1.5 lc rgb 'blue' title 'TD-BEM'\n"
      "unset arrow\nset ylabel 'contact force {{/Symbol l}} [N]'\n"
      "plot {} using 't':'contact_force' with lines lw 3 lc rgb 'gray70' title 'exact', "
      "{} using 't':'contact_force' with lines lw 1.5 lc rgb 'blue' title 'TD-BEM'\n"
      "unset multiplot\n",
      orbit->energy, orbit->period, s.right.gap, s.right.gap, exact_csv, tdbem_csv, exact_csv,
      tdbem_csv);
  const fs::path png = out / "mode1_contact.png";
  render_figure(png, plot, 1000, 800);
  return 0;
}

int draw_spacetime(const fs::path& out, const FigureInputs& inputs) {
  const FigureScene scene = read_figure_scene(inputs);
  for (int mode : {1, 2, 3}) {
    const fs::path dir = out / fmt::format("mode{}", mode);
    if (const auto orbit = load_traced_orbit(dir, inputs.energy, scene.setup.material.length))
      spacetime_figure(out, mode, scene, *orbit);
    else
      fmt::print("[figures] mode{}_spacetime skipped: no orbit in {}\n", mode, dir.string());
  }
  return 0;
}

// Fig. 4 widened: modes 1 to 5 (closed forms from grazing, traced points where OUT/modeJ holds
// a branch), the subharmonic band of mode 2, and the families attached to mode 1 (OUT/
// mode1_resonances/branch_point_K) as the vertical segments they are.
int draw_all_backbones(const fs::path& out, const FigureInputs& inputs) {
  const bar::BarSetup s = read_figure_scene(inputs).setup;
  const double g0 = s.right.gap;
  constexpr int modes = 5;
  double e_max = 1e-2;
  for (int j = 1; j <= modes; ++j)
    if (const fs::path dir = out / fmt::format("mode{}", j); has_branch(dir))
      for (double e : Table::read_csv(dir / "branch.csv").column("energy"))
        e_max = std::max(e_max, e);
  const char* colours[] = {"black", "dark-green", "blue", "dark-violet", "dark-red"};
  std::string curves;
  for (int j = 1; j <= modes; ++j) {
    const ContactFamily family(s.material, g0, j);
    Table closed({"energy", "frequency"});
    const double e_graze = family.grazing_energy();
    for (int i = 0; i <= 400; ++i) {
      const double e = e_graze * std::pow(e_max / e_graze, i / 400.0) * (1 + 1e-12);
      closed.add_row({e, family.frequency(e)});
    }
    const fs::path csv = out / fmt::format("backbones_all_mode{}_closed_form.csv", j);
    closed.write_csv(csv);
    curves += fmt::format(
        "{}{} using 'frequency':'energy' with lines lw 2 lc rgb '{}' title 'mode {}, closed form'",
        curves.empty() ? "plot " : ", ", core::gnuplot_quote(csv), colours[j - 1], j);
    if (const fs::path dir = out / fmt::format("mode{}", j); has_branch(dir))
      curves += fmt::format(
          ", {} using 'frequency':'energy' with points pt 7 ps 0.5 lc rgb '{}' title 'mode {}, "
          "TD-BEM shooting'",
          core::gnuplot_quote(dir / "branch.csv"), colours[j - 1], j);
  }
  if (fs::exists(out / "backbone_subharmonic.csv"))
    curves += fmt::format(
        ", {} using 'frequency_2d':'energy' with lines lw 10 lc rgb '#A0FF8C00' title "
        "'subharmonic band of mode 2 ({{/Symbol w}}_2/2, 2D)'",
        core::gnuplot_quote(out / "backbone_subharmonic.csv"));
  // Mode 4's band: its traced backbone where F alone has dimension 2, every point drawn.
  if (const fs::path sub4 = out / "subharmonic4"; has_branch(sub4)) {
    const Table b = Table::read_csv(sub4 / "branch.csv");
    const auto w = b.column("frequency"), e = b.column("energy"), d = b.column("dimension");
    Table band({"frequency", "energy", "frequency_2d"});
    int two = 0;
    for (std::size_t i = 0; i < w.size(); ++i) {
      const bool is_2d = i < d.size() && d[i] == 2;
      two += is_2d ? 1 : 0;
      band.add_row({w[i], e[i], is_2d ? w[i] : std::nan("")});
    }
    band.write_csv(out / "backbones_all_subharmonic4.csv");
    curves += fmt::format(
        ", {0} using 'frequency_2d':'energy' with lines lw 10 lc rgb '#A08B008B' title "
        "'subharmonic band of mode 4 ({{/Symbol w}}_4/2, 2D at {1} of {2} points)', {0} using "
        "'frequency':'energy' with points pt 9 ps 0.5 lc rgb 'dark-magenta' notitle",
        core::gnuplot_quote(out / "backbones_all_subharmonic4.csv"), two, w.size());
  }
  // The families attached to modes 1 to 3 that the main job follows, each a vertical segment
  // (constant period) labelled with its period in L/c at its top.
  int attached = 0;
  std::string labels;
  const double tau = s.material.length / s.material.wave_speed();
  for (const char* folder : {"mode1_resonances", "mode1_resonance_twelve", "mode2_resonances",
                             "mode2_resonances_14_11", "mode3_resonances"}) {
    for (const fs::path& dir : followed_branches(out / folder)) {
      curves += fmt::format(
          ", {} using 'frequency':'energy' with linespoints pt 1 ps 0.4 lw 2 lc rgb 'orange' {}",
          core::gnuplot_quote(dir / "branch.csv"),
          attached == 0 ? "title 'families attached to modes 1 to 3 (period in L/c)'" : "notitle");
      const Table b = Table::read_csv(dir / "branch.csv");
      const auto w = b.column("frequency"), e = b.column("energy"), t = b.column("period");
      if (!w.empty())
        labels += fmt::format(
            "set label {} 'T = {:.5g}' at {:.9g},{:.9g} right offset -0.5,0 "
            "font ',9' tc rgb 'dark-orange'\n",
            attached + 1, t.back() / tau, w.back(), *std::max_element(e.begin(), e.end()));
      ++attached;
    }
  }
  const double w1 = ContactFamily(s.material, g0, 1).linear_frequency();
  const double w_top = ContactFamily(s.material, g0, modes).asymptotic_frequency();
  const std::string plot = fmt::format(
      "set title 'Backbones of modes 1 to {} (g_0 = {} m, c = {} m/s, L = {} m)'\n"
      "set xlabel 'frequency {{/Symbol w}} [rad/s]'\nset ylabel 'energy E [J]'\n"
      "set logscale y\nset format y '10^{{%L}}'\nset grid\nset key below maxrows 5\n"
      "set xrange [{}:{}]\n{}{}\n",
      modes, g0, s.material.wave_speed(), s.material.length, 0.8 * w1, 1.05 * w_top, labels,
      curves);
  const fs::path png = out / "backbones_all.png";
  render_figure(png, plot, 1400, 900);
  return 0;
}

// closed_form_summary.csv: the acceptance numbers of every branch in one table.
int write_closed_form_summary(const fs::path& out) {
  std::vector<fs::path> dirs;
  if (fs::is_directory(out))
    for (const auto& entry : fs::directory_iterator(out))
      if (entry.is_directory() && fs::exists(entry.path() / "closed_form_check.csv") &&
          has_branch(entry.path()))
        dirs.push_back(entry.path());
  std::sort(dirs.begin(), dirs.end());
  Table summary({"branch", "points", "energy_first", "energy_last", "worst_relative_error",
                 "worst_return_error_u", "worst_return_error_v", "jacobian_evaluations"});
  for (const fs::path& dir : dirs) {
    const Table check = Table::read_csv(dir / "closed_form_check.csv");
    const auto energy = check.column("energy");
    if (energy.empty()) continue;
    const auto worst = [&](const char* name) {
      const auto v = check.column(name);
      return *std::max_element(v.begin(), v.end());
    };
    double jacobians = 0;  // the branch's cost, deterministic (its wall time varies run to run)
    for (double j : Table::read_csv(dir / "branch.csv").column("jacobian_evaluations"))
      jacobians += j;
    const std::string name = dir.filename().string();
    summary.add_row(name,
                    {double(energy.size()), energy.front(), energy.back(), worst("relative_error"),
                     worst("return_error_u"), worst("return_error_v"), jacobians});
    fmt::print(
        "[figures] {}: {} points, E {:.3g} .. {:.3g}, worst closed-form error {:.2e}, "
        "return error {:.2e}, {:.0f} Jacobians\n",
        name, energy.size(), energy.front(), energy.back(), worst("relative_error"),
        worst("return_error_u"), jacobians);
  }
  if (!dirs.empty()) summary.write_csv(out / "closed_form_summary.csv");
  return 0;
}

// Paper Fig. 8: the contacting-end displacement u(L, t) over T = 2 T2 of the traced members of
// OUT/subharmonic_continuum (exact solver; coloured by their shape), with the two grazing
// limits located by NLopt (grazing_limits.hpp) drawn thick.
int draw_subharmonic_continuum(const fs::path& out, const FigureInputs& inputs) {
  const fs::path dir = out / "subharmonic_continuum";
  if (!has_branch(dir) || !fs::exists(dir / "orbits.csv")) {
    fmt::print("[figures] subharmonic_continuum skipped: no branch in {}\n", dir.string());
    return 0;
  }
  const FigureScene scene = read_figure_scene(inputs);
  bar::BarSetup s = scene.setup;
  const double length = s.material.length, g0 = s.right.gap;
  const Table branch = Table::read_csv(dir / "branch.csv");
  const auto points = branch.column("point");
  const auto shapes = branch.column("shape");
  const int samples = 800;
  std::string members = "t,u_L,shape\n";
  double energy = 0, period = 0;
  int drawn = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto orbit = load_traced_orbit_point(dir, static_cast<int>(points[i]), 0, length);
    if (!orbit) continue;
    s.u0 = orbit->u0;
    s.v0 = bar::PiecewiseLinear::zero(length);
    const exact_bar::ExactBarSolution sol(s, orbit->period);
    if (!sol.ok()) continue;
    for (int k = 0; k <= samples; ++k) {
      const double t = orbit->period * k / samples;
      members += fmt::format("{:.9g},{:.9g},{:.6g}\n", t, sol.u_end(exact_bar::Side::right, t),
                             i < shapes.size() ? shapes[i] : 0.0);
    }
    members += "\n";
    energy = orbit->energy, period = orbit->period;
    ++drawn;
  }
  if (drawn == 0) {
    fmt::print("[figures] subharmonic_continuum skipped: no orbit in {}\n", dir.string());
    return 0;
  }
  core::write_text_atomically(out / "subharmonic_continuum_members.csv", members);
  // The limits, by NLopt at the members' energy.
  const GrazingLimits g = grazing_limits(s, TdbemSolver(ContactMethod::event), energy, {});
  Table limits({"t", "u_L_shape_1", "u_L_shape_0"});
  std::vector<exact_bar::ExactBarSolution> limit_solutions;
  for (const GrazingLimit& l : g.limits) {
    s.u0 = l.u0;
    limit_solutions.emplace_back(s, l.period);
  }
  for (int k = 0; k <= samples; ++k) {
    std::vector<double> row{period * k / samples};
    for (std::size_t j = 0; j < g.limits.size(); ++j) {
      const double t = std::min(g.limits[j].period * k / samples, limit_solutions[j].t_end());
      row.push_back(limit_solutions[j].ok() ? limit_solutions[j].u_end(exact_bar::Side::right, t)
                                            : std::nan(""));
    }
    limits.add_row(row);
  }
  limits.write_csv(out / "subharmonic_continuum_limits.csv");
  const std::string plot = fmt::format(
      "set title 'Subharmonic continuum at E = {:.3g} J: {} traced members, T = 2 T_2 = {:.6g} "
      "s (exact re-simulation)'\n"
      "set xlabel 't [s]'\nset ylabel 'contacting-end displacement u(L,t) [m]'\nset grid\n"
      "set key below horizontal\nset palette defined (0 'dark-orange', 0.5 'gray60', 1 "
      "'dark-cyan')\nset cblabel 'shape (first contact phase / total contact time)'\n"
      "set cbrange [0:1]\nset xrange [0:{}]\nset yrange [*:{}]\n"
      "plot {} using 't':'u_L':'shape' with lines lw 1 lc palette title 'members', "
      "{} using 't':'u_L_shape_1' with lines lw 4 lc rgb 'blue' title 'grazing limit, shape 1 "
      "(NLopt)', {} using 't':'u_L_shape_0' with lines lw 4 dt 2 lc rgb 'red' title 'grazing "
      "limit, shape 0 (NLopt)', {} with lines lw 1.5 lc rgb 'black' dt 3 title 'wall u = g_0 = "
      "{:g} m'\n",
      energy, drawn, period, period, 1.25 * g0,
      core::gnuplot_quote(out / "subharmonic_continuum_members.csv"),
      core::gnuplot_quote(out / "subharmonic_continuum_limits.csv"),
      core::gnuplot_quote(out / "subharmonic_continuum_limits.csv"), g0, g0);
  const fs::path png = out / "subharmonic_continuum.png";
  render_figure(png, plot, 1300, 700);
  return 0;
}

// Paper Fig. 9: u(x, t) over T = 2 T2 of the grazing limit shape 1 (the first member of
// OUT/subharmonic_continuum), TD-BEM.
int draw_subharmonic_spacetime(const fs::path& out, const FigureInputs& inputs) {
  const fs::path dir = out / "subharmonic_continuum";
  const FigureScene scene = read_figure_scene(inputs);
  const auto orbit = load_traced_orbit_point(dir, 0, 0, scene.setup.material.length);
  if (!orbit) {
    fmt::print("[figures] subharmonic_spacetime skipped: no orbit in {}\n", dir.string());
    return 0;
  }
  const SpaceTime st = space_time(scene.setup, *orbit, scene.dt, scene.elements);
  core::write_text_atomically(out / "subharmonic_spacetime.csv", st.text);
  const std::string plot = fmt::format(
      "set title 'Grazing subharmonic orbit (limit shape 1) over T = 2 T_2 (TD-BEM): E = {:.3g} "
      "J, T = {:.6g} s, wall at g_0 = {:g} m'\n"
      "set xlabel 'x [m]'\nset ylabel 't [s]'\nset zlabel 'u [m]' rotate parallel\n"
      "set pm3d depthorder\nset palette rgbformulae 33,13,10\nset view 55,35\n"
      "set key top left\nset ticslevel 0\n"
      "splot {} using 'x':'t':'u' with pm3d title 'u(x,t)'\n",
      orbit->energy, orbit->period, scene.setup.right.gap,
      core::gnuplot_quote(out / "subharmonic_spacetime.csv"));
  const fs::path png = out / "subharmonic_spacetime.png";
  render_figure(png, plot, 1100, 800);
  return 0;
}

std::vector<cli::ProblemJob> figure_jobs(const FigureInputs& inputs) {
  return {
      {"backbones", "backbones.png: frequency-energy backbones of modes 1 and 2 (Fig. 4)",
       [inputs](const fs::path& out) { return draw_backbones(out, inputs); }},
      {"backbones_all",
       "backbones_all.png: modes 1 to 5, the subharmonic band and the attached families",
       [inputs](const fs::path& out) { return draw_all_backbones(out, inputs); }},
      {"mode1_contact", "mode1_contact.png: contact end over one mode-1 period (Fig. 5)",
       [inputs](const fs::path& out) { return draw_mode1_contact(out, inputs); }},
      {"spacetime", "mode1/2/3_spacetime.png: u(x, t) over one period (Figs. 6, 7)",
       [inputs](const fs::path& out) { return draw_spacetime(out, inputs); }},
      {"subharmonic_continuum",
       "subharmonic_continuum.png: u(L, t) of the continuum's members and its NLopt grazing "
       "limits (Fig. 8)",
       [inputs](const fs::path& out) { return draw_subharmonic_continuum(out, inputs); }},
      {"subharmonic_spacetime",
       "subharmonic_spacetime.png: u(x, t) of a grazing subharmonic orbit over 2 T2 (Fig. 9)",
       [inputs](const fs::path& out) { return draw_subharmonic_spacetime(out, inputs); }},
      {"closed_form_summary", "closed_form_summary.csv: acceptance numbers of every branch",
       write_closed_form_summary},
  };
}

// The value of `key` in a trace's resolved scene.ini ("key = value", a default commented out
// as "# key = value  (default)"); empty when absent.
std::string scene_value(const fs::path& scene, const std::string& key) {
  std::ifstream in(scene);
  std::string line;
  while (std::getline(in, line)) {
    std::string text = line;
    if (text.rfind("# ", 0) == 0) text = text.substr(2);
    const auto eq = text.find(" = ");
    if (eq == std::string::npos || text.substr(0, eq) != key) continue;
    std::string value = text.substr(eq + 3);
    const auto note = value.find("  (default)");
    if (note != std::string::npos) value = value.substr(0, note);
    return value;
  }
  return {};
}

void render_figure(const fs::path& png, const std::string& plot, int width, int height) {
  const core::PlotResult r = core::render_png(png, plot, {width, height});
  if (r.ok)
    fmt::print("[figures] wrote {}\n", png.string());
  else
    fmt::print(stderr, "[figures] {}\n", r.message);
}

std::vector<fs::path> followed_branches(const fs::path& dir) {
  std::vector<fs::path> followed;
  if (!fs::exists(dir)) return followed;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().filename().string().rfind("branch_point_", 0) == 0 && has_branch(entry.path()))
      followed.push_back(entry.path());
  std::sort(followed.begin(), followed.end());
  return followed;
}

}  // namespace backbone::contact_bar
