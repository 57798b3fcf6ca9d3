// `backbone figures`: the paper's figures of the contact-bar modes, drawn from the outputs of
// `backbone trace` (branch.csv, orbits.csv of mode1 and mode2):
//   backbones.png        frequency-energy backbones, log energy axis, linear modes and the
//                        asymptotes 2 pi c / (3L) (mode 1) and 8 pi c / (5L) (mode 2) as
//                        vertical lines, closed forms of both modes
//   mode1_contact.png    contacting-end displacement and contact force over one period of a
//                        mode-1 orbit (TD-BEM and the exact oracle)
//   mode1_spacetime.png, mode2_spacetime.png
//                        u(x, t) over one period (TD-BEM), mode 2 marking the point of the
//                        bar that stays closest to zero displacement
// with the CSV behind each figure beside it, and
//   closed_form_summary.csv
//                        one row per traced contact-bar branch found in OUT/*/ (its
//                        closed_form_check.csv): points, energy range, worst closed-form
//                        frequency error and exact-oracle return errors, point seconds
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <sstream>

#include "core/errors.hpp"
#include "core/plot.hpp"
#include "core/scene.hpp"
#include "core/table.hpp"
#include "drivers/commands.hpp"
#include "problems/contact_bar/periodic_bar.hpp"
#include "problems/contact_bar/scene.hpp"
#include "problems/contact_bar/tdbem.hpp"
#include "problems/exact_bar/exact_bar_solver.hpp"

namespace {

namespace po = boost::program_options;
namespace fs = std::filesystem;
using backbone::core::InputError;
using backbone::core::Table;
using namespace backbone;
using std::numbers::pi;

// One orbit of a traced branch: its period, energy and initial displacement.
struct Orbit {
  double period = 0;
  double energy = 0;
  bar::PiecewiseLinear u0;
};

// The orbit of `branch_dir` whose energy is closest (in log) to `target_energy`
// (target <= 0: the middle of the branch's energy range).
bool load_orbit(const fs::path& branch_dir, double target_energy, double length, Orbit& orbit) {
  if (!fs::exists(branch_dir / "branch.csv") || !fs::exists(branch_dir / "orbits.csv"))
    return false;
  const Table branch = Table::read_csv(branch_dir / "branch.csv");
  const Table orbits = Table::read_csv(branch_dir / "orbits.csv");
  const auto point = branch.column("point"), energy = branch.column("energy"),
             period = branch.column("period");
  if (point.empty()) return false;
  double lo = 1e300, hi = 0;
  for (double e : energy)
    if (e > 0) lo = std::min(lo, e), hi = std::max(hi, e);
  const double target = target_energy > 0 ? target_energy : std::sqrt(lo * hi);
  std::size_t best = 0;
  for (std::size_t i = 0; i < energy.size(); ++i)
    if (std::abs(std::log(energy[i] / target)) < std::abs(std::log(energy[best] / target)))
      best = i;
  orbit.period = period[best];
  orbit.energy = energy[best];
  std::vector<double> xs, us;
  const auto op = orbits.column("point"), ox = orbits.column("x"), ou = orbits.column("u0");
  for (std::size_t i = 0; i < op.size(); ++i) {
    if (op[i] != point[best]) continue;
    if (xs.empty() && ox[i] > 0) xs.push_back(0.0), us.push_back(0.0);  // fixed end
    xs.push_back(std::min(ox[i], length));
    us.push_back(ou[i]);
  }
  if (xs.size() < 2) return false;
  orbit.u0 = bar::PiecewiseLinear(xs, us);
  return true;
}

void report(const backbone::core::PlotResult& r, const fs::path& png) {
  if (r.ok)
    fmt::print("[figures] wrote {}\n", png.string());
  else
    fmt::print(stderr, "[figures] {}\n", r.message);
}

// Fig. 4: frequency-energy backbones.
void backbones_figure(const fs::path& out, const bar::BarSetup& s, const fs::path& mode1,
                      const fs::path& mode2) {
  const double L = s.material.length, c = s.material.wave_speed(),
               EA = s.material.axial_stiffness(), g0 = s.right.gap;
  double e_max = 1e-2;
  for (const fs::path& dir : {mode1, mode2})
    if (fs::exists(dir / "branch.csv"))
      for (double e : Table::read_csv(dir / "branch.csv").column("energy"))
        e_max = std::max(e_max, e);
  // Closed forms of modes 1 (DESIGN.md section 1) and 2 (periodic_bar.cpp), from grazing up.
  for (int mode : {1, 2}) {
    Table closed({"energy", "frequency"});
    const double e_graze = EA * std::pow((2 * mode - 1) * g0, 2) / (2 * L);
    for (int i = 0; i <= 400; ++i) {
      const double e = e_graze * std::pow(e_max / e_graze, i / 400.0) * (1 + 1e-12);
      closed.add_row({e, mode == 1 ? contact_bar::mode1_frequency(s.material, g0, e)
                                   : contact_bar::mode2_frequency(s.material, g0, e)});
    }
    closed.write_csv(out / fmt::format("backbone_mode{}_closed_form.csv", mode));
  }
  const double w1 = pi * c / (2 * L), w2 = 3 * pi * c / (2 * L), w_inf = 2 * pi * c / (3 * L);
  const double w2_inf = 8 * pi * c / (5 * L);  // mode 2: T -> 5L / (4c)
  std::string plot = fmt::format(
      "set title 'Backbones of the contact bar (g_0 = {} m, c = {} m/s, L = {} m)'\n"
      "set xlabel 'frequency {{/Symbol w}} [rad/s]'\nset ylabel 'energy E [J]'\n"
      "set logscale y\nset format y '10^{{%L}}'\nset grid\nset key outside right\n"
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
      backbone::core::gnuplot_quote(out / "backbone_mode1_closed_form.csv"),
      backbone::core::gnuplot_quote(out / "backbone_mode2_closed_form.csv"));
  if (fs::exists(mode1 / "branch.csv"))
    plot += fmt::format(
        ", {} using 'frequency':'energy' with points pt 7 ps 0.6 lc rgb 'blue' "
        "title 'mode 1, TD-BEM shooting'",
        backbone::core::gnuplot_quote(mode1 / "branch.csv"));
  if (fs::exists(mode2 / "branch.csv"))
    plot += fmt::format(
        ", {} using 'frequency':'energy' with points pt 5 ps 0.6 lc rgb "
        "'dark-green' title 'mode 2, TD-BEM shooting'",
        backbone::core::gnuplot_quote(mode2 / "branch.csv"));
  const fs::path png = out / "backbones.png";
  report(backbone::core::render_png(png, plot + "\n", {1200, 700}), png);
}

// Fig. 5: contacting-end displacement and contact force over one period of a mode-1 orbit.
void contact_figure(const fs::path& out, bar::BarSetup s, const Orbit& orbit, double dt) {
  s.u0 = orbit.u0;
  s.v0 = bar::PiecewiseLinear::zero(s.material.length);
  bar::SimulationOptions o;
  o.t_end = orbit.period;
  o.dt = std::min(dt, orbit.period / 400);
  o.history_samples = 801;
  o.energy = false;
  const contact_bar::TdbemSolver tdbem(contact_bar::ContactMethod::event);
  const exact_bar::ExactBarSolver exact;
  const bar::History h = tdbem.simulate(s, o);
  const bar::History e = exact.simulate(s, o);
  h.to_table().write_csv(out / "mode1_contact_tdbem.csv");
  e.to_table().write_csv(out / "mode1_contact_exact.csv");
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
      orbit.energy, orbit.period, s.right.gap, s.right.gap,
      backbone::core::gnuplot_quote(out / "mode1_contact_exact.csv"),
      backbone::core::gnuplot_quote(out / "mode1_contact_tdbem.csv"),
      backbone::core::gnuplot_quote(out / "mode1_contact_exact.csv"),
      backbone::core::gnuplot_quote(out / "mode1_contact_tdbem.csv"));
  const fs::path png = out / "mode1_contact.png";
  report(backbone::core::render_png(png, plot, {1000, 800}), png);
}

// Figs. 6, 7: u(x, t) over one period by TD-BEM snapshots (field at one instant each).
void spacetime_figure(const fs::path& out, const std::string& name, bar::BarSetup s,
                      const Orbit& orbit, double dt, int elements, bool mark_node) {
  s.u0 = orbit.u0;
  s.v0 = bar::PiecewiseLinear::zero(s.material.length);
  const contact_bar::TdbemSolver tdbem(contact_bar::ContactMethod::event);
  bar::SnapshotRequest r;
  r.dt = std::min(dt, orbit.period / 400);
  r.elements = elements;
  const int instants = 120;
  std::string text = "t,x,u\n";
  std::vector<double> max_abs(static_cast<std::size_t>(elements + 1), 0.0);
  std::vector<double> xs;
  for (int k = 0; k <= instants; ++k) {
    const double t = orbit.period * k / instants;
    const bar::FieldSnapshot f = tdbem.snapshot(s, t, r);
    if (!f.ok) throw std::runtime_error(fmt::format("TD-BEM failed at t = {}: {}", t, f.message));
    xs = f.x;
    for (std::size_t i = 0; i < f.x.size(); ++i) {
      text += fmt::format("{:.9g},{:.9g},{:.9g}\n", t, f.x[i], f.u[i]);
      max_abs[i] = std::max(max_abs[i], std::abs(f.u[i]));
    }
    text += "\n";  // gnuplot grid block separator
  }
  backbone::core::write_text_atomically(out / (name + "_spacetime.csv"), text);
  std::string marker;
  std::string title_extra;
  if (mark_node) {
    // The node: the interior local minimum of max_t |u(x, t)| with the smallest value (the
    // fixed end x = 0 is excluded: near it |u| is small only because u(0) = 0).
    std::size_t best = 0;
    for (std::size_t i = 1; i + 1 < max_abs.size(); ++i)
      if (max_abs[i] <= max_abs[i - 1] && max_abs[i] <= max_abs[i + 1] &&
          (best == 0 || max_abs[i] < max_abs[best]))
        best = i;
    if (best == 0) best = max_abs.size() - 1;
    Table node({"t", "x", "u"});
    node.add_row({0.0, xs[best], 0.0});
    node.add_row({orbit.period, xs[best], 0.0});
    node.write_csv(out / (name + "_node.csv"));
    marker = fmt::format(
        ", {} using 'x':'t':'u' with lines lw 4 lc rgb 'red' title "
        "'closest to a node: x = {:.3g} m, max|u| = {:.2e} m'",
        backbone::core::gnuplot_quote(out / (name + "_node.csv")), xs[best], max_abs[best]);
    title_extra = fmt::format(", quasi-node at x = {:.3g} m", xs[best]);
  }
  const std::string plot = fmt::format(
      "set title '{} over one period (TD-BEM): E = {:.3g} J, T = {:.6g} s{}'\n"
      "set xlabel 'x [m]'\nset ylabel 't [s]'\nset zlabel 'u [m]' rotate parallel\n"
      "set pm3d depthorder\nset palette rgbformulae 33,13,10\nset view 55,35\n"
      "set key top left\nset ticslevel 0\n"
      "splot {} using 'x':'t':'u' with pm3d title 'u(x,t)'{}\n",
      name == "mode1" ? "Mode 1" : "Mode 2", orbit.energy, orbit.period, title_extra,
      backbone::core::gnuplot_quote(out / (name + "_spacetime.csv")), marker);
  const fs::path png = out / (name + "_spacetime.png");
  report(backbone::core::render_png(png, plot, {1100, 800}), png);
}

// closed_form_summary.csv: the acceptance numbers of every branch in one table.
void closed_form_summary(const fs::path& out) {
  std::vector<fs::path> dirs;
  for (const auto& entry : fs::directory_iterator(out))
    if (entry.is_directory() && fs::exists(entry.path() / "closed_form_check.csv") &&
        fs::exists(entry.path() / "branch.csv"))
      dirs.push_back(entry.path());
  std::sort(dirs.begin(), dirs.end());
  // The first column is a name, so the CSV is written as text (same atomic rule as Table).
  std::string csv =
      "branch,points,energy_first,energy_last,worst_relative_error,worst_return_error_u,"
      "worst_return_error_v,point_seconds\n";
  for (const fs::path& dir : dirs) {
    const Table check = Table::read_csv(dir / "closed_form_check.csv");
    const Table branch = Table::read_csv(dir / "branch.csv");
    const auto energy = check.column("energy");
    if (energy.empty()) continue;
    const auto worst = [&](const char* name) {
      const auto v = check.column(name);
      return *std::max_element(v.begin(), v.end());
    };
    double seconds = 0;
    for (double t : branch.column("seconds")) seconds += t;
    const std::string name = dir.filename().string();
    csv += fmt::format("{},{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}\n", name,
                       energy.size(), energy.front(), energy.back(), worst("relative_error"),
                       worst("return_error_u"), worst("return_error_v"), seconds);
    fmt::print(
        "[figures] {}: {} points, E {:.3g} .. {:.3g}, worst closed-form error {:.2e}, "
        "return error {:.2e}, {:.2f} s\n",
        name, energy.size(), energy.front(), energy.back(), worst("relative_error"),
        worst("return_error_u"), seconds);
  }
  if (dirs.empty()) return;
  backbone::core::write_text_atomically(out / "closed_form_summary.csv", csv);
}

int run_figures(const std::vector<std::string>& args) {
  po::options_description keys(
      "backbone figures [--out DIR] [--scene INI] [--mode1 DIR] [--mode2 DIR]");
  keys.add_options()("help", "describe the command")(
      "out", po::value<std::string>()->default_value("results"), "output folder")(
      "scene", po::value<std::string>()->default_value("problems/contact_bar/scenes/paper.ini"),
      "contact-bar scene the branches were traced with")(
      "mode1", po::value<std::string>(), "trace output of mode 1 (default OUT/mode1)")(
      "mode2", po::value<std::string>(), "trace output of mode 2 (default OUT/mode2)")(
      "energy", po::value<double>()->default_value(0.0),
      "energy of the orbits drawn [J] (0: middle of each branch)");
  po::variables_map vm;
  try {
    po::store(po::command_line_parser(args).options(keys).run(), vm);
    po::notify(vm);
  } catch (const po::error& e) {
    throw InputError("", e.what());
  }
  if (vm.count("help")) {
    fmt::print("{}", fmt::format("{}", [&] {
                 std::ostringstream s;
                 s << keys;
                 return s.str();
               }()));
    return 0;
  }
  const fs::path out = vm["out"].as<std::string>();
  const fs::path mode1 =
      vm.count("mode1") ? fs::path(vm["mode1"].as<std::string>()) : out / "mode1";
  const fs::path mode2 =
      vm.count("mode2") ? fs::path(vm["mode2"].as<std::string>()) : out / "mode2";
  const double energy = vm["energy"].as<double>();
  if (!std::isfinite(energy) || energy < 0)
    throw InputError("energy", fmt::format("must be >= 0 (got {})", energy));
  const backbone::core::Scene scene = backbone::core::read_scene(
      contact_bar::scene_keys(), vm["scene"].as<std::string>(), {}, po::options_description());
  const bar::BarSetup setup = contact_bar::setup_from_scene(scene);
  const double dt = scene.positive("dt");
  const int elements = static_cast<int>(scene.integer("elements", 1));
  if (!fs::exists(mode1 / "branch.csv") && !fs::exists(mode2 / "branch.csv")) {
    fmt::print(stderr, "[figures] no branch found in {} or {}: run backbone trace first\n",
               mode1.string(), mode2.string());
    return 1;
  }
  fs::create_directories(out);
  backbones_figure(out, setup, mode1, mode2);
  Orbit orbit;
  if (load_orbit(mode1, energy, setup.material.length, orbit)) {
    contact_figure(out, setup, orbit, dt);
    spacetime_figure(out, "mode1", setup, orbit, dt, elements, false);
  }
  if (load_orbit(mode2, energy, setup.material.length, orbit))
    spacetime_figure(out, "mode2", setup, orbit, dt, elements, true);
  closed_form_summary(out);
  return 0;
}

}  // namespace

static const bool registered = backbone::drivers::register_command(
    {"figures", "[--out DIR] [--scene INI]",
     "draw the contact-bar mode figures (backbones, contact history, space-time)", run_figures});
