// `backbone inspect`: the dimension of the solution set at one saved point of a traced branch,
// with its evidence (continuation/dimension_evidence.hpp), for the problem of any plugin.
//
//   const cli::ProblemPlugin& plugin = ...;   // the plugin of the scene's `problem`
//   return cli::inspect_command(plugin, {"DIR/scene.ini", "--orbit", "DIR/orbits.csv:7"});
#pragma once

#include <string>
#include <vector>

#include "continuation/cli/plugin.hpp"

namespace backbone::cli {

// `backbone inspect SCENE --orbit DIR/orbits.csv:K [--branch NAME] [--key value ...]` for the
// plugin of SCENE: builds the problem with plugin.setup (the branch of DIR/summary.txt unless
// --branch), reads point K of DIR/unknowns.csv, prints the evidence. The scene must give the
// trace's grid keys (DIR/scene.ini does). Returns the exit code; InputError for bad input.
int inspect_command(const ProblemPlugin& plugin, const std::vector<std::string>& args);

}  // namespace backbone::cli
