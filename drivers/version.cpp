// `backbone version`: prints the version and the libraries it was built with.
#include <fmt/format.h>
#include <sundials/sundials_config.h>

#include <Eigen/Core>
#include <boost/version.hpp>

#include "core/errors.hpp"
#include "drivers/internal/commands.hpp"

namespace {
int run_version(const std::vector<std::string>& args) {
  if (!args.empty() && (args[0] == "--help" || args[0] == "-h")) {
    fmt::print(
        "usage: backbone version\n  prints the version and the libraries it was built "
        "with\n");
    return 0;
  }
  if (!args.empty())
    throw backbone::core::InputError(args[0], "backbone version takes no arguments");
  fmt::print("backbone 0.1.0 (Eigen {}.{}.{}, SUNDIALS {}, Boost {}, fmt {})\n",
             EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION, EIGEN_MINOR_VERSION, SUNDIALS_VERSION,
             BOOST_LIB_VERSION, FMT_VERSION);
  return 0;
}
}  // namespace

namespace backbone::drivers {

Command version_command() {
  return {"version", "", "print the version and library versions", run_version};
}

}  // namespace backbone::drivers
