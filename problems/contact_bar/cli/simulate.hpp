// `backbone simulate` for contact-bar scenes: one time history per bar solver.
//
// simulate_keys are the bar's scene keys plus method (tdbem | fem | exact | all), periods and
// compare. simulate_scene validates everything and runs every solver before it creates `out`:
// bad input writes nothing (InputError, exit 2), a numerical failure writes nothing (exit 1).
// It writes out/history.csv (t,u_contact,contact_force,energy[,u_probe...]) and
// out/history.png; with compare (or method = all) one history_<method>.csv per solver and one
// figure with the three curves.
//
//   core::Scene scene = core::read_scene(contact_bar::simulate_keys(), "paper.ini", args, keys);
//   int code = contact_bar::simulate_scene(scene, "out/paper");   // 0, or 1 on failure
#pragma once

#include <boost/program_options.hpp>
#include <filesystem>

#include "core/io/scene.hpp"

namespace backbone::contact_bar {

boost::program_options::options_description simulate_keys();
int simulate_scene(const core::Scene& scene, const std::filesystem::path& out);

}  // namespace backbone::contact_bar
