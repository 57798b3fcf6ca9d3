// bar::PiecewiseLinear against an independent oracle: the interval found by a linear scan of
// the knots. The class finds it by index arithmetic on near-uniform knots and by binary search
// on others; either way the value on the interval is the same expression, so the two agree
// exactly when (and only when) the same interval is chosen.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "core/errors.hpp"
#include "problems/bar/bar.hpp"

namespace backbone::bar {
namespace {

// Index i of the interval [x_{i-1}, x_i) holding x (front < x < back), by scanning.
std::size_t scanned_interval(const std::vector<double>& x, double at) {
  std::size_t i = 1;
  while (i + 1 < x.size() && x[i] <= at) ++i;
  return i;
}

double oracle_value(const std::vector<double>& x, const std::vector<double>& y, double at) {
  if (at <= x.front()) return y.front();
  if (at >= x.back()) return y.back();
  const std::size_t i = scanned_interval(x, at);
  const double w = (at - x[i - 1]) / (x[i] - x[i - 1]);
  return (1 - w) * y[i - 1] + w * y[i];
}

// Left (side -1) or right (+1) derivative: on a knot the interval on that side.
double oracle_slope(const std::vector<double>& x, const std::vector<double>& y, double at,
                    int side) {
  if (x.size() < 2) return 0;
  if (at < x.front() || (at == x.front() && side < 0)) return 0;
  if (at > x.back() || (at == x.back() && side > 0)) return 0;
  std::size_t i = 1;
  while (i + 1 < x.size() && (side > 0 ? x[i] <= at : x[i] < at)) ++i;
  return (y[i] - y[i - 1]) / (x[i] - x[i - 1]);
}

// Knots of the kinds the solvers see: a shooting state's u0 (i L / N, and i * 0.1 whose
// rounding leaves the grid by ulps), knots jittered by up to 0.2 of the spacing (still guessed
// by index), a mapped grid (a free knot: not uniform) and two knots.
std::vector<std::vector<double>> knot_sets() {
  std::vector<std::vector<double>> sets;
  for (int n : {2, 3, 40, 160}) {
    std::vector<double> x;
    for (int i = 0; i <= n; ++i) x.push_back(1.0 * i / n);
    sets.push_back(x);
  }
  std::vector<double> tenths;
  for (int i = 0; i <= 37; ++i) tenths.push_back(i * 0.1);
  sets.push_back(tenths);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  std::vector<double> jittered;
  for (int i = 0; i <= 50; ++i) jittered.push_back(i == 0 || i == 50 ? i : i + jitter(rng));
  sets.push_back(jittered);
  std::vector<double> mapped;  // nodes 0..20 with node 7 moved to 0.6: two spacings
  for (int i = 0; i <= 20; ++i) mapped.push_back(i <= 7 ? 0.6 * i / 7 : 0.6 + 0.4 * (i - 7) / 13);
  sets.push_back(mapped);
  sets.push_back({0.25, 3.0});
  return sets;
}

std::vector<double> query_points(const std::vector<double>& x) {
  std::vector<double> q;
  const double inf = std::numeric_limits<double>::infinity();
  for (double k : x) {  // on every knot and one ulp either side
    q.push_back(k);
    q.push_back(std::nextafter(k, -inf));
    q.push_back(std::nextafter(k, inf));
  }
  std::mt19937 rng(11);
  const double span = x.back() - x.front();
  std::uniform_real_distribution<double> anywhere(x.front() - 0.1 * span, x.back() + 0.1 * span);
  for (int i = 0; i < 2000; ++i) q.push_back(anywhere(rng));
  return q;
}

TEST(PiecewiseLinear, ValuesAndSlopesMatchALinearScanExactly) {
  for (const auto& x : knot_sets()) {
    std::vector<double> y;
    for (std::size_t i = 0; i < x.size(); ++i) y.push_back(std::sin(3.0 * i) - 0.01 * i);
    const PiecewiseLinear f(x, y);
    for (double at : query_points(x)) {
      EXPECT_EQ(f(at), oracle_value(x, y, at)) << at << " on " << x.size() << " knots";
      for (int side : {-1, 1})
        EXPECT_EQ(f.slope(at, side), oracle_slope(x, y, at, side)) << at << " side " << side;
    }
  }
}

// The integral is exact for a piecewise-linear integrand: the trapezoid rule on every piece,
// summed here over the pieces cut by a linear scan (equal up to the summation's round-off).
TEST(PiecewiseLinear, IntegralMatchesTrapezoidsOverTheScannedPieces) {
  for (const auto& x : knot_sets()) {
    std::vector<double> y;
    for (std::size_t i = 0; i < x.size(); ++i) y.push_back(std::cos(2.0 * i));
    const PiecewiseLinear f(x, y);
    const std::vector<double> q = query_points(x);
    for (std::size_t k = 0; k + 1 < q.size(); k += 7) {
      const double a = std::min(q[k], q[k + 1]), b = std::max(q[k], q[k + 1]);
      std::vector<double> cuts{a};
      for (double knot : x)
        if (knot > a && knot < b) cuts.push_back(knot);
      cuts.push_back(b);
      double expected = 0, scale = 0;
      for (std::size_t j = 0; j + 1 < cuts.size(); ++j) {
        const double piece = 0.5 * (oracle_value(x, y, cuts[j]) + oracle_value(x, y, cuts[j + 1])) *
                             (cuts[j + 1] - cuts[j]);
        expected += piece;
        scale += std::abs(piece);
      }
      // Same pieces in the same order: equal to the last bit; the bound allows only the
      // round-off of the sum should the order ever differ.
      EXPECT_NEAR(f.integral(a, b), expected, 1e-15 * scale) << a << " " << b;
    }
  }
}

// A velocity in characteristic form is piecewise constant: with_jumps holds it. The values are
// the right limits at a jump and the integral is that of the step function, both by hand.
TEST(PiecewiseLinear, WithJumpsHoldsAStepFunction) {
  const PiecewiseLinear f =
      PiecewiseLinear::with_jumps({0.0, 0.3, 0.3, 1.0}, {2.0, 2.0, -1.0, -1.0});
  EXPECT_EQ(f(0.1), 2.0);
  EXPECT_EQ(f(0.3), -1.0);  // the right limit
  EXPECT_EQ(f(0.7), -1.0);
  EXPECT_EQ(f.slope(0.3, -1), 0.0);
  EXPECT_EQ(f.slope(0.3, +1), 0.0);
  // 2 * 0.3 - 1 * 0.7 = -0.1, and pieces of it; round-off of a few products.
  EXPECT_NEAR(f.integral(0.0, 1.0), -0.1, 1e-15);
  EXPECT_NEAR(f.integral(0.2, 0.5), 2 * 0.1 - 0.2, 1e-15);
  EXPECT_NEAR(f.integral(0.5, 0.2), -(2 * 0.1 - 0.2), 1e-15);
  EXPECT_NEAR(f.integral(-1.0, 2.0), 2 * 1.3 - 1.7, 1e-15);  // constant beyond the ends
  EXPECT_NEAR(f.integral(0.3, 0.3), 0.0, 0.0);
  // Ramps around a jump: the slopes on either side.
  const PiecewiseLinear g = PiecewiseLinear::with_jumps({0.0, 0.5, 0.5, 1.0}, {0.0, 1.0, 3.0, 2.0});
  EXPECT_DOUBLE_EQ(g(0.25), 0.5);
  EXPECT_DOUBLE_EQ(g(0.75), 2.5);
  EXPECT_DOUBLE_EQ(g.slope(0.5, -1), 2.0);
  EXPECT_DOUBLE_EQ(g.slope(0.5, +1), -2.0);
  EXPECT_NEAR(g.integral(0.0, 1.0), 0.25 + 1.25, 1e-15);
}

TEST(PiecewiseLinear, JumpsOnlyWhereAsked) {
  EXPECT_THROW(PiecewiseLinear({0.0, 0.5, 0.5, 1.0}, {0.0, 1.0, 2.0, 0.0}), core::InputError);
  // Never three knots at one x, never a jump at an end.
  EXPECT_THROW(PiecewiseLinear::with_jumps({0.0, 0.5, 0.5, 0.5, 1.0}, {0, 1, 2, 3, 0}),
               core::InputError);
  EXPECT_THROW(PiecewiseLinear::with_jumps({0.0, 0.0, 1.0}, {0, 1, 0}), core::InputError);
  EXPECT_THROW(PiecewiseLinear::with_jumps({0.0, 1.0, 1.0}, {0, 1, 0}), core::InputError);
}

}  // namespace
}  // namespace backbone::bar
