// Benchmark bouncing_bar (bench.hpp): TD-BEM and FEM against the closed-form bouncing bar.
#include "problems/exact_bar/bouncing_bar.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "core/io/plot.hpp"
#include "core/io/table.hpp"
#include "problems/contact_bar/bench/cases.hpp"
#include "problems/contact_bar/bench/metrics.hpp"
#include "problems/contact_bar/bench/support.hpp"
#include "problems/contact_bar/solver/tdbem.hpp"
#include "problems/fem_bar/fem.hpp"

namespace backbone::contact_bar {

namespace {

const double nan = std::numeric_limits<double>::quiet_NaN();

struct MethodRun {
  std::string name;
  std::function<bar::History(const bar::SimulationOptions&)> simulate;
  ForceWindow window;
  double courant = 1;  // dt = courant * dx / c
};

// The closed-form bouncing bar over 10 periods and the scales its errors are measured in.
struct BouncingBar {
  bar::BarSetup setup = exact_bar::bouncing_bar_setup();
  double t_end = 10 * exact_bar::bouncing_bar_period();
  double L = setup.material.length, c = setup.material.wave_speed();
  // Energy scale: the potential energy released by the fall, |b| A L h0 (= 500 J).
  double energy_scale = std::abs(setup.body_force) * setup.material.area * L * setup.right.gap;
  std::vector<double> breaks = bouncing_bar_force_jumps(t_end);
};

// The methods compared: TD-BEM (projection, event) and FEM at Courant 1 and 0.9.
struct BouncingSolvers {
  TdbemSolver projection{ContactMethod::projection};
  TdbemSolver event{ContactMethod::event};
  fem_bar::FemBarSolver fem;
  std::vector<MethodRun> methods(const bar::BarSetup& setup) const {
    return {
        {"tdbem_projection", [&](const auto& o) { return projection.simulate(setup, o); },
         tdbem_force_window, 1},
        {"tdbem_event", [&](const auto& o) { return event.simulate(setup, o); }, tdbem_force_window,
         1},
        {"fem", [&](const auto& o) { return fem.simulate(setup, o); }, fem_force_window, 1},
        {"fem_c0.9", [&](const auto& o) { return fem.simulate(setup, o); }, fem_force_window, 0.9}};
  }
};

// One method on one grid: {elements, dt, max_u_error, force_error, energy_drift, seconds,
// max_u_error_period1}, the row of bouncing_bar.csv after its method.
std::vector<double> measure(const MethodRun& m, int elements, const BouncingBar& b) {
  bar::SimulationOptions o;
  o.t_end = b.t_end;
  o.elements = elements;
  o.dt = m.courant * (b.L / elements) / b.c;
  // Timed run: every step recorded (errors), no energy (interior work).
  o.history_samples = static_cast<int>(std::ceil(b.t_end / o.dt)) + 2;
  o.energy = false;
  bar::History h;
  const double seconds = bench::best_seconds([&] { h = m.simulate(o); });
  double max_u_error = 0, max_u_error_period1 = 0;
  for (std::size_t j = 0; j < h.t.size(); ++j) {
    const double e =
        std::abs(h.u_contact[j] - exact_bar::bouncing_bar_contact_displacement(h.t[j]));
    max_u_error = std::max(max_u_error, e);
    if (h.t[j] <= exact_bar::bouncing_bar_period())
      max_u_error_period1 = std::max(max_u_error_period1, e);
  }
  if (h.t.empty() || h.t.back() < b.t_end - 1.01 * o.dt) max_u_error = nan;  // stopped early
  const auto exact_force = [](double t) { return exact_bar::bouncing_bar_contact_force(t); };
  const double force_error = relative_force_error(h, o.dt, m.window, exact_force, b.breaks);
  // Energy run: 4000 rows (the closed form conserves E exactly: E(t) = E(0) = 0).
  o.history_samples = 4000;
  o.energy = true;
  const bar::History he = m.simulate(o);
  double drift = 0;
  for (double e : he.energy) drift = std::max(drift, std::abs(e - he.energy.front()));
  return {double(elements),       o.dt,    max_u_error,        force_error,
          drift / b.energy_scale, seconds, max_u_error_period1};
}

// Work-precision: each error column against CPU seconds, one curve per method.
void plot_work_precision(const std::filesystem::path& csv, const std::filesystem::path& png,
                         const std::vector<MethodRun>& methods) {
  const std::string q = core::gnuplot_quote(csv);
  std::string panels;
  for (const auto& [column, label] : {std::pair{4, "max contact-end displacement error [m]"},
                                      std::pair{5, "relative L1 step-averaged force error"},
                                      std::pair{6, "energy drift / 500 J"}}) {
    panels += fmt::format("set ylabel '{}'\nplot ", label);
    for (std::size_t k = 0; k < methods.size(); ++k)
      panels += fmt::format(
          "{}{} using (strcol(1) eq '{}' ? $7 : NaN):{} with linespoints pt {} "
          "title '{}'",
          k ? ", " : "", q, methods[k].name, column, 5 + 2 * k, methods[k].name);
    panels += "\n";
  }
  bench::plot(png,
              "set multiplot layout 1,3 title 'Bouncing bar, 10 periods: "
              "work-precision (elements 25..1600)'\nset logscale xy\nset grid\nset format y "
              "'%.0e'\n"
              "set xlabel 'CPU seconds'\nset key bottom left noenhanced\n" +
                  panels + "unset multiplot\n",
              {1800, 600});
}

// History figure (paper Fig. 3): the first 2 periods on 50 elements (dt = 1/150) of the first
// three methods against the closed form.
void write_history_figure(const std::filesystem::path& out, const std::vector<MethodRun>& methods,
                          const BouncingBar& b) {
  const int elements = 50;
  bar::SimulationOptions o;
  o.t_end = 2 * exact_bar::bouncing_bar_period();
  o.elements = elements;
  o.dt = (b.L / elements) / b.c;
  o.history_samples = static_cast<int>(std::ceil(o.t_end / o.dt)) + 2;
  o.energy = false;
  std::vector<bar::History> runs;
  for (std::size_t k = 0; k < 3; ++k) runs.push_back(methods[k].simulate(o));
  core::Table hist({"t", "exact_u", "tdbem_projection_u", "tdbem_event_u", "fem_u", "exact_force",
                    "tdbem_projection_force", "tdbem_event_force", "fem_force"});
  const std::size_t rows = std::min({runs[0].t.size(), runs[1].t.size(), runs[2].t.size()});
  for (std::size_t j = 0; j < rows; ++j) {
    const double t = runs[0].t[j];
    hist.add_row({t, exact_bar::bouncing_bar_contact_displacement(t), runs[0].u_contact[j],
                  runs[1].u_contact[j], runs[2].u_contact[j],
                  exact_bar::bouncing_bar_contact_force(t), runs[0].contact_force[j],
                  runs[1].contact_force[j], runs[2].contact_force[j]});
  }
  const std::filesystem::path hcsv = out / "bouncing_bar_history.csv";
  hist.write_csv(hcsv);
  bench::plot(
      out / "bouncing_bar_history.png",
      fmt::format("set multiplot layout 2,1 title 'Bouncing bar, 50 elements, dt = dx/c = 1/150'\n"
                  "set grid\nset key noenhanced\nset xlabel 't [s]'\n"
                  "set ylabel 'u(L, t) [m]'\nset key bottom right\n"
                  "plot {0} using 1:2 with lines lw 3 lc rgb 'black' title 'exact', "
                  "{0} using 1:3 with lines lc rgb 'orange' title 'TD-BEM projection', "
                  "{0} using 1:4 with lines dt 2 lc rgb 'blue' title 'TD-BEM event', "
                  "{0} using 1:5 with lines dt 3 lc rgb 'red' title 'FEM (Courant 1)'\n"
                  "set ylabel 'contact force [N]'\nset key top right\n"
                  "plot {0} using 1:6 with lines lw 3 lc rgb 'black' title 'exact', "
                  "{0} using 1:7 with steps lc rgb 'orange' title 'TD-BEM projection', "
                  "{0} using 1:8 with steps dt 2 lc rgb 'blue' title 'TD-BEM event', "
                  "{0} using 1:9 with lines dt 3 lc rgb 'red' title 'FEM (Courant 1)'\n"
                  "unset multiplot\n",
                  core::gnuplot_quote(hcsv)),
      {1400, 900});
}

}  // namespace

int bench_bouncing_bar(const std::filesystem::path& out) {
  fmt::print(
      "bench bouncing_bar: 10 periods (t_end = 160/3), dt = Courant * dx / c, errors vs "
      "the closed form\n");
  const BouncingBar b;
  const BouncingSolvers solvers;
  const std::vector<MethodRun> methods = solvers.methods(b.setup);
  core::Table table({"method", "elements", "dt", "max_u_error", "force_error", "energy_drift",
                     "seconds", "max_u_error_period1"});
  for (const MethodRun& m : methods) {
    for (int elements : {25, 50, 100, 200, 400, 800, 1600})
      table.add_row(m.name, measure(m, elements, b));
    fmt::print("  {} done\n", m.name);
  }
  const std::filesystem::path csv = bench::write_table(table, out, "bouncing_bar");
  fmt::print(
      "  force_error: relative L1 error of step-averaged contact forces; energy_drift: "
      "max |E(t) - E(0)| / (|b| A L h0 = {:g} J)\n",
      b.energy_scale);
  plot_work_precision(csv, out / "bouncing_bar.png", methods);
  write_history_figure(out, methods, b);
  return 0;
}

}  // namespace backbone::contact_bar
