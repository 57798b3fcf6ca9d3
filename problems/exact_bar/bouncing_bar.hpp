// The bouncing bar (Doyen, Ern & Piperno 2011; README.md, section 'Bouncing bar') and
// its closed-form solution, derived by hand from the characteristics.
//
// L = 10, E = 900, rho = 1, A = 1 (c = 30, tau = L/c = 1/3), gravity g = 10 towards the
// foundation, released undeformed at rest with its contacting end h0 = 5 above the
// foundation. In backbone's frame: left end free, right end contact with gap 5, body force
// +10 along +x. The motion is periodic with period 16 tau = 16/3: fall (1 = 3 tau), impact
// (2 tau, force 300 -> 500), flight with the bar vibrating (6 tau), impact (2 tau, force
// 500 -> 300, cancels the vibration), rigid flight back to rest at the top (3 tau).
//
//   bar::BarSetup s = exact_bar::bouncing_bar_setup();
//   double u = exact_bar::bouncing_bar_contact_displacement(1.2);   // 5: on the foundation
//   double f = exact_bar::bouncing_bar_contact_force(1.2);          // 300 * 1.2 = 360
//   double T = exact_bar::bouncing_bar_period();                    // 16/3
#pragma once

#include "problems/bar/bar.hpp"

namespace backbone::exact_bar {

bar::BarSetup bouncing_bar_setup();
double bouncing_bar_period();  // 16 L / c = 16/3
// u(L, t) in backbone's frame (the wall at u = 5); valid for every t >= 0.
double bouncing_bar_contact_displacement(double t);
// Contact force at the contacting end; right-continuous (0 at take-off); valid for t >= 0.
double bouncing_bar_contact_force(double t);

}  // namespace backbone::exact_bar
