// `backbone simulate SCENE [--method tdbem|fem|exact|all] [--out DIR] [--periods P] [--compare]
// [--key value ...]`: time simulation of a contact-bar scene. Writes DIR/history.csv
// (t,u_contact,contact_force,energy[,u_probe...]) and DIR/history.png; with --compare (or
// --method all) runs tdbem, fem and exact, writes DIR/history_<method>.csv each and one PNG with
// the three curves. Everything is validated and every solver has run before DIR is created: bad
// input writes nothing (exit 2), a numerical failure writes nothing (exit 1).
#include <fmt/format.h>

#include <boost/program_options.hpp>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "core/errors.hpp"
#include "core/plot.hpp"
#include "core/scene.hpp"
#include "drivers/bar_solvers.hpp"
#include "drivers/commands.hpp"
#include "problems/contact_bar/scene.hpp"

namespace backbone::drivers {
namespace {

namespace po = boost::program_options;
namespace fs = std::filesystem;

const char* const usage =
    "SCENE [--method tdbem|fem|exact|all] [--out DIR] [--periods P] [--compare] [--key value ...]";

po::options_description driver_keys() {
  po::options_description keys("simulate options");
  keys.add_options()("method", po::value<std::string>()->default_value("tdbem"),
                     "solver: tdbem | fem | exact | all (= --compare)")(
      "out", po::value<std::string>()->default_value("simulate_out"), "output directory DIR")(
      "periods", po::value<double>()->default_value(1.0),
      "simulated time in scene periods (t_end = periods * period) (> 0)")(
      "compare", po::bool_switch(), "run tdbem, fem and exact; one figure with the three")(
      "help", po::bool_switch(), "print the keys and exit");
  return keys;
}

// "--gap -1" would read "-1" as an option: glue negative numbers to their key.
std::vector<std::string> glue_negative_values(const std::vector<std::string>& words) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < words.size(); ++i) {
    const std::string& w = words[i];
    if (w.rfind("--", 0) == 0 && w.find('=') == std::string::npos && i + 1 < words.size() &&
        words[i + 1].size() > 1 && words[i + 1][0] == '-' &&
        (std::isdigit(static_cast<unsigned char>(words[i + 1][1])) || words[i + 1][1] == '.')) {
      out.push_back(w + "=" + words[i + 1]);
      ++i;
    } else {
      out.push_back(w);
    }
  }
  return out;
}

void print_help() {
  std::ostringstream keys;
  keys << driver_keys() << "\n" << contact_bar::scene_keys();
  fmt::print("usage: backbone simulate {}\n\n{}", usage, keys.str());
}

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

int run_simulate(const std::vector<std::string>& args) {
  for (const auto& a : args)
    if (a == "--help" || a == "-h") {
      print_help();
      return core::exit_ok;
    }
  if (args.empty() || args[0].rfind("-", 0) == 0)
    throw core::InputError("scene", "the first argument must be the scene file (SCENE)");
  const std::string scene_path = args[0];
  const std::string problem = core::scene_problem_name(scene_path);  // unreadable -> InputError
  if (problem != "contact_bar")
    throw core::InputError("problem",
                           fmt::format("simulate runs contact_bar scenes (got '{}')", problem));
  const std::vector<std::string> overrides =
      glue_negative_values(std::vector<std::string>(args.begin() + 1, args.end()));
  const core::Scene scene =
      core::read_scene(contact_bar::scene_keys(), scene_path, overrides, driver_keys());

  // Validate everything before anything runs or is written.
  const bar::BarSetup setup = contact_bar::setup_from_scene(scene);
  const double periods = scene.positive("periods");
  const bar::SimulationOptions options = contact_bar::simulation_from_scene(scene, periods);
  const contact_bar::ContactMethod contact = contact_bar::contact_method_from_scene(scene);
  std::string method = scene.choice("method", {"tdbem", "fem", "exact", "all"});
  const bool compare = scene.flag("compare") || method == "all";
  const std::string out_text = scene.text("out");
  if (out_text.empty()) throw core::InputError("out", "must not be empty");
  const fs::path out(out_text);
  if (fs::exists(out) && !fs::is_directory(out))
    throw core::InputError("out", fmt::format("'{}' exists and is not a directory", out_text));
  std::vector<std::string> methods =
      compare ? bar_solver_names() : std::vector<std::string>{method};
  if (methods.size() > 1) {  // the TD-BEM constraint on dt, checked up front
    contact_bar::TdbemMarch check(setup, options.dt, contact);
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
    if (name == "tdbem") label += fmt::format(" ({})", contact_bar::to_string(contact));
    curves.emplace_back(label, csv);
  }
  const std::string title =
      fmt::format("{}: {} period(s) of {} s, dt = {} s", fs::path(scene_path).stem().string(),
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
  fmt::print("wrote {}\n", out.string());
  return core::exit_ok;
}

}  // namespace

static const bool registered =
    register_command({"simulate", usage,
                      "time simulation of a contact-bar scene (tdbem, fem, exact)", run_simulate});

}  // namespace backbone::drivers
