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
//
//   backbone bench                          # all three cases (a few minutes on one core)
//   backbone bench --case bouncing_bar --out /tmp/bench
#include <fmt/format.h>

#include <algorithm>
#include <boost/program_options.hpp>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "core/plot.hpp"
#include "core/table.hpp"
#include "drivers/commands.hpp"
#include "problems/bar/bar.hpp"
#include "problems/contact_bar/tdbem.hpp"
#include "problems/exact_bar/bouncing_bar.hpp"
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

int run_bench(const std::vector<std::string>& args) {
  po::options_description keys("backbone bench");
  keys.add_options()("case", po::value<std::string>(),
                     "tdbem_scaling | bouncing_bar | mode1_convergence (default: all)")(
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
      {"mode1_convergence", case_mode1_convergence}};
  std::string selected = vm.count("case") ? vm["case"].as<std::string>() : "";
  if (!selected.empty() &&
      std::none_of(cases.begin(), cases.end(), [&](const auto& c) { return c.first == selected; }))
    throw core::InputError("case", fmt::format("must be one of tdbem_scaling, bouncing_bar, "
                                               "mode1_convergence (got '{}')",
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
    {"bench", "[--case tdbem_scaling|bouncing_bar|mode1_convergence] [--out DIR]",
     "benchmarks with known answers (CSV + PNG in results/bench)", run_bench});
