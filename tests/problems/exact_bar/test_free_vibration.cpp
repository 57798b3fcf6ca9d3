// Linear free vibration (no contact) against the d'Alembert closed form
//   u(x, t) = (U(x - ct) + U(x + ct)) / 2 + (G(x + ct) - G(x - ct)) / (2c),
// U the periodic extension of u0 (odd about a fixed end, even about a free end), G the
// primitive of the same extension of v0 (zero mean over a period). This oracle shares no code
// with the solver: it never reflects a signal, it only folds arguments into one period.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "problems/exact_bar/exact_solution.hpp"

namespace backbone::exact_bar {
namespace {

// Periodic extension of f on [0, L]: fixed-fixed (odd about 0 and L, period 2L) or
// fixed-free (odd about 0, even about L, period 4L).
struct Extension {
  bar::PiecewiseLinear f;
  double period;
  double operator()(double s) const { return f(fold(s)); }
  double slope(double s) const { return f.slope(fold(s), 1); }
  double primitive(double s) const { return f.integral(0.0, fold(s)); }  // zero-mean period
  double fold(double s) const {
    const double r = std::fmod(s, period);
    return r < 0 ? r + period : r;
  }
};

Extension extend(const bar::PiecewiseLinear& f, double L, bool right_free) {
  std::vector<double> knots{0.0, L};
  for (double k : f.knots()) knots.push_back(k);
  std::vector<std::pair<double, double>> pts;
  for (double k : knots) {
    if (right_free) {  // [0,L]: f(x); [L,2L]: f(2L-x); [2L,3L]: -f(x-2L); [3L,4L]: -f(4L-x)
      pts.push_back({k, f(k)});
      pts.push_back({2 * L - k, f(k)});
      pts.push_back({2 * L + k, -f(k)});
      pts.push_back({4 * L - k, -f(k)});
    } else {  // [0,L]: f(x); [L,2L]: -f(2L-x)
      pts.push_back({k, f(k)});
      pts.push_back({2 * L - k, -f(k)});
    }
  }
  std::sort(pts.begin(), pts.end());
  std::vector<double> x, y;
  for (const auto& [px, py] : pts) {
    if (!x.empty() && px == x.back()) continue;
    x.push_back(px);
    y.push_back(py);
  }
  return {bar::PiecewiseLinear(x, y), right_free ? 4 * L : 2 * L};
}

struct Case {
  bar::BarSetup setup;
  Extension u_ext, v_ext;
  double c;
  double u_exact(double x, double t) const {
    return 0.5 * (u_ext(x - c * t) + u_ext(x + c * t)) +
           (v_ext.primitive(x + c * t) - v_ext.primitive(x - c * t)) / (2 * c);
  }
  double v_exact(double x, double t) const {
    return 0.5 * c * (u_ext.slope(x + c * t) - u_ext.slope(x - c * t)) +
           0.5 * (v_ext(x + c * t) + v_ext(x - c * t));
  }
};

Case make_case(bool right_free) {
  Case k;
  auto& s = k.setup;
  s.material = {1.5, 2.0, 1.0, 0.7};  // c = sqrt(2): nothing lands on a round number
  const double L = s.material.length;
  s.left = {bar::EndType::fixed, 0};
  s.right = {right_free ? bar::EndType::free : bar::EndType::fixed, 0};
  // Kinked u0 and v0 (zero at fixed ends), knots at unrelated places.
  if (right_free) {
    s.u0 = bar::PiecewiseLinear({0.0, 0.31, 0.9, L}, {0.0, 0.02, -0.005, 0.011});
    s.v0 = bar::PiecewiseLinear({0.0, 0.47, 1.2, L}, {0.0, -0.03, 0.01, 0.004});
  } else {
    s.u0 = bar::PiecewiseLinear({0.0, 0.31, 0.9, L}, {0.0, 0.02, -0.005, 0.0});
    s.v0 = bar::PiecewiseLinear({0.0, 0.47, 1.2, L}, {0.0, -0.03, 0.01, 0.0});
  }
  k.c = s.material.wave_speed();
  k.u_ext = extend(s.u0, L, right_free);
  k.v_ext = extend(s.v0, L, right_free);
  return k;
}

// Round-off only: the solver's times accumulate one rounding per window (about 100 windows
// here) and the oracle folds arguments of size ~ct; both stay far below 1e-13 relative.
constexpr double tolerance = 1e-13;

void check_against_dalembert(bool right_free) {
  const Case k = make_case(right_free);
  const double L = k.setup.material.length;
  const double period = (right_free ? 4 : 2) * L / k.c;
  const double t_end = 20.37 * period;
  const ExactBarSolution sol = solve(k.setup, t_end);
  ASSERT_TRUE(sol.ok()) << sol.message();
  double scale = 0, err_u = 0, err_v = 0, v_scale = 0;
  for (double t : {0.0, 0.123, 1.0 * period, 7.77, 20.0 * period, t_end}) {
    for (int i = 0; i <= 37; ++i) {
      const double x = L * (i + 0.123) / 38.5;
      scale = std::max(scale, std::abs(k.u_exact(x, t)));
      v_scale = std::max(v_scale, std::abs(k.v_exact(x, t)));
      err_u = std::max(err_u, std::abs(sol.u(x, t) - k.u_exact(x, t)));
      err_v = std::max(err_v, std::abs(sol.v(x, t) - k.v_exact(x, t)));
    }
  }
  EXPECT_LT(err_u / scale, tolerance) << "relative error of u: " << err_u / scale;
  EXPECT_LT(err_v / v_scale, tolerance) << "relative error of v: " << err_v / v_scale;
  ::testing::Test::RecordProperty("relative_error_u", std::to_string(err_u / scale));
}

TEST(ExactBarFreeVibration, FixedFixedMatchesDalembertAfter20Periods) {
  check_against_dalembert(false);
}

TEST(ExactBarFreeVibration, FixedFreeMatchesDalembertAfter20Periods) {
  check_against_dalembert(true);
}

// Every solution of the fixed-fixed bar is 2L/c periodic, of the fixed-free bar 4L/c periodic
// (all frequencies are multiples of the fundamental): u returns to u0 and v to v0.
void check_periodicity(bool right_free) {
  const Case k = make_case(right_free);
  const double L = k.setup.material.length;
  const double period = (right_free ? 4 : 2) * L / k.c;
  const ExactBarSolution sol = solve(k.setup, 20 * period);
  double err = 0, half_err = 0;
  for (int i = 0; i <= 50; ++i) {
    const double x = L * i / 50.0;
    err = std::max(err, std::abs(sol.u(x, period) - k.setup.u0(x)));
    err = std::max(err, std::abs(sol.u(x, 20 * period) - k.setup.u0(x)));
    // Half a period is NOT a return (guards against a trivially periodic solver).
    half_err = std::max(half_err, std::abs(sol.u(x, 0.5 * period) - k.setup.u0(x)));
  }
  EXPECT_LT(err, 1e-15);  // |u0| ~ 0.02: round-off
  EXPECT_GT(half_err, 1e-3);
}

TEST(ExactBarFreeVibration, FixedFixedReturnsToU0After2LOverC) {
  check_periodicity(false);
}
TEST(ExactBarFreeVibration, FixedFreeReturnsToU0After4LOverC) {
  check_periodicity(true);
}

TEST(ExactBarFreeVibration, EnergyConservedWithoutContact) {
  const Case k = make_case(true);
  const ExactBarSolution sol = solve(k.setup, 50.0);
  const double e0 = sol.energy(0.0);
  // Independent value at t = 0: the energy of u0, v0 integrated by the PiecewiseLinear helpers.
  const auto& m = k.setup.material;
  double e_initial = 0;
  const std::vector<double> xs{0.0, 0.31, 0.47, 0.9, 1.2, 1.5};
  for (std::size_t i = 0; i + 1 < xs.size(); ++i) {
    const double a = xs[i], b = xs[i + 1], mid = 0.5 * (a + b);
    const double e = k.setup.u0.slope(mid, 1);
    auto v2 = [&](double x) { return k.setup.v0(x) * k.setup.v0(x); };
    e_initial += 0.5 * m.axial_stiffness() * e * e * (b - a) +
                 0.5 * m.density * m.area * (b - a) / 6 * (v2(a) + 4 * v2(mid) + v2(b));
  }
  EXPECT_NEAR(e0, e_initial, 1e-15 * e_initial);
  for (double t = 0.1; t < 50; t += 1.37) EXPECT_NEAR(sol.energy(t), e0, 1e-13 * e0) << t;
}

}  // namespace
}  // namespace backbone::exact_bar
