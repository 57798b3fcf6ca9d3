// Scene keys of the contact bar and their translation into a bar::BarSetup and
// bar::SimulationOptions.
//
// Keys are flat (the same in an INI file and on the command line) and carry their unit in the
// description (`backbone simulate --help` prints them). Piecewise-linear initial fields are
// written as knots "x:value x:value ..." with x in [0, length] [m]; empty or absent = zero.
// Every violated constraint is an InputError naming the key.
//
//   namespace cb = backbone::contact_bar;
//   core::Scene scene = core::read_scene(cb::scene_keys(), "scenes/paper.ini", {}, driver_keys);
//   bar::BarSetup setup = cb::setup_from_scene(scene);            // validated
//   bar::SimulationOptions o = cb::simulation_from_scene(scene, 2);  // t_end = 2 periods
//   cb::ContactMethod m = cb::contact_method_from_scene(scene);
//   bar::PiecewiseLinear u0 = cb::parse_knots("u0", "0:0 1:-0.01", 1.0);
#pragma once

#include <boost/program_options.hpp>
#include <string>
#include <vector>

#include "core/io/scene.hpp"
#include "problems/bar/bar.hpp"
#include "problems/contact_bar/solver/tdbem.hpp"

namespace backbone::contact_bar {

namespace po = boost::program_options;

po::options_description scene_keys();

bar::BarSetup setup_from_scene(const core::Scene& scene);
// The bar alone (material, ends, gap, body force), u0 = v0 = 0: for problems that choose their
// own initial fields (the orbit problem of `trace`), so that the scene's u0/v0 knots, written
// for its own length, do not have to be rewritten when --length changes.
bar::BarSetup bar_from_scene(const core::Scene& scene);
// t_end = periods * period; dt, elements, history_samples, probes from the scene.
bar::SimulationOptions simulation_from_scene(const core::Scene& scene, double periods = 1);
ContactMethod contact_method_from_scene(const core::Scene& scene);

// "x:value x:value ..." -> PiecewiseLinear (empty -> zero on [0, length]).
bar::PiecewiseLinear parse_knots(const std::string& key, const std::string& text, double length);
// "0.25 0.5" or "0.25,0.5" -> {0.25, 0.5}; every entry finite.
std::vector<double> parse_numbers(const std::string& key, const std::string& text);

}  // namespace backbone::contact_bar
