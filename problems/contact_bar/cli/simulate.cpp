#include "problems/contact_bar/cli/simulate.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "continuation/outputs.hpp"
#include "core/errors.hpp"
#include "core/io/plot.hpp"
#include "problems/contact_bar/figures/modes.hpp"
#include "problems/contact_bar/solver/bar_solvers.hpp"
#include "problems/contact_bar/solver/scene.hpp"

namespace backbone::contact_bar {

namespace fs = std::filesystem;
using core::InputError;

namespace {
// At most about a minute and 150 MB of any solver (check_run_size says what is counted).
constexpr long default_max_steps = 100'000'000;
}  // namespace

po::options_description simulate_keys() {
  po::options_description keys = scene_keys();
  po::options_description run("simulate");
  run.add_options()("method", po::value<std::string>()->default_value("tdbem"),
                    "solver: tdbem | fem | exact | all (= --compare)")(
      "periods", po::value<double>()->default_value(1.0),
      "simulated time in scene periods (t_end = periods * period) (> 0)")(
      "compare", po::bool_switch(), "run tdbem, fem and exact; one figure with the three")(
      "max_steps", po::value<long>()->default_value(default_max_steps),
      "refuse a run larger than this many time steps (>= 1): t_end / dt (tdbem, fem), max(rows, "
      "100) "
      "x min(L/c, t_end) / dt (the tdbem window, integrated per row), node-steps / 100 (fem), "
      "1000 x t_end / (L/c) (exact: stored wave transits)")(
      "orbit", po::value<std::string>(),
      "DIR/orbits.csv:K: simulate point K of a traced branch (its u0, v0 = 0) over `periods` of "
      "its own period instead of the scene's u0, v0 and period (the scene gives the same bar)");
  keys.add(run);
  return keys;
}

namespace {

std::string plot_script(const std::vector<std::pair<std::string, fs::path>>& curves,
                        const std::string& scene_name) {
  std::string s;
  s += "set datafile separator ','\nset key top right\nset grid\n";
  s += "set multiplot layout 2,1 title " + core::gnuplot_quote(scene_name) + " noenhanced\n";
  s += "set xlabel 't [s]'\nset ylabel 'contact-end displacement u [m]'\nplot ";
  for (std::size_t i = 0; i < curves.size(); ++i)
    s += (i ? ", " : "") + core::gnuplot_quote(curves[i].second) +
         " using 1:2 with lines lw 1.5 title " + core::gnuplot_quote(curves[i].first);
  s += "\nset xlabel 't [s]'\nset ylabel 'contact force {/Symbol l} [N]'\nplot ";
  for (std::size_t i = 0; i < curves.size(); ++i)
    s += (i ? ", " : "") + core::gnuplot_quote(curves[i].second) +
         " using 1:3 with lines lw 1.5 title " + core::gnuplot_quote(curves[i].first);
  s += "\nunset multiplot\n";
  return s;
}

// Empty when the history reaches t_end with finite values, else what is wrong with it.
std::string history_defect(const bar::History& h, double t_end) {
  for (const auto* column : {&h.u_contact, &h.contact_force, &h.energy})
    for (std::size_t i = 0; i < column->size(); ++i)
      if (!std::isfinite((*column)[i]))
        return fmt::format("non-finite values at t = {}", i < h.t.size() ? h.t[i] : 0.0);
  if (h.t.empty()) return "no rows";
  if (!(h.t.back() >= t_end * (1 - 1e-12)))
    return fmt::format("the history stops at t = {} before t_end = {} (the march failed there)",
                       h.t.back(), t_end);
  return "";
}

// The run's size against max_steps, before anything runs. Counted: the march length t_end / dt
// (TD-BEM, FEM); the TD-BEM's window of w = min(L / c, t_end) / dt steps (one knot per end),
// held in memory and integrated for the energy of each of the R rows: max(R, 100) w; the FEM's
// node-steps (t_end / dt) (elements + 1) / 100; the exact solution's stored wave transits
// (~0.5 kB each), 1000 t_end / (L / c). The weights give each count about the cost of one
// TD-BEM step, so the default 1e8 keeps any solver to about a minute and 150 MB.
void check_run_size(const core::Scene& scene, const bar::BarSetup& setup,
                    const bar::SimulationOptions& o, const std::vector<std::string>& methods) {
  const long max_steps = scene.integer("max_steps", 1, std::numeric_limits<long>::max());
  const double limit = static_cast<double>(max_steps);
  const std::string raise = fmt::format("or raise max_steps (now {})", max_steps);
  const double steps = o.t_end / o.dt;
  const auto uses = [&](const char* m) {
    return std::find(methods.begin(), methods.end(), m) != methods.end();
  };
  if ((uses("tdbem") || uses("fem")) && steps > limit)
    throw InputError("dt", fmt::format("t_end / dt = {:.4g} s / {} s = {:.4g} time steps (t_end = "
                                       "periods * period); use a larger dt or fewer periods, {}",
                                       o.t_end, o.dt, steps, raise));
  const double rows = std::min(static_cast<double>(o.history_samples), steps + 1);
  const double tau = setup.material.travel_time();
  if (uses("tdbem")) {
    const double window = std::min(tau, o.t_end) / o.dt;
    if (std::max(rows, 100.0) * window > limit)
      throw InputError("dt", fmt::format("the TD-BEM keeps min(L / c, t_end) / dt = {:.4g} steps "
                                         "per end and integrates them for each of {:.0f} history "
                                         "rows (work max(rows, 100) x {:.4g} > max_steps); use a "
                                         "larger dt or fewer history_samples, {}",
                                         window, rows, window, raise));
  }
  // The history every solver writes: rows x (time, the ends' and every probe's u and v), held in
  // memory and written as history.csv; a tenth of max_steps values at most (8 bytes each).
  const double columns = 1 + 2 * (2 + static_cast<double>(o.probes.size()));
  const double values = rows * columns * static_cast<double>(methods.size());
  if (values > limit / 10)
    throw InputError(o.probes.size() > 2 ? "probes" : "history_samples",
                     fmt::format("the history holds {:.0f} rows x {:.0f} columns x {} solvers = "
                                 "{:.4g} values (> max_steps / 10); use fewer probes or "
                                 "history_samples, {}",
                                 rows, columns, methods.size(), values, raise));
  if (uses("fem") && steps * (o.elements + 1.0) > 100 * limit)
    throw InputError("elements", fmt::format("the FEM does {:.4g} steps on {} nodes (node-steps / "
                                             "100 > max_steps); use fewer elements or periods, {}",
                                             steps, o.elements + 1, raise));
  if (uses("exact") && 1000 * (o.t_end / tau) > limit)
    throw InputError("periods", fmt::format("the exact solution stores t_end / (L / c) = {:.4g} "
                                            "wave transits (~0.5 kB each; 1000 x transits > "
                                            "max_steps); use fewer periods, {}",
                                            o.t_end / tau, raise));
}

}  // namespace

int simulate_scene(const core::Scene& scene, const fs::path& out) {
  // Validate everything before anything runs or is written.
  bar::BarSetup setup = setup_from_scene(scene);
  const double periods = scene.positive("periods");
  bar::SimulationOptions options = simulation_from_scene(scene, periods);
  double period = scene.positive("period");
  if (scene.has("orbit")) {
    // A traced orbit: its own u0 (orbits.csv holds it at its actual knots), v0 = 0, its period.
    const auto [dir, point] = continuation::parse_saved_point(scene.text("orbit"), "orbit");
    const auto orbit = [&] {
      try {
        return load_traced_orbit_point(dir, point, 0, setup.material.length);
      } catch (const InputError& e) {
        throw InputError("orbit", fmt::format("'{}': {}", (dir / "orbits.csv").string(), e.what()));
      }
    }();
    if (!orbit)
      throw core::InputError("orbit", fmt::format("'{}' has no traced orbit {} (branch.csv and "
                                                  "orbits.csv of a trace)",
                                                  dir.string(), point));
    setup.u0 = orbit->u0;
    setup.v0 = bar::PiecewiseLinear::zero(setup.material.length);
    setup.validate();
    period = orbit->period;
    options.t_end = periods * period;
    fmt::print("orbit {} of {}: period {:.12g} s, energy {:.6g} J\n", point, dir.string(), period,
               orbit->energy);
  }
  const ContactMethod contact = contact_method_from_scene(scene);
  const std::string method = scene.choice("method", {"tdbem", "fem", "exact", "all"});
  const bool compare = scene.flag("compare") || method == "all";
  const std::vector<std::string> methods =
      compare ? bar_solver_names() : std::vector<std::string>{method};
  if (methods.size() > 1) {  // the TD-BEM constraint on dt, checked up front
    TdbemMarch check(setup, options.dt, contact);
  }
  check_run_size(scene, setup, options, methods);

  std::vector<std::pair<std::string, bar::History>> histories;
  for (const auto& name : methods) {
    auto solver = make_bar_solver(name, contact);
    bar::History h = solver->simulate(setup, options);  // InputError: nothing written yet
    if (const std::string defect = history_defect(h, options.t_end); !defect.empty()) {
      fmt::print(stderr, "backbone simulate: {} failed: {}\n", name, defect);
      return core::exit_numerical_failure;
    }
    histories.emplace_back(name, std::move(h));
  }

  fs::create_directories(out);
  std::vector<std::pair<std::string, fs::path>> curves;
  for (const auto& [name, h] : histories) {
    const fs::path csv = out / (compare ? "history_" + name + ".csv" : "history.csv");
    h.to_table().write_csv(csv);
    std::string label = name;
    if (name == "tdbem") label += fmt::format(" ({})", to_string(contact));
    curves.emplace_back(label, csv);
  }
  const std::string title =
      fmt::format("{}: {} period(s) of {} s, dt = {} s", fs::path(scene.path()).stem().string(),
                  periods, period, options.dt);
  const core::PlotResult plot =
      core::render_png(out / "history.png", plot_script(curves, title), {1000, 800});
  if (!plot.ok) fmt::print(stderr, "backbone simulate: figure skipped: {}\n", plot.message);
  for (const auto& [name, h] : histories)
    fmt::print("{}: {} rows to t = {} s, final u_contact = {:.6g} m{}\n", name, h.t.size(),
               h.t.back(), h.u_contact.back(),
               h.energy.empty()
                   ? ""
                   : fmt::format(", energy {:.6g} -> {:.6g} J", h.energy.front(), h.energy.back()));
  return core::exit_ok;
}

}  // namespace backbone::contact_bar
