// backbone: nonlinear modes by shooting and continuation. Dispatches to a subcommand.
#include <fmt/format.h>

#include <exception>
#include <new>

#include "core/errors.hpp"
#include "drivers/commands.hpp"

namespace backbone::drivers {

namespace {
std::map<std::string, Command>& registry() {
  static std::map<std::string, Command> table;
  return table;
}

void print_usage() {
  fmt::print("usage: backbone COMMAND [arguments]\n\ncommands:\n");
  for (const auto& [name, c] : commands()) fmt::print("  {:<10} {}\n", name, c.summary);
  fmt::print("\n'backbone COMMAND --help' describes a command and its keys.\n");
}
}  // namespace

bool register_command(Command command) {
  std::string name = command.name;
  return registry().emplace(name, std::move(command)).second;
}

const std::map<std::string, Command>& commands() {
  return registry();
}

}  // namespace backbone::drivers

int main(int argc, char** argv) {
  using namespace backbone;
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
    drivers::print_usage();
    return argc < 2 ? core::exit_bad_input : core::exit_ok;
  }
  const std::string name = argv[1];
  auto it = drivers::commands().find(name);
  if (it == drivers::commands().end()) {
    fmt::print(stderr, "backbone: unknown command '{}' (try 'backbone --help')\n", name);
    return core::exit_bad_input;
  }
  std::vector<std::string> args(argv + 2, argv + argc);
  try {
    return it->second.run(args);
  } catch (const core::InputError& e) {
    fmt::print(stderr, "backbone {}: {}\n", name, e.what());
    return core::exit_bad_input;
  } catch (const std::bad_alloc&) {
    fmt::print(stderr, "backbone {}: out of memory\n", name);
    return core::exit_numerical_failure;
  } catch (const std::exception& e) {
    fmt::print(stderr, "backbone {}: {}\n", name, e.what());
    return core::exit_numerical_failure;
  }
}
