// drivers::main (main.hpp): dispatches to a subcommand, maps exceptions to exit codes.
#include "drivers/main.hpp"

#include <fmt/format.h>

#include <exception>
#include <filesystem>
#include <new>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "core/errors.hpp"
#include "drivers/internal/commands.hpp"
#include "drivers/internal/plugins.hpp"

namespace backbone::drivers {

namespace {

// glibc serves every block above 128 KiB by its own mmap and returns it on free, so each dense
// Jacobian, QR or bordered system of a fine grid (6.5 MB at N = 640) would be faulted in page by
// page on every evaluation. Blocks up to 256 MiB come from the heap and up to 512 MiB of freed
// heap is kept, so large blocks are reused in place (drivers/README.md, 'Memory').
void keep_large_blocks() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 256 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
#endif
}

void print_usage(const std::string& program) {
  fmt::print("usage: {} COMMAND [arguments]\n\ncommands:\n", program);
  for (const auto& [name, c] : commands()) fmt::print("  {:<10} {}\n", name, c.summary);
  fmt::print("\n'{} COMMAND --help' describes a command and its keys.\n", program);
}
}  // namespace

const std::map<std::string, Command>& commands() {
  static const std::map<std::string, Command> table = [] {
    std::map<std::string, Command> t;
    for (Command c : {bench_command(), figures_command(), inspect_command(), reproduce_command(),
                      simulate_command(), trace_command(), version_command()})
      t.emplace(c.name, std::move(c));
    return t;
  }();
  return table;
}

int main(int argc, char** argv, RegisterPlugins register_plugins) {
  set_plugin_registration(register_plugins);
  // The executable's own name in its messages (`backbone`, or an outside CLI's).
  const std::string program = std::filesystem::path(argv[0]).filename().string();
  keep_large_blocks();
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
    print_usage(program);
    if (argc >= 2) return core::exit_ok;
    fmt::print(stderr, "{}: a command is required (the list above)\n", program);
    return core::exit_bad_input;
  }
  const std::string name = argv[1];
  auto it = commands().find(name);
  if (it == commands().end()) {
    fmt::print(stderr, "{0}: unknown command '{1}' (try '{0} --help')\n", program, name);
    return core::exit_bad_input;
  }
  std::vector<std::string> args(argv + 2, argv + argc);
  try {
    return it->second.run(args);
  } catch (const core::InputError& e) {
    fmt::print(stderr, "{} {}: {}\n", program, name, e.what());
    return core::exit_bad_input;
  } catch (const std::bad_alloc&) {
    fmt::print(stderr, "{} {}: out of memory\n", program, name);
    return core::exit_numerical_failure;
  } catch (const std::exception& e) {
    fmt::print(stderr, "{} {}: {}\n", program, name, e.what());
    return core::exit_numerical_failure;
  }
}

}  // namespace backbone::drivers
