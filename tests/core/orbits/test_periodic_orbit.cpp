// Periodic-orbit vocabulary: formulation names, unknown layout, default observables.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/errors.hpp"
#include "core/orbits/periodic_orbit.hpp"

namespace backbone::core {
namespace {

TEST(ShootingFormulation, ParsesBothSpellings) {
  EXPECT_EQ(parse_formulation("paper"), ShootingFormulation::displacement_periodicity);
  EXPECT_EQ(parse_formulation("displacement_periodicity"),
            ShootingFormulation::displacement_periodicity);
  EXPECT_EQ(parse_formulation("regular"), ShootingFormulation::half_period_velocity);
  EXPECT_EQ(parse_formulation("half_period_velocity"), ShootingFormulation::half_period_velocity);
  for (auto f :
       {ShootingFormulation::displacement_periodicity, ShootingFormulation::half_period_velocity})
    EXPECT_EQ(parse_formulation(to_string(f)), f);
  // What the logs echo is what the scene key takes.
  EXPECT_STREQ(scene_name(ShootingFormulation::half_period_velocity), "regular");
  for (auto f :
       {ShootingFormulation::displacement_periodicity, ShootingFormulation::half_period_velocity})
    EXPECT_EQ(parse_formulation(scene_name(f)), f);
  try {
    parse_formulation("Paper");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "formulation");
  }
}

// Linear oscillator x'' + x = 0 with two uncoupled masses: layout and observables only.
class TwoOscillators : public PeriodicOrbitProblem {
 public:
  int state_size() const override { return 2; }
  int num_parameters() const override { return 1; }
  double energy(const Vector& x) const override { return 0.5 * x.head(2).squaredNorm(); }

 protected:
  EvalStatus compute_residual(const Vector&, Vector& r) const override {
    r.setZero();
    return EvalStatus::ok;
  }
};

TEST(PeriodicOrbitProblem, LayoutAndObservables) {
  TwoOscillators p;
  EXPECT_EQ(p.num_unknowns(), 4);  // 2 states | T | 1 parameter
  EXPECT_EQ(p.num_equations(), 2);
  EXPECT_EQ(p.period_index(), 2);
  EXPECT_EQ(p.formulation(), ShootingFormulation::half_period_velocity);  // the default
  Vector x(4);
  x << 0.3, 0.4, 2 * std::numbers::pi, 7.0;
  const Observables obs = p.observables(x);
  ASSERT_EQ(obs.size(), 3u);
  EXPECT_EQ(obs[0].first, "period");
  EXPECT_DOUBLE_EQ(obs[0].second, 2 * std::numbers::pi);
  EXPECT_EQ(obs[1].first, "frequency");
  EXPECT_DOUBLE_EQ(obs[1].second, 1.0);
  EXPECT_EQ(obs[2].first, "energy");
  EXPECT_DOUBLE_EQ(obs[2].second, 0.125);
  const Vector c = p.state_coordinates();
  ASSERT_EQ(c.size(), 2);
  EXPECT_EQ(c[0], 0.0);
  EXPECT_EQ(c[1], 1.0);
}

}  // namespace
}  // namespace backbone::core
