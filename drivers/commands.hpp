// Subcommands of the backbone CLI register themselves here.
//
// A subcommand is a function from its arguments (the words after the subcommand name) to an
// exit code. main() looks the name up, runs it, and maps exceptions: core::InputError -> one
// line on stderr and exit 2; any other exception -> exit 1. A command returns 1 for a numerical
// failure it reports itself (branch ended early, Newton failed).
//
//   // drivers/simulate.cpp
//   namespace { int run_simulate(const std::vector<std::string>& args) { ...; return 0; } }
//   static const bool registered = backbone::drivers::register_command(
//       {"simulate", "SCENE [--method tdbem|fem|exact] [--out DIR]", "time simulation",
//       run_simulate});
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace backbone::drivers {

struct Command {
  std::string name;
  std::string usage;    // argument synopsis
  std::string summary;  // one line
  std::function<int(const std::vector<std::string>&)> run;
};

bool register_command(Command command);
const std::map<std::string, Command>& commands();

}  // namespace backbone::drivers
