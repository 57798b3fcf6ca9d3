// The paper scene's bar for the contact-bar tests (problems/contact_bar/scenes/paper.ini):
// E = rho = L = A = 1 (c = 1), fixed at x = 0, a wall at g0 = 1e-3 beyond x = L.
//
//   backbone::bar::BarSetup s = test_support::paper_setup();   // s.u0 and s.v0 are zero
#pragma once

#include "problems/bar/bar.hpp"

namespace test_support {

constexpr double kGap = 1e-3;

inline backbone::bar::BarSetup paper_setup() {
  backbone::bar::BarSetup s;
  s.left = {backbone::bar::EndType::fixed, 0};
  s.right = {backbone::bar::EndType::contact, kGap};
  return s;
}

}  // namespace test_support
