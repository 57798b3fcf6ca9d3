// SIGINT / SIGTERM during a long run (continuation/cli/stop_signals.hpp): the first one is recorded
// and announced, the process carries on (the run stops after its current point); a second one
// stops the process at once with the signal's default action. Each case runs in a child
// process (gtest death tests), so the signals hit only it.
#include <gtest/gtest.h>

#include <csignal>
#include <cstdlib>

#include "continuation/cli/stop_signals.hpp"

namespace backbone::cli {
namespace {

TEST(StopSignals, TheFirstSignalIsRecordedAndTheProcessCarriesOn) {
  for (int sig : {SIGINT, SIGTERM}) {
    EXPECT_EXIT(
        {
          StopSignals stop;
          const bool before = stop.requested();
          std::raise(sig);
          std::exit(!before && stop.requested() && stop.signal() == sig ? 0 : 1);
        },
        ::testing::ExitedWithCode(0), "stopping after the current point");
  }
}

TEST(StopSignals, ASecondSignalStopsAtOnce) {
  EXPECT_EXIT(
      {
        StopSignals stop;
        std::raise(SIGTERM);
        std::raise(SIGINT);  // either signal: the second stops with its default action
        std::exit(0);        // not reached
      },
      ::testing::KilledBySignal(SIGINT), "");
}

TEST(StopSignals, TheDestructorRestoresTheDefaultActions) {
  EXPECT_EXIT(
      {
        { StopSignals stop; }
        std::raise(SIGTERM);
        std::exit(0);  // not reached: SIGTERM's default action ends the process
      },
      ::testing::KilledBySignal(SIGTERM), "");
}

}  // namespace
}  // namespace backbone::cli
