#include "problems/contact_bar/simulate.hpp"

#include <fmt/format.h>

#include <cmath>

#include "core/errors.hpp"
#include "core/plot.hpp"
#include "problems/contact_bar/bar_solvers.hpp"
#include "problems/contact_bar/scene.hpp"

namespace backbone::contact_bar {

namespace fs = std::filesystem;

po::options_description simulate_keys() {
  po::options_description keys = scene_keys();
  po::options_description run("simulate");
  run.add_options()("method", po::value<std::string>()->default_value("tdbem"),
                    "solver: tdbem | fem | exact | all (= --compare)")(
      "periods", po::value<double>()->default_value(1.0),
      "simulated time in scene periods (t_end = periods * period) (> 0)")(
      "compare", po::bool_switch(), "run tdbem, fem and exact; one figure with the three");
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
         " skip 1 using 1:2 with lines lw 1.5 title " + core::gnuplot_quote(curves[i].first);
  s += "\nset xlabel 't [s]'\nset ylabel 'contact force {/Symbol l} [N]'\nplot ";
  for (std::size_t i = 0; i < curves.size(); ++i)
    s += (i ? ", " : "") + core::gnuplot_quote(curves[i].second) +
         " skip 1 using 1:3 with lines lw 1.5 title " + core::gnuplot_quote(curves[i].first);
  s += "\nunset multiplot\n";
  return s;
}

bool history_is_complete(const bar::History& h, double t_end) {
  if (h.t.empty() || !(h.t.back() >= t_end * (1 - 1e-12))) return false;
  for (const auto* column : {&h.u_contact, &h.contact_force, &h.energy})
    for (double v : *column)
      if (!std::isfinite(v)) return false;
  return true;
}

}  // namespace

int simulate_scene(const core::Scene& scene, const fs::path& out) {
  // Validate everything before anything runs or is written.
  const bar::BarSetup setup = setup_from_scene(scene);
  const double periods = scene.positive("periods");
  const bar::SimulationOptions options = simulation_from_scene(scene, periods);
  const ContactMethod contact = contact_method_from_scene(scene);
  const std::string method = scene.choice("method", {"tdbem", "fem", "exact", "all"});
  const bool compare = scene.flag("compare") || method == "all";
  const std::vector<std::string> methods =
      compare ? bar_solver_names() : std::vector<std::string>{method};
  if (methods.size() > 1) {  // the TD-BEM constraint on dt, checked up front
    TdbemMarch check(setup, options.dt, contact);
  }

  std::vector<std::pair<std::string, bar::History>> histories;
  for (const auto& name : methods) {
    auto solver = make_bar_solver(name, contact);
    bar::History h = solver->simulate(setup, options);  // InputError: nothing written yet
    if (!history_is_complete(h, options.t_end)) {
      fmt::print(stderr, "backbone simulate: {} failed (non-finite values) before t = {}\n", name,
                 options.t_end);
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
                  periods, scene.positive("period"), options.dt);
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
