#include <fmt/format.h>
#include <gtest/gtest.h>
#include <iostream>

#include "continuation/branch.hpp"
#include "core/solvers/bordered_system.hpp"
#include "core/solvers/newton.hpp"
#include "problems/impact_oscillator/impact_oscillator.hpp"

namespace bb = backbone;
using bb::impact_oscillator::ImpactOscillator;
using bb::impact_oscillator::period_one_orbit;

TEST(ImpactOscillatorDebug, GrazingSolve) {
  ImpactOscillator o;
  o.set_free_parameter("wall");
  const double sigma = 0.1421;
  auto exact = period_one_orbit(2.8, 0.8, sigma);
  bb::core::Vector x(3);
  x << exact->start, sigma;
  bb::core::BorderedSystem sys(o, {bb::core::BorderRow::observable("impact_velocity", exact->impact_velocity / 2)});
  bb::core::NewtonOptions opt;
  auto c = bb::core::make_corrector("eigen", opt);
  bb::core::Vector r; bb::core::Matrix J;
  sys.residual(x, r); sys.jacobian(x, J);
  std::cout << "V " << exact->impact_velocity << " r " << r.transpose() << "\n";
  std::cout << J << "\n";
  auto s = c->solve(sys, x);
  std::cout << s.message << " x " << x.transpose() << "\n";
}
