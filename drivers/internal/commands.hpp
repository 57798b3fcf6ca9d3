// Internal to backbone::drivers: the subcommands of a backbone CLI, each a function from its
// arguments (the words after the subcommand name) to an exit code, one file each (trace.cpp,
// simulate.cpp, ...).
//
// drivers::main (main.hpp) looks the name up in commands(), runs it, and maps exceptions:
// core::InputError -> one line on stderr and exit 2; any other exception -> exit 1. A command
// returns 1 for a numerical failure it reports itself (branch ended early, Newton failed).
//
//   // drivers/version.cpp
//   Command version_command() { return {"version", "", "print the version", run_version}; }
//   // main.cpp's commands() lists it: the table is explicit, so a static library keeps every
//   // command.
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

Command bench_command();
Command figures_command();
Command inspect_command();
Command reproduce_command();
Command simulate_command();
Command trace_command();
Command version_command();

// Every subcommand above, by name.
const std::map<std::string, Command>& commands();

}  // namespace backbone::drivers
