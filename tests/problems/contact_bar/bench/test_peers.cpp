// The contact bar's peer benchmarks (problems/contact_bar/bench/peers.hpp): backbone's side of
// lu_legrand against the mode-1 closed form, and the stored peer data against the summary the
// peers' README gives.
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>

#include "core/io/table.hpp"
#include "problems/contact_bar/bench/peers.hpp"

using namespace backbone;

// Mode 1 at N = 10 over Lu & Legrand's range: the orbits are piecewise linear, which the
// TD-BEM with event contact and a 10-interval grid hold exactly, so the frequency is the closed
// form's up to the Newton tolerance, 3e-9 g0: the strain is at least 1.25 g0 / L on this range,
// so a residual of 3e-9 g0 moves T (~3) by at most ~2.4e-9, dT / T <= 1e-9. A point off the
// family is off by far more.
TEST(ContactBarPeers, PaperMode1MatchesTheClosedFormOverLuAndLegrandsRange) {
  const contact_bar::Mode1Trace t = contact_bar::trace_paper_mode1(10);
  ASSERT_TRUE(t.complete) << t.message;
  EXPECT_LE(t.max_error, 1e-9);
  EXPECT_LE(t.median_error, t.max_error);
  EXPECT_GT(t.points, 10);
  std::cout << "[ measured ] " << t.points << " points, " << t.seconds << " s CPU, median error "
            << t.median_error << ", max " << t.max_error << "\n";
}

// The stored Lu & Legrand runs hold 790 points each and, over their admissible points, the
// median errors 2.0e-3 (20 harmonics) and 3.2e-3 (40) of the peers' README (2 digits there).
TEST(ContactBarPeers, StoredLuAndLegrandRunsMatchTheirSummary) {
  for (const auto& [harmonics, median] : {std::pair{20, 2.0e-3}, std::pair{40, 3.2e-3}}) {
    const core::Table t =
        core::Table::read_csv(contact_bar::contact_bar_peers_folder() /
                              ("lu_legrand_mode1_h" + std::to_string(harmonics) + ".csv"));
    EXPECT_EQ(t.rows(), 790u);
    std::vector<double> errors;
    const std::vector<double> admissible = t.column("admissible"), error = t.column("relerr_freq");
    for (std::size_t i = 0; i < t.rows(); ++i)
      if (admissible[i] == 1) errors.push_back(error[i]);
    std::sort(errors.begin(), errors.end());
    const double m = errors.size() % 2
                         ? errors[errors.size() / 2]
                         : 0.5 * (errors[errors.size() / 2 - 1] + errors[errors.size() / 2]);
    EXPECT_NEAR(m, median, 0.05e-3) << harmonics << " harmonics";
  }
}
