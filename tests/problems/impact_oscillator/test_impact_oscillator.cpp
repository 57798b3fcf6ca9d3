// The impact oscillator against its closed-form period-1 orbit (problems/impact_oscillator/
// README.md, 'The period-1 orbit'): the orbit, its multipliers eig(S R), det M = r^2, the
// period doubling where 1 + tr + det of that closed-form M vanishes, the grazing wall
// 1 / (omega^2 - 1); and the switch onto the period-2 branch.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "continuation/methods/pseudo_arclength.hpp"
#include "continuation/orbit_bifurcations/bifurcations.hpp"
#include "continuation/orbit_bifurcations/doubling.hpp"
#include "core/solvers/newton.hpp"
#include "problems/impact_oscillator/impact_oscillator.hpp"

namespace bb = backbone;
namespace core = bb::core;
namespace continuation = bb::continuation;
using bb::impact_oscillator::ImpactOscillator;
using bb::impact_oscillator::period_one_orbit;

namespace {

constexpr double omega = 2.8;

ImpactOscillator oscillator(double r) {
  ImpactOscillator o;
  o.set_parameter("restitution", r);
  o.set_free_parameter("wall");
  return o;
}

core::Vector unknowns(double r, double sigma) {
  const auto exact = period_one_orbit(omega, r, sigma);
  core::Vector x(3);
  x << exact->start, sigma;
  return x;
}

// The period doubling of the closed form: where 1 + tr M + det M = 0 (multiplier -1), by
// bisection on sigma to machine precision.
double closed_form_doubling(double r, double lo, double hi) {
  const auto g = [r](double sigma) {
    const auto o = period_one_orbit(omega, r, sigma);
    return std::real((1.0 + o->multipliers[0]) * (1.0 + o->multipliers[1]));
  };
  const double g_lo = g(lo);
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (g(mid) * g_lo > 0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// The shot's error at rtol 1e-12 over one period is about 1e-11 (the closed-form residual reads
// 1e-11); near grazing the impact time amplifies it as 1 / V. 1e-9 holds for V >= 0.01.
constexpr double orbit_tolerance = 1e-9;

continuation::Branch trace(const ImpactOscillator& o, double r, double sigma, double direction,
                           core::Corrector& corrector) {
  continuation::ContinuationOptions options;
  options.ds = 0.01;
  options.ds_max = 0.05;
  options.max_points = 200;
  options.rank_check_every = 0;
  options.bounds = {{"wall", -0.2, 1.0}, {"impact_velocity", 4e-3, 1e300}};
  return continuation::pseudo_arclength(o, unknowns(r, sigma), direction * core::Vector::Unit(3, 2),
                                        corrector, options);
}

}  // namespace

TEST(ImpactOscillator, ClosedFormOrbitSolvesTheShootingWithItsMultipliers) {
  for (const double r : {0.8, 1.0})
    for (const double sigma : {-0.2, -0.1, 0.0, 0.1, 0.14}) {
      const ImpactOscillator o = oscillator(r);
      const core::Vector x = unknowns(r, sigma);
      core::Vector res;
      ASSERT_EQ(o.residual(x, res), core::EvalStatus::ok);
      EXPECT_LT(res.lpNorm<Eigen::Infinity>(), orbit_tolerance) << "r " << r << " sigma " << sigma;
      core::Matrix M;
      ASSERT_EQ(o.monodromy(x, M), core::EvalStatus::ok);
      // det S = r^2 at the one impact, det R = 1: exact up to the shot's error.
      EXPECT_NEAR(M.determinant(), r * r, orbit_tolerance);
      const auto exact = period_one_orbit(omega, r, sigma);
      const core::Floquet f = core::analyse_monodromy(M, o.floquet_structure(), {});
      // Multipliers up to 111 in modulus (sigma 0.14), relative to the largest: measured 6e-9 at
      // V = 0.014 (the impact time's error, 7e-11, amplified by 1 / V), 1e-10 elsewhere.
      const double scale =
          std::max({1.0, std::abs(exact->multipliers[0]), std::abs(exact->multipliers[1])});
      double worst = 0;
      for (const auto& mu : f.multipliers)
        worst = std::max(worst, std::min(std::abs(mu - exact->multipliers[0]),
                                         std::abs(mu - exact->multipliers[1])));
      EXPECT_LT(worst / scale, 1e-8) << "r " << r << " sigma " << sigma;
      EXPECT_EQ(o.floquet_structure().conservative, r == 1.0);
    }
}

TEST(ImpactOscillator, BranchFollowsTheClosedFormAndLocatesDoublingAndGrazing) {
  for (const double r : {0.8, 1.0}) {
    const ImpactOscillator o = oscillator(r);
    auto corrector = core::make_corrector("eigen", {});
    double worst = 0;
    for (const double direction : {1.0, -1.0}) {
      const continuation::Branch branch = trace(o, r, 0.0, direction, *corrector);
      ASSERT_GT(branch.points.size(), 5u);
      EXPECT_FALSE(branch.ended_early()) << branch.message;
      for (const auto& p : branch.points) {
        const auto exact = period_one_orbit(omega, r, p.observable("wall"));
        ASSERT_TRUE(exact);
        worst = std::max(worst, std::abs(p.observable("impact_velocity") - exact->impact_velocity));
        ASSERT_TRUE(p.floquet);
        EXPECT_NEAR(p.floquet->determinant, r * r, orbit_tolerance);
      }
      const auto found = continuation::detect_orbit_bifurcations(o, branch, *corrector, {});
      const auto of_type = [&](const std::string& type) {
        return std::count_if(found.begin(), found.end(),
                             [&](const auto& b) { return b.type == type && b.located; });
      };
      if (direction > 0) {
        // Up to the grazing: the free orbit c cos(omega t) touches the wall, sigma = |c|.
        ASSERT_EQ(of_type("grazing"), 1);
        EXPECT_NEAR(found.back().x[2], 1 / (omega * omega - 1), 1e-10);
      } else {
        // Down to -0.2: one period doubling, where the closed form's 1 + tr + det vanishes.
        ASSERT_EQ(of_type("period_doubling"), 1);
        const auto& b = found.front();
        const double sigma = closed_form_doubling(r, -0.1, 0.0);
        // Located to the bracket of 1e-10 of the orbit's size (bifurcations.hpp).
        EXPECT_NEAR(b.x[2], sigma, 1e-9);
        EXPECT_NEAR(b.observables[5].second, period_one_orbit(omega, r, sigma)->impact_velocity,
                    1e-9);
        EXPECT_NEAR(std::abs(b.floquet.multipliers[0]), 1.0, 1e-6);
      }
    }
    EXPECT_LT(worst, 1e-8) << "r " << r;
  }
}

TEST(ImpactOscillator, DoublingSwitchesOntoTheBranchOfTwiceThePeriod) {
  const ImpactOscillator o = oscillator(0.8);
  auto corrector = core::make_corrector("eigen", {});
  const continuation::Branch down = trace(o, 0.8, 0.0, -1.0, *corrector);
  const auto found = continuation::detect_orbit_bifurcations(o, down, *corrector, {});
  ASSERT_FALSE(found.empty());
  continuation::ContinuationOptions options;
  options.ds = 0.01;
  options.ds_max = 0.05;
  options.max_points = 10;
  options.rank_check_every = 0;
  const continuation::DoubledBranch d =
      continuation::follow_period_doubling(o, found.front(), *corrector, options);
  ASSERT_EQ(d.branch.points.size(), 10u) << d.message;
  for (const auto& p : d.branch.points) {
    // The forcing sets the period: exactly two forcing periods.
    EXPECT_DOUBLE_EQ(p.observable("period"), 2 * 2 * std::numbers::pi / omega);
    EXPECT_EQ(p.observable("impacts_per_period"), 2);
    ASSERT_TRUE(p.floquet);
    EXPECT_NEAR(p.floquet->determinant, std::pow(0.8, 4), orbit_tolerance);  // two impacts
  }
  // Born supercritical: stable where the period-1 orbit has just lost its stability.
  EXPECT_EQ(d.branch.points.front().floquet->stable, 1);
  EXPECT_GT(d.branch.points.front().observable("wall"), found.front().x[2]);
}
