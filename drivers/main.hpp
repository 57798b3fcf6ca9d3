// The entry point of a backbone-style CLI: `backbone COMMAND [arguments]` with the problems that
// register_plugins adds to the plugin registry (continuation/cli/plugin.hpp).
//
// The `backbone` executable of this tree and any executable made by the CMake function
// backbone_add_cli (drivers/BackboneCli.cmake) have a generated main() (main.cpp.in) that names
// each plugin's register function and calls
//
//   int main(int argc, char** argv) { return backbone::drivers::main(argc, argv, &register_all); }
#pragma once

#include "continuation/cli/plugin.hpp"

namespace backbone::drivers {

using RegisterPlugins = void (*)(cli::PluginRegistry&);

// Runs the subcommand argv[1] with the plugins that register_plugins registers (called once,
// before the subcommand runs). Returns the exit code: 0 ok, 1 numerical failure, 2 bad input.
int main(int argc, char** argv, RegisterPlugins register_plugins);

}  // namespace backbone::drivers
