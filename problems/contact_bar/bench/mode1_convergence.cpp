// Benchmark mode1_convergence (bench.hpp): errors on the exact mode 1 against dt.
#include <fmt/format.h>

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

struct Mode1Errors {
  double onset = nan, release = nan, force = nan, ret = nan;
};

// Onset/release from the first contact episode of the history (rows where the force is > 0):
// for a step method the instant is known to the step only.
void episode_from_history(const bar::History& h, const Mode1ContactEpisode& exact, Mode1Errors& e) {
  double onset = nan, release = nan;
  for (std::size_t j = 0; j < h.t.size(); ++j) {
    if (std::isnan(onset) && h.contact_force[j] > 0) onset = h.t[j];
    if (!std::isnan(onset) && std::isnan(release) && !(h.contact_force[j] > 0)) release = h.t[j];
  }
  e.onset = std::abs(onset - exact.onset);
  e.release = std::abs(release - exact.release);
}

// Force error against the exact step means of the contact episode.
double force_error(const bar::History& h, double dt, ForceWindow window,
                   const Mode1ContactEpisode& exact) {
  return relative_force_error(h, dt, window, [&](double t) { return exact.force_at(t); },
                              {exact.onset, exact.release});
}

Mode1Errors mode1_tdbem(ContactMethod method, double dt) {
  const bench::PaperMode1 mode1 = bench::paper_mode1();
  const Mode1ContactEpisode& exact = mode1.episode;
  Mode1Errors e;
  TdbemMarch march(mode1.setup, dt, method);
  if (!march.advance_to(exact.period)) return e;
  double onset = nan, release = nan;
  for (const auto& ev : march.events()) {
    if (!ev.right_end) continue;
    if (ev.closing && std::isnan(onset)) onset = ev.t;
    if (!ev.closing && !std::isnan(onset) && std::isnan(release)) release = ev.t;
  }
  e.onset = std::abs(onset - exact.onset);
  e.release = std::abs(release - exact.release);
  double ret = 0;
  for (int i = 0; i <= 100; ++i) {
    const double x = i / 100.0;
    ret = std::max(ret, std::abs(march.displacement(x) - mode1.eps * x));
  }
  e.ret = ret / std::abs(mode1.eps);
  bar::SimulationOptions o;
  o.t_end = exact.period;
  o.dt = dt;
  o.history_samples = static_cast<int>(std::ceil(o.t_end / dt)) + 2;
  o.energy = false;
  const bar::History h = TdbemSolver(method).simulate(mode1.setup, o);
  e.force = force_error(h, dt, tdbem_force_window, exact);
  return e;
}

Mode1Errors mode1_fem(double dt) {
  const bench::PaperMode1 mode1 = bench::paper_mode1();
  const Mode1ContactEpisode& exact = mode1.episode;
  const bar::BarSetup& setup = mode1.setup;
  const int elements = static_cast<int>(std::floor(1.0 / dt + 1e-9));  // Courant <= 1
  Mode1Errors e;
  bar::SimulationOptions o;
  o.t_end = exact.period;
  o.dt = dt;
  o.elements = elements;
  o.history_samples = static_cast<int>(std::ceil(o.t_end / dt)) + 2;
  o.energy = false;
  const fem_bar::FemBarSolver fem;
  const bar::History h = fem.simulate(setup, o);
  episode_from_history(h, exact, e);
  e.force = force_error(h, dt, fem_force_window, exact);
  bar::SnapshotRequest r;
  r.dt = dt;
  r.elements = elements;
  const bar::FieldSnapshot snap = fem.snapshot(setup, exact.period, r);
  double ret = 0;
  for (std::size_t i = 0; i < snap.x.size(); ++i)
    ret = std::max(ret, std::abs(snap.u[i] - mode1.eps * snap.x[i]));
  e.ret = snap.ok ? ret / std::abs(mode1.eps) : nan;
  return e;
}

}  // namespace

int bench_mode1_convergence(const std::filesystem::path& out) {
  fmt::print(
      "bench mode1_convergence: exact mode 1 (eps = -0.01, g0 = 1e-3, T = 3.1), errors "
      "vs dt\n");
  core::Table table({"contact", "dt", "onset_error", "release_error", "force_error", "return_error",
                     "order_onset", "order_release", "order_force", "order_return"});
  struct Series {
    std::string name;
    std::vector<double> dts;
    std::function<Mode1Errors(double)> run;
  };
  // The dt of the brief put onset (1.1) and release (2) on the time grid; the "_offgrid"
  // series use dt / sqrt(2) so that they fall inside steps (where projection is first order).
  const std::vector<double> on_grid{1e-2, 1e-3, 1e-4, 1e-5};
  std::vector<double> off_grid;
  for (double dt : on_grid) off_grid.push_back(dt / std::sqrt(2.0));
  const auto projection = [](double dt) { return mode1_tdbem(ContactMethod::projection, dt); };
  const auto event = [](double dt) { return mode1_tdbem(ContactMethod::event, dt); };
  // FEM at Courant <= 1 (elements = floor(L / (c dt))); 1e-5 would cost 1e5 nodes x 3e5 steps.
  const std::vector<Series> series{
      {"projection", on_grid, projection},
      {"event", on_grid, event},
      {"fem", {on_grid.begin(), on_grid.end() - 1}, [](double dt) { return mode1_fem(dt); }},
      {"projection_offgrid", off_grid, projection},
      {"event_offgrid", off_grid, event},
      {"fem_offgrid", {off_grid.begin(), off_grid.end() - 1}, [](double dt) {
         return mode1_fem(dt);
       }}};
  // Errors below this are round-off (they grow like the number of steps, ~1e-16 / dt): an order
  // between two of them says nothing about the method, so it is left NaN.
  constexpr double round_off = 1e-10;
  const auto order = [&](double h_coarse, double e_coarse, double h_fine, double e_fine) {
    return e_coarse < round_off || e_fine < round_off
               ? nan
               : observed_order(h_coarse, e_coarse, h_fine, e_fine);
  };
  for (const Series& s : series) {
    Mode1Errors previous;
    double previous_dt = nan;
    for (double dt : s.dts) {
      const Mode1Errors e = s.run(dt);
      table.add_row(s.name, {dt, e.onset, e.release, e.force, e.ret,
                             order(previous_dt, previous.onset, dt, e.onset),
                             order(previous_dt, previous.release, dt, e.release),
                             order(previous_dt, previous.force, dt, e.force),
                             order(previous_dt, previous.ret, dt, e.ret)});
      previous = e;
      previous_dt = dt;
    }
    fmt::print("  {} done\n", s.name);
  }
  const std::filesystem::path csv = bench::write_table(table, out, "mode1_convergence");
  fmt::print(
      "  onset/release: |t - 1.1|, |t - 2| (TD-BEM: its contact events; FEM: first row "
      "with force > 0 and the next with force 0); force_error: relative L1 error of "
      "step-averaged forces; return_error: max_x |u(x, 3.1) - eps x| / |eps|\n");

  const std::string q = core::gnuplot_quote(csv);
  std::string panels;
  for (const auto& [column, label] :
       {std::pair{3, "contact onset error [s]"}, std::pair{4, "release error [s]"},
        std::pair{5, "relative L1 force error"}, std::pair{6, "return-to-u0 error / |eps|"}}) {
    panels += fmt::format("set ylabel '{}'\nplot ", label);
    for (std::size_t k = 0; k < series.size(); ++k)
      panels += fmt::format(
          "{}{} using 2:(strcol(1) eq '{}' && ${} > 0 ? ${} : NaN) with "
          "linespoints pt {} title '{}'",
          k ? ", " : "", q, series[k].name, column, column, 5 + 2 * k, series[k].name);
    panels += ", x title 'order 1' dt 2 lc rgb 'gray'\n";
  }
  bench::plot(out / "mode1_convergence.png",
              "set multiplot layout 2,2 title 'Mode 1: errors vs dt (zero = "
              "round-off, not drawn)'\nset logscale xy\nset grid\nset format y '%.0e'\n"
              "set xlabel 'dt [s]'\nset key bottom right noenhanced\n" +
                  panels + "unset multiplot\n",
              {1400, 1000});
  return 0;
}

}  // namespace backbone::contact_bar
