#include "problems/exact_bar/bouncing_bar.hpp"

#include <cmath>

namespace backbone::exact_bar {

namespace {

// Scene constants.
constexpr double length = 10, youngs_modulus = 900, density = 1, area = 1;
constexpr double g = 10;  // body acceleration towards the foundation
constexpr double h0 = 5;  // initial height of the contacting end
// Derived: c = 30, tau = L / c = 1/3, impedance rho A c = 30.
constexpr double tau = 1.0 / 3.0;
constexpr double impedance = 30;
constexpr double t_land = 1;           // sqrt(2 h0 / g) = 3 tau
constexpr double v_land = g * t_land;  // 10

// Derivation (characteristics, A = R+ arriving at the contact end, B = R- at the free end;
// a signal crossing the bar gains g tau; free end reflects unchanged, closed end flips sign):
// - fall, t < 1: rigid motion v = g t, so A(t) = B(t) = g t; u(L) = g t^2 / 2 reaches h0 at 1.
// - impact 1, [1, 1 + 2 tau): the flipped wave -A needs 2 tau to come back, so A(t) = g t
//   throughout and the force EA A / c = rho A c g t rises 300 -> 500. Then A jumps to
//   -g t + 4 g tau < 0: take-off at 1 + 2 tau = 5/3, the end stays at h0.
// - flight 1, t = 1 + 2 m tau + s (m = 1, 2, 3, s in [0, 2 tau)): each round trip adds 4 g tau,
//   A(t) = g (2 m tau - t_land - s): the end velocity is a saw-tooth (the bar vibrates).
//   Integrating: the end falls by 40/9 during m = 1, stays at that level over m = 2 (zero
//   mean velocity) and climbs back to h0 exactly at the end of m = 3, t = 11/3, where A
//   jumps to g (5/3 - s) > 0: impact 2.
// - impact 2, [11/3, 13/3): A(t) = g (16/3 - t), force rho A c A: 500 -> 300 (impact 1 played
//   backwards). After it A(t + 2 tau) = -A(t) + 2 g tau = g (t - 16/3): rigid motion with
//   velocity -10 at take-off, e = 0 everywhere.
// - flight 2, [13/3, 16/3): rigid, u(L) = h0 - v_land s + g s^2 / 2, at rest with u(L) = 0 at
//   16/3: the initial state again.
constexpr double t_takeoff1 = t_land + 2 * tau;     // 5/3
constexpr double t_impact2 = t_takeoff1 + 6 * tau;  // 11/3
constexpr double t_takeoff2 = t_impact2 + 2 * tau;  // 13/3
constexpr double period = 16 * tau;                 // 16/3

double phase(double t) {
  const double p = std::fmod(t, period);
  return p < 0 ? p + period : p;
}

}  // namespace

bar::BarSetup bouncing_bar_setup() {
  bar::BarSetup s;
  s.material = {length, youngs_modulus, density, area};
  s.left = {bar::EndType::free, 0};
  s.right = {bar::EndType::contact, h0};
  s.body_force = density * g;
  s.u0 = bar::PiecewiseLinear::zero(length);
  s.v0 = bar::PiecewiseLinear::zero(length);
  return s;
}

double bouncing_bar_period() {
  return period;
}

double bouncing_bar_contact_displacement(double t) {
  const double p = phase(t);
  if (p < t_land) return 0.5 * g * p * p;
  if (p < t_takeoff1) return h0;
  if (p < t_impact2) {
    // Flight 1: saw-tooth end velocity g (2 m tau - t_land - s) on the m-th 2 tau window.
    const int m = std::min(3, 1 + static_cast<int>((p - t_takeoff1) / (2 * tau)));
    const double s = p - (t_land + 2 * m * tau);
    const double level = m == 1 ? 0.0 : -40.0 / 9.0;  // displacement at the window's start
    return h0 + level + g * ((2 * m * tau - t_land) * s - 0.5 * s * s);
  }
  if (p < t_takeoff2) return h0;
  const double s = p - t_takeoff2;  // flight 2: rigid, leaves with velocity -v_land
  return h0 - v_land * s + 0.5 * g * s * s;
}

double bouncing_bar_contact_force(double t) {
  const double p = phase(t);
  if (p >= t_land && p < t_takeoff1) return impedance * (v_land + g * (p - t_land));
  if (p >= t_impact2 && p < t_takeoff2) return impedance * (v_land + g * (t_takeoff2 - p));
  return 0;
}

}  // namespace backbone::exact_bar
