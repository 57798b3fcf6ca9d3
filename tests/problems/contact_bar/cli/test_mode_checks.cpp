// The check every point of a contact-bar mode passes (TraceSetup::reject_point of `trace
// --branch modeJ`): an orbit that never reaches the wall is refused, although it is periodic.
// Next to grazing every non-contact state of the bar is 4L/c-periodic (a manifold of dimension
// N beside the mode), and on fine grids a corrector can land there.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "continuation/cli/scene_options.hpp"
#include "core/io/scene.hpp"
#include "core/orbits/periodic_orbit.hpp"
#include "problems/contact_bar/cli/trace.hpp"

namespace backbone::contact_bar {
namespace {

TEST(ModeChecks, AnOrbitThatNeverReachesTheWallIsRefused) {
  const cli::ProblemPlugin plugin = trace_plugin();
  boost::program_options::options_description keys = plugin.scene_keys();
  keys.add(cli::continuation_keys(keys));
  const std::string paper =
      std::string(BACKBONE_SOURCE_DIR) + "/problems/contact_bar/scenes/paper.ini";
  const core::Scene scene = core::read_scene(keys, paper, {"--shooting_elements", "20"},
                                             boost::program_options::options_description());
  const cli::TraceSetup setup = plugin.setup(scene, "mode1");
  ASSERT_TRUE(setup.reject_point);
  // The closed-form start is a member: accepted.
  EXPECT_EQ(setup.reject_point(setup.guess), "");
  // Linear mode 1 with its end amplitude 0.9 g0 (g0 = 1e-3): periodic with T = 4 L/c, never on
  // the wall.
  const auto* problem = dynamic_cast<const core::PeriodicOrbitProblem*>(setup.problem.get());
  ASSERT_NE(problem, nullptr);
  core::Vector x = setup.guess;
  for (int i = 1; i <= 20; ++i) x[i - 1] = -0.9e-3 * std::sin(std::numbers::pi * i / 40.0);
  x[problem->period_index()] = 4;
  const std::string why = setup.reject_point(x);
  EXPECT_NE(why.find("never reaches the wall"), std::string::npos) << why;
}

}  // namespace
}  // namespace backbone::contact_bar
