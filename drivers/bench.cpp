// `backbone bench`: benchmarks with known answers (DESIGN.md section 4), not tests. Each case
// writes a CSV table and a PNG into --out (default results/bench) and prints its table.
//
//   tdbem_scaling      TD-BEM CPU time vs number of steps (mode 1, 10 periods): the slope of
//                      log(time) vs log(steps) should be 1 (O(1) work per step).
//   bouncing_bar       TD-BEM (projection, event) and FEM (Courant 1 and 0.9) against the
//                      closed-form bouncing bar over 10 periods: end displacement, contact
//                      force, energy drift, CPU time; plus the history figure (paper Fig. 3).
//   mode1_convergence  TD-BEM errors on the exact mode 1 (onset, release, force, return to u0)
//                      vs dt, with observed orders, for each contact method (FEM for reference).
//   formulations       the paper's shooting residual u0 - u(T) vs the regular half-period
//                      velocity one (DESIGN.md section 3) on the same exact orbits of modes 1 and
//                      2 (4 amplitudes each): Newton from one perturbed start per orbit, at fixed
//                      energy (the natural parameter: [F; E - E*], so both aim at x* itself),
//                      iterations, observed orders, error to x*, exact-oracle return error and
//                      rank reports (forward/central differences, verified) at the final point.
//                      Residuals are reported in metres whatever unit the problem uses.
//
//   backbone bench                          # all four cases (a few minutes on one core)
//   backbone bench --case bouncing_bar --out /tmp/bench
#include <fmt/format.h>

#include <algorithm>
#include <boost/program_options.hpp>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "continuation/natural.hpp"
#include "core/errors.hpp"
#include "core/finite_difference.hpp"
#include "core/newton.hpp"
#include "core/periodic_orbit.hpp"
#include "core/plot.hpp"
#include "core/rank_report.hpp"
#include "core/table.hpp"
#include "drivers/commands.hpp"
#include "problems/bar/bar.hpp"
#include "problems/contact_bar/periodic_bar.hpp"
#include "problems/contact_bar/tdbem.hpp"
#include "problems/exact_bar/bouncing_bar.hpp"
#include "problems/exact_bar/exact_bar_solver.hpp"
#include "problems/fem_bar/fem.hpp"

namespace {

namespace po = boost::program_options;
namespace fs = std::filesystem;
using namespace backbone;

const double nan = std::numeric_limits<double>::quiet_NaN();

// A CSV whose first column may be text (method names); written atomically, echoed to stdout.
class TextTable {
 public:
  explicit TextTable(std::vector<std::string> columns) : columns_(std::move(columns)) {}
  void add_row(const std::string& label, const std::vector<double>& values) {
    std::vector<std::string> row{label};
    for (double v : values) row.push_back(fmt::format("{:.17g}", v));
    rows_.push_back(row);
  }
  void add_row(const std::vector<double>& values) {
    std::vector<std::string> row;
    for (double v : values) row.push_back(fmt::format("{:.17g}", v));
    rows_.push_back(row);
  }
  // Cells in column order, text or number(...).
  void add_cells(std::vector<std::string> cells) { rows_.push_back(std::move(cells)); }
  static std::string number(double v) { return fmt::format("{:.17g}", v); }
  std::string csv() const {
    std::string text = join(columns_) + "\n";
    for (const auto& r : rows_) text += join(r) + "\n";
    return text;
  }
  // Compact screen rendering (6 significant digits).
  void print() const {
    std::vector<std::size_t> width(columns_.size());
    auto cell = [](const std::string& s) {
      char* end = nullptr;
      const double v = std::strtod(s.c_str(), &end);
      return end && *end == '\0' && !s.empty() ? fmt::format("{:.6g}", v) : s;
    };
    for (std::size_t c = 0; c < columns_.size(); ++c) width[c] = columns_[c].size();
    for (const auto& r : rows_)
      for (std::size_t c = 0; c < r.size(); ++c) width[c] = std::max(width[c], cell(r[c]).size());
    auto line = [&](const std::vector<std::string>& r, bool header) {
      std::string s;
      for (std::size_t c = 0; c < r.size(); ++c)
        s += fmt::format("{:>{}}  ", header ? r[c] : cell(r[c]), width[c]);
      fmt::print("  {}\n", s);
    };
    line(columns_, true);
    for (const auto& r : rows_) line(r, false);
  }
  void write(const fs::path& path) const { core::write_text_atomically(path, csv()); }

 private:
  static std::string join(const std::vector<std::string>& v) {
    std::string s;
    for (std::size_t i = 0; i < v.size(); ++i) s += (i ? "," : "") + v[i];
    return s;
  }
  std::vector<std::string> columns_;
  std::vector<std::vector<std::string>> rows_;
};

double seconds_of(const std::function<void()>& run) {
  const auto start = std::chrono::steady_clock::now();
  run();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Best of up to 3 runs; runs longer than `single` seconds are not repeated.
double best_seconds(const std::function<void()>& run, double single = 0.5) {
  double best = seconds_of(run);
  for (int k = 1; k < 3 && best < single; ++k) best = std::min(best, seconds_of(run));
  return best;
}

void report_plot(const core::PlotResult& r, const fs::path& png) {
  if (r.ok)
    fmt::print("  wrote {}\n", png.string());
  else
    fmt::print("  figure skipped: {}\n", r.message);
}

// Least-squares slope of log(y) vs log(x).
double log_log_slope(const std::vector<double>& x, const std::vector<double>& y) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = static_cast<double>(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double a = std::log(x[i]), b = std::log(y[i]);
    sx += a, sy += b, sxx += a * a, sxy += a * b;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

// Observed order between two (dt, error) pairs; NaN when either error is at round-off (0).
double order(double dt_coarse, double e_coarse, double dt_fine, double e_fine) {
  if (!(e_coarse > 0) || !(e_fine > 0)) return nan;
  return std::log(e_coarse / e_fine) / std::log(dt_coarse / dt_fine);
}

// Contact forces are impulsive at the step scale, so they are compared as step averages: each
// method's sample is the mean force over the interval its scheme attributes it to (TD-BEM:
// piecewise-constant traction over [t_n - dt, t_n]; FEM: the multiplier's impulse lambda_n dt
// acts between t_n - dt/2 and t_n + dt/2), against the exact mean over the same interval.
// Error = sum |F_num - F_exact_mean| / sum |F_exact_mean| (relative L1 norm over the run).
struct ForceWindow {
  double before = 1, after = 0;  // interval [t - before dt, t + after dt]
};
const ForceWindow tdbem_window{1, 0};
const ForceWindow fem_window{0.5, 0.5};

// Mean of f over [a, b], f piecewise smooth with jumps at `breaks`: Simpson on each piece.
double mean_over(const std::function<double(double)>& f, double a, double b,
                 const std::vector<double>& breaks) {
  a = std::max(a, 0.0);
  if (!(b > a)) return f(std::max(b, 0.0));
  std::vector<double> cuts{a};
  for (double t : breaks)
    if (t > a && t < b) cuts.push_back(t);
  cuts.push_back(b);
  double integral = 0;
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    const double l = cuts[i], r = cuts[i + 1], w = r - l, e = 1e-12 * w;
    // One-sided values at the cut points (the force jumps there).
    integral += w / 6 * (f(l + e) + 4 * f(0.5 * (l + r)) + f(r - e));
  }
  return integral / (b - a);
}

double relative_force_error(const bar::History& h, double dt, ForceWindow window,
                            const std::function<double(double)>& exact,
                            const std::vector<double>& breaks) {
  double num = 0, den = 0;
  for (std::size_t j = 0; j < h.t.size(); ++j) {
    const double t = h.t[j];
    const double mean = mean_over(exact, t - window.before * dt, t + window.after * dt, breaks);
    num += std::abs(h.contact_force[j] - mean);
    den += std::abs(mean);
  }
  return num / den;
}

// ---------------------------------------------------------------------------------------------
// Mode 1 of DESIGN.md section 1: u0 = eps x, eps = -0.01, g0 = 1e-3, L = c = EA = 1.
const double mode1_eps = -0.01, mode1_gap = 1e-3, mode1_period = 3.1, mode1_onset = 1.1,
             mode1_release = 2.0, mode1_force = 0.01;

bar::BarSetup mode1_setup() {
  bar::BarSetup s;
  s.left = {bar::EndType::fixed, 0};
  s.right = {bar::EndType::contact, mode1_gap};
  s.u0 = bar::PiecewiseLinear({0.0, 1.0}, {0.0, mode1_eps});
  return s;
}

double mode1_exact_force(double t) {
  return t >= mode1_onset && t < mode1_release ? mode1_force : 0.0;
}

// ---------------------------------------------------------------------------------------------
int case_tdbem_scaling(const fs::path& out) {
  fmt::print(
      "bench tdbem_scaling: TD-BEM (event contact) on mode 1 over 10 periods, "
      "history_samples = 2, energy off\n");
  const bar::BarSetup setup = mode1_setup();
  const contact_bar::TdbemSolver tdbem(contact_bar::ContactMethod::event);
  const double t_end = 10 * mode1_period;
  core::Table table({"steps", "seconds", "seconds_per_step"});
  std::vector<double> steps, seconds;
  for (double n : {1e3, 1e4, 1e5, 1e6}) {
    bar::SimulationOptions o;
    o.t_end = t_end;
    o.dt = t_end / n;
    o.history_samples = 2;
    o.energy = false;
    bool ok = true;
    const double s = best_seconds([&] { ok = ok && tdbem.simulate(setup, o).t.size() == 2; },
                                  n >= 1e6 ? 0.0 : 1e9);
    if (!ok) fmt::print("  warning: march stopped early at n = {:g}\n", n);
    steps.push_back(n);
    seconds.push_back(s);
    table.add_row({n, s, s / n});
  }
  const double slope = log_log_slope(steps, seconds);
  const fs::path csv = out / "tdbem_scaling.csv";
  table.write_csv(csv);
  core::Table fit({"slope"});
  fit.add_row({slope});
  fit.write_csv(out / "tdbem_scaling_fit.csv");
  TextTable screen(table.columns());
  for (std::size_t i = 0; i < table.rows(); ++i) screen.add_row(table.row(i));
  screen.print();
  fmt::print("  fitted slope of log(seconds) vs log(steps): {:.3f} (1 = linear cost)\n", slope);
  const fs::path png = out / "tdbem_scaling.png";
  report_plot(
      core::render_png(
          png, fmt::format("set logscale xy\nset grid\nset xlabel 'time steps n'\n"
                           "set ylabel 'CPU seconds'\nset title 'TD-BEM march cost, fitted "
                           "slope {:.3f}'\nset key left top\n"
                           "plot {} using 1:2 with linespoints pt 7 title 'TD-BEM (event)', "
                           "{:.6g}*x title 'linear (through n = 1e6)' dt 2\n",
                           slope, core::gnuplot_quote(csv), seconds.back() / steps.back())),
      png);
  return 0;
}

// ---------------------------------------------------------------------------------------------
struct MethodRun {
  std::string name;
  std::function<bar::History(const bar::SimulationOptions&)> simulate;
  ForceWindow window;
  double courant = 1;  // dt = courant * dx / c
};

int case_bouncing_bar(const fs::path& out) {
  fmt::print(
      "bench bouncing_bar: 10 periods (t_end = 160/3), dt = Courant * dx / c, errors vs "
      "the closed form\n");
  const bar::BarSetup setup = exact_bar::bouncing_bar_setup();
  const double t_end = 10 * exact_bar::bouncing_bar_period();
  const double L = setup.material.length, c = setup.material.wave_speed();
  const double tau = L / c;
  // Energy scale: the potential energy released by the fall, |b| A L h0 (= 500 J).
  const double energy_scale =
      std::abs(setup.body_force) * setup.material.area * L * setup.right.gap;
  // Force jumps of the closed form: impacts start at 3 tau + k 16 tau and 11 tau + k 16 tau and
  // last 2 tau each.
  std::vector<double> breaks;
  for (double start = 0; start < t_end + 16 * tau; start += 16 * tau)
    for (double s : {3.0, 5.0, 11.0, 13.0}) breaks.push_back(start + s * tau);
  const auto exact_force = [](double t) { return exact_bar::bouncing_bar_contact_force(t); };

  const contact_bar::TdbemSolver projection(contact_bar::ContactMethod::projection);
  const contact_bar::TdbemSolver event(contact_bar::ContactMethod::event);
  const fem_bar::FemBarSolver fem;
  const std::vector<MethodRun> methods{
      {"tdbem_projection", [&](const auto& o) { return projection.simulate(setup, o); },
       tdbem_window, 1},
      {"tdbem_event", [&](const auto& o) { return event.simulate(setup, o); }, tdbem_window, 1},
      {"fem", [&](const auto& o) { return fem.simulate(setup, o); }, fem_window, 1},
      {"fem_c0.9", [&](const auto& o) { return fem.simulate(setup, o); }, fem_window, 0.9}};

  TextTable table({"method", "elements", "dt", "max_u_error", "force_error", "energy_drift",
                   "seconds", "max_u_error_period1"});
  for (const MethodRun& m : methods) {
    for (int elements : {25, 50, 100, 200, 400, 800, 1600}) {
      bar::SimulationOptions o;
      o.t_end = t_end;
      o.elements = elements;
      o.dt = m.courant * (L / elements) / c;
      // Timed run: every step recorded (errors), no energy (interior work).
      o.history_samples = static_cast<int>(std::ceil(t_end / o.dt)) + 2;
      o.energy = false;
      bar::History h;
      const double seconds = best_seconds([&] { h = m.simulate(o); });
      double max_u_error = 0, max_u_error_period1 = 0;
      for (std::size_t j = 0; j < h.t.size(); ++j) {
        const double e =
            std::abs(h.u_contact[j] - exact_bar::bouncing_bar_contact_displacement(h.t[j]));
        max_u_error = std::max(max_u_error, e);
        if (h.t[j] <= exact_bar::bouncing_bar_period())
          max_u_error_period1 = std::max(max_u_error_period1, e);
      }
      if (h.t.empty() || h.t.back() < t_end - 1.01 * o.dt) max_u_error = nan;  // stopped early
      const double force_error = relative_force_error(h, o.dt, m.window, exact_force, breaks);
      // Energy run: 4000 rows (the closed form conserves E exactly: E(t) = E(0) = 0).
      o.history_samples = 4000;
      o.energy = true;
      const bar::History he = m.simulate(o);
      double drift = 0;
      for (double e : he.energy) drift = std::max(drift, std::abs(e - he.energy.front()));
      table.add_row(m.name, {static_cast<double>(elements), o.dt, max_u_error, force_error,
                             drift / energy_scale, seconds, max_u_error_period1});
    }
    fmt::print("  {} done\n", m.name);
  }
  const fs::path csv = out / "bouncing_bar.csv";
  table.write(csv);
  table.print();
  fmt::print(
      "  force_error: relative L1 error of step-averaged contact forces; energy_drift: "
      "max |E(t) - E(0)| / (|b| A L h0 = {:g} J)\n",
      energy_scale);

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
  const fs::path png = out / "bouncing_bar.png";
  report_plot(
      core::render_png(
          png,
          "set multiplot layout 1,3 title 'Bouncing bar, 10 periods: "
          "work-precision (elements 25..1600)'\nset logscale xy\nset grid\nset format y '%.0e'\n"
          "set xlabel 'CPU seconds'\nset key bottom left noenhanced\n" +
              panels + "unset multiplot\n",
          {1800, 600}),
      png);

  // History figure (paper Fig. 3): first 2 periods on 50 elements (dt = 1/150).
  {
    const int elements = 50;
    bar::SimulationOptions o;
    o.t_end = 2 * exact_bar::bouncing_bar_period();
    o.elements = elements;
    o.dt = (L / elements) / c;
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
    const fs::path hcsv = out / "bouncing_bar_history.csv";
    hist.write_csv(hcsv);
    const std::string hq = core::gnuplot_quote(hcsv);
    const fs::path hpng = out / "bouncing_bar_history.png";
    report_plot(
        core::render_png(
            hpng,
            fmt::format(
                "set multiplot layout 2,1 title 'Bouncing bar, 50 elements, dt = dx/c = 1/150'\n"
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
                hq),
            {1400, 900}),
        hpng);
  }
  return 0;
}

// ---------------------------------------------------------------------------------------------
struct Mode1Errors {
  double onset = nan, release = nan, force = nan, ret = nan;
};

// Onset/release from the first contact episode of the history (rows where the force is > 0):
// for a step method the instant is known to the step only.
void episode_from_history(const bar::History& h, Mode1Errors& e) {
  double onset = nan, release = nan;
  for (std::size_t j = 0; j < h.t.size(); ++j) {
    if (std::isnan(onset) && h.contact_force[j] > 0) onset = h.t[j];
    if (!std::isnan(onset) && std::isnan(release) && !(h.contact_force[j] > 0)) release = h.t[j];
  }
  e.onset = std::abs(onset - mode1_onset);
  e.release = std::abs(release - mode1_release);
}

Mode1Errors mode1_tdbem(contact_bar::ContactMethod method, double dt) {
  const bar::BarSetup setup = mode1_setup();
  Mode1Errors e;
  contact_bar::TdbemMarch march(setup, dt, method);
  if (!march.advance_to(mode1_period)) return e;
  double onset = nan, release = nan;
  for (const auto& ev : march.events()) {
    if (!ev.right_end) continue;
    if (ev.closing && std::isnan(onset)) onset = ev.t;
    if (!ev.closing && !std::isnan(onset) && std::isnan(release)) release = ev.t;
  }
  e.onset = std::abs(onset - mode1_onset);
  e.release = std::abs(release - mode1_release);
  double ret = 0;
  for (int i = 0; i <= 100; ++i) {
    const double x = i / 100.0;
    ret = std::max(ret, std::abs(march.displacement(x) - mode1_eps * x));
  }
  e.ret = ret / std::abs(mode1_eps);
  bar::SimulationOptions o;
  o.t_end = mode1_period;
  o.dt = dt;
  o.history_samples = static_cast<int>(std::ceil(o.t_end / dt)) + 2;
  o.energy = false;
  const bar::History h = contact_bar::TdbemSolver(method).simulate(setup, o);
  e.force =
      relative_force_error(h, dt, tdbem_window, mode1_exact_force, {mode1_onset, mode1_release});
  return e;
}

Mode1Errors mode1_fem(double dt) {
  const bar::BarSetup setup = mode1_setup();
  const int elements = static_cast<int>(std::floor(1.0 / dt + 1e-9));  // Courant <= 1
  Mode1Errors e;
  bar::SimulationOptions o;
  o.t_end = mode1_period;
  o.dt = dt;
  o.elements = elements;
  o.history_samples = static_cast<int>(std::ceil(o.t_end / dt)) + 2;
  o.energy = false;
  const fem_bar::FemBarSolver fem;
  const bar::History h = fem.simulate(setup, o);
  episode_from_history(h, e);
  e.force =
      relative_force_error(h, dt, fem_window, mode1_exact_force, {mode1_onset, mode1_release});
  bar::SnapshotRequest r;
  r.dt = dt;
  r.elements = elements;
  const bar::FieldSnapshot snap = fem.snapshot(setup, mode1_period, r);
  double ret = 0;
  for (std::size_t i = 0; i < snap.x.size(); ++i)
    ret = std::max(ret, std::abs(snap.u[i] - mode1_eps * snap.x[i]));
  e.ret = snap.ok ? ret / std::abs(mode1_eps) : nan;
  return e;
}

int case_mode1_convergence(const fs::path& out) {
  fmt::print(
      "bench mode1_convergence: exact mode 1 (eps = -0.01, g0 = 1e-3, T = 3.1), errors "
      "vs dt\n");
  TextTable table({"contact", "dt", "onset_error", "release_error", "force_error", "return_error",
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
  const auto projection = [](double dt) {
    return mode1_tdbem(contact_bar::ContactMethod::projection, dt);
  };
  const auto event = [](double dt) { return mode1_tdbem(contact_bar::ContactMethod::event, dt); };
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
  const fs::path csv = out / "mode1_convergence.csv";
  table.write(csv);
  table.print();
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
  const fs::path png = out / "mode1_convergence.png";
  report_plot(
      core::render_png(png,
                       "set multiplot layout 2,2 title 'Mode 1: errors vs dt (zero = "
                       "round-off, not drawn)'\nset logscale xy\nset grid\nset format y '%.0e'\n"
                       "set xlabel 'dt [s]'\nset key bottom right noenhanced\n" +
                           panels + "unset multiplot\n",
                       {1400, 1000}),
      png);
  return 0;
}

// ---------------------------------------------------------------------------------------------
// formulations: the paper's shooting residual f = u0 - u(T) against the regular half-period
// velocity residual (DESIGN.md section 3), on the same exact orbits of the contact family.

// End amplitudes (ratio * g0) along each branch, from grazing to E ~ 1e-2 J, the top of the
// traced range: mode 1 E = (ratio g0)^2 / 2 (5e-3 J at 100), mode 2 E = ((2 ratio + 1) g0)^2 / 2
// (9.9e-3 J at 70).
struct FormulationBranch {
  int mode;
  std::vector<double> ratios;
};
const std::vector<FormulationBranch> formulation_branches{{1, {1.05, 2, 10, 100}},
                                                          {2, {1.05, 2, 10, 70}}};
const std::vector<std::pair<std::string, core::ShootingFormulation>> formulation_names{
    {"regular", core::ShootingFormulation::half_period_velocity},
    {"paper", core::ShootingFormulation::displacement_periodicity}};
// The start of both formulations: x* plus start_u0_perturbation g0 sin(3 i) on u0 entry i
// (a fixed pattern, alternating from node to node) and start_period_perturbation relative on T;
// the knot stays. 1e-3 g0, not 1e-2: the pattern's strain, 2 * 1e-2 g0 / dx = 0.4 g0 / L, is
// 40% of the grazing strain g0 / L, and from there both formulations leave the family at
// A = 1.05 g0 (measured: u0 2% to 7% off x*, the paper's onto a T = 4L/c orbit without contact).
const double start_u0_perturbation = 1e-3, start_period_perturbation = 1e-3;
const double formulation_tolerance_metres = 1e-13;  // Newton: ||F||_inf in metres
const int formulation_max_iterations = 30;
// The trace's contact-bar settings (drivers/trace_contact_bar.cpp): residual sampled on 2x as
// many test functions as unknowns, rank threshold 1e-5 relative.
constexpr int formulation_oversampling = 2;
constexpr double formulation_rank_threshold = 1e-5;

// Metres per unit of the problem's residual, measured rather than assumed (the problem may
// scale its residual, e.g. by g0): the paper residual of the linear state u0 = -g0 x / (2L) at
// T = 2L/c is exactly 2 u0 / unit, because every fixed-free linear motion satisfies
// u(t + 2L/c) = -u(t) and an end amplitude g0/2 never reaches the wall.
double residual_unit(contact_bar::ContactBarOrbitProblem& problem, const core::Vector& like) {
  const core::ShootingFormulation kept = problem.formulation();
  problem.set_formulation(core::ShootingFormulation::displacement_periodicity);
  const bar::Material& material = problem.setup_template().material;
  const double gap = problem.setup_template().right.gap;
  core::Vector x = like;  // keeps the knot, if any
  const core::Vector y = problem.node_positions(x);
  const int n = problem.options().elements;
  for (int i = 0; i < n; ++i) x[i] = -0.5 * gap * y[i] / material.length;
  x[problem.period_index()] = 2 * material.travel_time();
  core::Vector r;
  const bool ok = problem.residual(x, r) == core::EvalStatus::ok;
  problem.set_formulation(kept);
  // The last residual entry samples x = L (u0(L) = x[n - 1]) whatever grid the residual uses.
  return ok && r.size() > 0 ? 2 * x[n - 1] / r[r.size() - 1] : nan;
}

// Observed convergence of a sequence e_0, e_1, ... (residuals or errors): order = median over
// k of log(e_{k+1} / e_k) / log(e_k / e_{k-1}) (2: quadratic, 1: linear); ratio = geometric
// mean of e_{k+1} / e_k (the linear rate). Only the leading values above `floor` (round-off)
// enter; NaN when too few do.
struct ObservedRate {
  double order = nan, ratio = nan;
};
ObservedRate observed_rate(const std::vector<double>& e, double floor) {
  std::size_t used = 0;  // e_0 .. e_{used - 1} are above the floor
  while (used < e.size() && e[used] > floor) ++used;
  ObservedRate rate;
  if (used >= 2) rate.ratio = std::pow(e[used - 1] / e[0], 1.0 / static_cast<double>(used - 1));
  std::vector<double> orders;
  for (std::size_t k = 1; k + 1 < used; ++k)
    orders.push_back(std::log(e[k + 1] / e[k]) / std::log(e[k] / e[k - 1]));
  if (!orders.empty()) {
    std::sort(orders.begin(), orders.end());
    const std::size_t h = orders.size() / 2;
    rate.order = orders.size() % 2 ? orders[h] : 0.5 * (orders[h - 1] + orders[h]);
  }
  return rate;
}

// max |u0(x) - u0*(x)| / max |u0*| between the piecewise-linear u0 of two points (exact: the
// difference is piecewise linear, so its maximum sits on a knot of either).
double relative_u0_distance(const contact_bar::ContactBarOrbitProblem& problem,
                            const core::Vector& x, const core::Vector& exact) {
  const bar::PiecewiseLinear a = problem.initial_displacement(x);
  const bar::PiecewiseLinear b = problem.initial_displacement(exact);
  double distance = 0, size = 0;
  for (const bar::PiecewiseLinear* f : {&a, &b})
    for (double k : f->knots()) distance = std::max(distance, std::abs(a(k) - b(k)));
  for (double v : b.values()) size = std::max(size, std::abs(v));
  return distance / size;
}

// Newton on [F; E - E*] (energy fixed: both formulations aim at x* itself), one iteration per
// solve() so that every iterate is measured. The eigen corrector keeps no state between calls
// and applies the same tests after each iteration, so the iterates are those of one solve().
struct NewtonTrace {
  core::NewtonStatus status = core::NewtonStatus::max_iterations;
  int iterations = 0;
  std::vector<double> shooting_residual;  // ||F||_inf [m] at the start and after each iteration
  std::vector<double> energy_error;       // |E - E*| [J]
  std::vector<double> u0_error;           // relative_u0_distance to x*
  double seconds = 0;
};

NewtonTrace trace_newton(const contact_bar::ContactBarOrbitProblem& problem,
                         const core::Vector& exact, double unit, core::Vector& x) {
  const double energy = problem.energy(exact);
  const continuation::ParameterConstraintSystem system(
      problem, continuation::NaturalParameter::of_observable("energy"), energy);
  core::NewtonOptions options;
  options.residual_tolerance = formulation_tolerance_metres / unit;  // problem's units
  options.max_iterations = 1;
  const auto newton = core::make_corrector("eigen", options);
  NewtonTrace trace;
  auto record = [&] {
    core::Vector r;
    trace.shooting_residual.push_back(
        problem.residual(x, r) == core::EvalStatus::ok ? unit * r.lpNorm<Eigen::Infinity>() : nan);
    trace.energy_error.push_back(std::abs(problem.energy(x) - energy));
    trace.u0_error.push_back(relative_u0_distance(problem, x, exact));
  };
  record();
  trace.seconds = seconds_of([&] {
    while (trace.iterations < formulation_max_iterations) {
      const core::NewtonSummary s = newton->solve(system, x);
      if (s.iterations == 0) {  // already converged at the start
        trace.status = s.status;
        return;
      }
      ++trace.iterations;
      record();
      if (s.status != core::NewtonStatus::max_iterations) {
        trace.status = s.status;
        return;
      }
    }
  });
  return trace;
}

// Rank report of the shooting Jacobian (2N equations, N + 1 unknowns) as the continuation makes
// it (continuation/point_recorder.cpp: the problem's forward-difference Jacobian, relative
// threshold 1e-8, candidate null directions verified by re-correction), and the same with an
// absolute floor at the measured uncertainty of that Jacobian, ||J_forward - J_central||_2
// (Weyl: singular values below it cannot be told from zero), and the central-difference
// Jacobian at the relative threshold (DESIGN.md section 3 and the tests count on it). At the
// paper's double root the period column is that uncertain: v(., T) jumps at T, so one-sided
// differences give -v(T+), central ones its mean, zero (rank_report.hpp on absolute_threshold).
struct RankColumns {
  core::RankReport relative, absolute, central;  // central: relative threshold, J_central
  double period_column_forward = nan, period_column_central = nan, uncertainty = nan;
  double sigma_min(int k) const {  // k-th smallest singular value, 1-based
    const Eigen::Index m = relative.singular_values.size();
    return m >= k ? relative.singular_values[m - k] : nan;
  }
  double central_sigma_min_relative() const {
    const Eigen::Index m = central.singular_values.size();
    return m > 0 ? central.singular_values[m - 1] / central.singular_values[0] : nan;
  }
};

RankColumns rank_columns(const core::PeriodicOrbitProblem& problem, const core::Vector& x) {
  RankColumns c;
  core::Matrix forward, central;
  core::FiniteDifferenceOptions central_differences;
  central_differences.scheme = core::FiniteDifferenceOptions::Scheme::central;
  if (problem.jacobian(x, forward) != core::EvalStatus::ok ||
      core::finite_difference_jacobian(problem, x, central, central_differences) !=
          core::EvalStatus::ok)
    return c;
  const int period = problem.period_index();
  c.period_column_forward = forward.col(period).lpNorm<Eigen::Infinity>();
  c.period_column_central = central.col(period).lpNorm<Eigen::Infinity>();
  c.uncertainty = Eigen::JacobiSVD<core::Matrix>(forward - central).singularValues()[0];
  // The continuation's verifier (continuation/point_recorder.cpp).
  core::NewtonOptions verifier_options;
  verifier_options.residual_tolerance = 0.1 * core::VerifyOptions{}.residual_tolerance;
  verifier_options.max_iterations = 60;
  const auto verifier = core::make_corrector("eigen", verifier_options);
  core::RankOptions absolute;
  absolute.absolute_threshold = c.uncertainty;
  core::RankOptions relative;
  relative.relative_threshold = formulation_rank_threshold;
  absolute.relative_threshold = formulation_rank_threshold;
  c.relative = core::rank_report(forward, relative);
  c.absolute = core::rank_report(forward, absolute);
  c.central = core::rank_report(central, relative);
  for (core::RankReport* report : {&c.relative, &c.absolute, &c.central})
    core::verify_null_directions(problem, x, *verifier, core::VerifyOptions{}, *report);
  return c;
}

int case_formulations(const fs::path& out) {
  const double gap = 1e-3;
  bar::BarSetup setup;  // paper scene: E = rho = L = A = 1 (c = 1)
  setup.left = {bar::EndType::fixed, 0};
  setup.right = {bar::EndType::contact, gap};
  const contact_bar::TdbemSolver tdbem(contact_bar::ContactMethod::event);
  const exact_bar::ExactBarSolver oracle;
  fmt::print(
      "bench formulations: regular (half-period velocity) vs paper (u0 - u(T)) shooting from "
      "the same perturbed exact orbits\n  TD-BEM event contact, 20 elements, 40 steps per "
      "period, residual on {}x as many test functions as unknowns (trace's default); Newton "
      "(eigen) on [F; E - E*], ||F||_inf <= {:g} m, {} iterations\n",
      formulation_oversampling, formulation_tolerance_metres, formulation_max_iterations);

  // Columns by group: the orbit and the start; the Newton run; where it ended; rank reports.
  std::vector<std::string> columns;
  for (const std::vector<std::string>& group :
       {std::vector<std::string>{"formulation", "status", "mode", "amplitude_ratio", "energy",
                                 "exact_residual", "exact_sigma_min_relative", "exact_nullity",
                                 "start_residual", "start_u0_error"},
        {"iterations", "final_residual", "energy_error", "residual_order", "residual_ratio"},
        {"u0_error", "error_order", "error_ratio", "period_error", "knot_error", "return_error_u",
         "return_error_v"},
        {"period_column_forward", "period_column_central", "jacobian_uncertainty"},
        {"sigma_min_1", "sigma_min_2", "sigma_min_3", "sigma_max", "threshold", "nullity",
         "verified"},
        {"threshold_absolute", "nullity_absolute", "verified_absolute"},
        {"central_sigma_min_relative", "nullity_central", "verified_central"},
        {"residual_unit", "seconds"}})
    columns.insert(columns.end(), group.begin(), group.end());
  TextTable table(columns);
  TextTable history({"mode", "amplitude_ratio", "formulation", "iteration", "residual",
                     "energy_error", "u0_error"});
  TextTable screen({"mode", "A/g0", "form", "status", "it", "|F| [m]", "order_F", "order_err",
                    "u0_err", "T_err", "return_err", "smin/smax", "null/ver", "abs", "central",
                    "x*: smin/smax"});
  const auto num = TextTable::number;
  const auto counts = [](const core::RankReport& r) {
    return fmt::format("{}/{}", r.nullity, r.verified_dimension);
  };

  for (const FormulationBranch& branch : formulation_branches) {
    contact_bar::OrbitOptions options;
    options.elements = 20;
    options.steps_per_period = 40;
    options.free_knots = branch.mode == 2 ? 1 : 0;  // mode 2: its crest is a free knot
    options.test_elements = formulation_oversampling * (options.elements + options.free_knots);
    contact_bar::ContactBarOrbitProblem problem(setup, tdbem, options);
    const int period = problem.period_index();
    for (double ratio : branch.ratios) {
      const core::Vector exact = problem.contact_family_guess(branch.mode, ratio);
      const double energy = problem.energy(exact);
      const double unit = residual_unit(problem, exact);
      core::Vector start = exact;
      for (int i = 0; i < options.elements; ++i)
        start[i] += start_u0_perturbation * gap * std::sin(3.0 * (i + 1));
      start[period] *= 1 + start_period_perturbation;
      double u_max = 0;
      for (int i = 0; i < options.elements; ++i) u_max = std::max(u_max, std::abs(exact[i]));
      // Round-off of a residual or error of size u_max after O(steps) operations.
      const double eps = std::numeric_limits<double>::epsilon();
      const double residual_floor = 100 * eps * u_max, error_floor = 100 * eps;

      for (const auto& [label, formulation] : formulation_names) {
        problem.set_formulation(formulation);
        core::Vector r;
        const double exact_residual = problem.residual(exact, r) == core::EvalStatus::ok
                                          ? unit * r.lpNorm<Eigen::Infinity>()
                                          : nan;
        // The Jacobian at x* itself (no verification): is the orbit sought a regular root?
        core::Matrix exact_jacobian;
        core::RankReport at_exact;
        if (problem.jacobian(exact, exact_jacobian) == core::EvalStatus::ok)
          at_exact = core::rank_report(
              exact_jacobian, core::RankOptions{.relative_threshold = formulation_rank_threshold});
        const Eigen::Index m = at_exact.singular_values.size();
        const double exact_sigma_min =
            m > 0 ? at_exact.singular_values[m - 1] / at_exact.singular_values[0] : nan;

        core::Vector x = start;
        const NewtonTrace trace = trace_newton(problem, exact, unit, x);
        const ObservedRate residual_rate = observed_rate(trace.shooting_residual, residual_floor);
        const ObservedRate error_rate = observed_rate(trace.u0_error, error_floor);
        const double final_energy = problem.energy(x);
        const double closed_form_frequency =
            branch.mode == 1 ? contact_bar::mode1_frequency(setup.material, gap, final_energy)
                             : contact_bar::mode2_frequency(setup.material, gap, final_energy);
        const double period_error =
            std::abs(x[period] * closed_form_frequency / (2 * std::numbers::pi) - 1);
        const double knot_error =
            options.free_knots == 1 ? std::abs(x[options.elements] - exact[options.elements]) : nan;
        const contact_bar::ReturnError returned = contact_bar::return_error(problem, x, oracle);
        const RankColumns rank = rank_columns(problem, x);
        const double sigma_max =
            rank.relative.singular_values.size() ? rank.relative.singular_values[0] : nan;
        const std::string status = core::to_string(trace.status);
        table.add_cells({label,
                         status,
                         num(branch.mode),
                         num(ratio),
                         num(energy),
                         num(exact_residual),
                         num(exact_sigma_min),
                         num(at_exact.nullity),
                         num(trace.shooting_residual.front()),
                         num(trace.u0_error.front()),
                         num(trace.iterations),
                         num(trace.shooting_residual.back()),
                         num(trace.energy_error.back()),
                         num(residual_rate.order),
                         num(residual_rate.ratio),
                         num(trace.u0_error.back()),
                         num(error_rate.order),
                         num(error_rate.ratio),
                         num(period_error),
                         num(knot_error),
                         num(returned.displacement),
                         num(returned.velocity),
                         num(rank.period_column_forward),
                         num(rank.period_column_central),
                         num(rank.uncertainty),
                         num(rank.sigma_min(1)),
                         num(rank.sigma_min(2)),
                         num(rank.sigma_min(3)),
                         num(sigma_max),
                         num(rank.relative.threshold),
                         num(rank.relative.nullity),
                         num(rank.relative.verified_dimension),
                         num(rank.absolute.threshold),
                         num(rank.absolute.nullity),
                         num(rank.absolute.verified_dimension),
                         num(rank.central_sigma_min_relative()),
                         num(rank.central.nullity),
                         num(rank.central.verified_dimension),
                         num(unit),
                         num(trace.seconds)});
        for (std::size_t k = 0; k < trace.shooting_residual.size(); ++k)
          history.add_cells({num(branch.mode), num(ratio), label, num(static_cast<double>(k)),
                             num(trace.shooting_residual[k]), num(trace.energy_error[k]),
                             num(trace.u0_error[k])});
        screen.add_cells({num(branch.mode), num(ratio), label, status, num(trace.iterations),
                          num(trace.shooting_residual.back()), num(residual_rate.order),
                          num(error_rate.order), num(trace.u0_error.back()), num(period_error),
                          num(returned.worst()), num(rank.sigma_min(1) / sigma_max),
                          counts(rank.relative), counts(rank.absolute), counts(rank.central),
                          num(exact_sigma_min)});
      }
    }
  }
  const fs::path csv = out / "formulations.csv";
  const fs::path hcsv = out / "formulations_history.csv";
  table.write(csv);
  history.write(hcsv);
  screen.print();
  fmt::print(
      "  |F|: final ||F||_inf; order_F, order_err: median observed order of the residual and of "
      "u0_err = max|u0 - u0*| / max|u0*| (2 quadratic, 1 linear);\n  T_err: |T / T_closed(E) - "
      "1|; return_err: exact-oracle return error (relative); smin/smax: smallest singular value "
      "of the forward-difference\n  shooting Jacobian at the final point; null/ver: nullity at "
      "relative 1e-5 / verified dimension; abs: absolute floor ||J_fwd - J_cen||_2; central: "
      "J_cen;\n  x*: smin/smax at the exact orbit\n");

  // Residual and u0 error vs iteration: one column per mode, colour per amplitude, dash per
  // formulation. The error is the comparable measure: the two residuals differ by definition.
  const std::string q = core::gnuplot_quote(hcsv);
  std::string panels;
  for (const auto& [column, label] : {std::pair{5, "shooting residual ||F||_{/Symbol \\245}  [m]"},
                                      std::pair{7, "u_0 error max|u_0 - u_0^*| / max|u_0^*|"}})
    for (const FormulationBranch& branch : formulation_branches) {
      panels += fmt::format("set title 'mode {}'\nset ylabel '{}'\nplot ", branch.mode, label);
      for (std::size_t k = 0; k < branch.ratios.size(); ++k)
        for (std::size_t f = 0; f < formulation_names.size(); ++f)
          panels += fmt::format(
              "{}{} using (($1 == {} && abs($2 - {:.17g}) < 1e-9 && strcol(3) eq '{}') ? $4 "
              ": NaN):(${} > 0 ? ${} : NaN) with linespoints lc {} dt {} pt {} title '{}, A = "
              "{:g} g_0'",
              k + f ? ", " : "", q, branch.mode, branch.ratios[k], formulation_names[f].first,
              column, column, k + 1, f + 1, f ? 6 : 7, formulation_names[f].first,
              branch.ratios[k]);
      if (column == 5)
        panels += fmt::format(", {:g} title 'tolerance' dt 2 lw 2 lc rgb 'black'",
                              formulation_tolerance_metres);
      panels += "\n";
    }
  const fs::path png = out / "formulations.png";
  report_plot(
      core::render_png(png,
                       fmt::format("set multiplot layout 2,2 title 'Newton from the same "
                                   "perturbed exact orbit at fixed energy: regular "
                                   "(solid) vs paper (dashed), g_0 = {:g} m'\nset "
                                   "logscale y\nset grid\nset format y '10^{{%L}}'\n"
                                   "set xlabel 'Newton iteration'\nset key outside right top "
                                   "font ',8'\n",
                                   gap) +
                           panels + "unset multiplot\n",
                       {1600, 1300}),
      png);
  return 0;
}

int run_bench(const std::vector<std::string>& args) {
  po::options_description keys("backbone bench");
  keys.add_options()(
      "case", po::value<std::string>(),
      "tdbem_scaling | bouncing_bar | mode1_convergence | formulations (default: all)")(
      "out", po::value<std::string>()->default_value("results/bench"), "output directory")(
      "help", "describe the command");
  po::variables_map vm;
  try {
    po::store(po::command_line_parser(args).options(keys).run(), vm);
    po::notify(vm);
  } catch (const po::error& e) {
    throw core::InputError("", e.what());
  }
  if (vm.count("help")) {
    std::ostringstream text;
    text << keys;
    fmt::print("usage: backbone bench [--case NAME] [--out DIR]\n{}", text.str());
    return 0;
  }
  const std::vector<std::pair<std::string, std::function<int(const fs::path&)>>> cases{
      {"tdbem_scaling", case_tdbem_scaling},
      {"bouncing_bar", case_bouncing_bar},
      {"mode1_convergence", case_mode1_convergence},
      {"formulations", case_formulations}};
  std::string selected = vm.count("case") ? vm["case"].as<std::string>() : "";
  if (!selected.empty() &&
      std::none_of(cases.begin(), cases.end(), [&](const auto& c) { return c.first == selected; }))
    throw core::InputError("case", fmt::format("must be one of tdbem_scaling, bouncing_bar, "
                                               "mode1_convergence, formulations (got '{}')",
                                               selected));
  const fs::path out = vm["out"].as<std::string>();
  int status = 0;
  for (const auto& [name, run] : cases) {
    if (!selected.empty() && name != selected) continue;
    const double seconds = seconds_of([&] { status = std::max(status, run(out)); });
    fmt::print("bench {}: {:.1f} s\n\n", name, seconds);
  }
  return status;
}

}  // namespace

static const bool registered = backbone::drivers::register_command(
    {"bench", "[--case tdbem_scaling|bouncing_bar|mode1_convergence|formulations] [--out DIR]",
     "benchmarks with known answers (CSV + PNG in results/bench)", run_bench});
