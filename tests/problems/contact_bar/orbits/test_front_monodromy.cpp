#include <gtest/gtest.h>
#include <fmt/format.h>
#include <Eigen/Eigenvalues>
#include <iostream>

#include "problems/contact_bar/orbits/family.hpp"
#include "problems/exact_bar/front_monodromy.hpp"

using namespace backbone;

namespace {
bar::BarSetup paper() {
  bar::BarSetup s;
  s.material = {};
  s.right = {bar::EndType::contact, 1e-3};
  return s;
}
}  // namespace

TEST(FrontMonodromy, Explore) {
  for (int J : {1, 2, 3}) {
    bar::BarSetup s = paper();
    contact_bar::ContactFamily fam(s.material, 1e-3, J);
    const double E = 3 * fam.grazing_energy();
    s.u0 = fam.u0(E);
    const double T = fam.period(E);
    exact_bar::ExactBarSolution orbit(s, 2 * T);
    auto os = exact_bar::free_flight_state(orbit, T);
    std::cout << "J=" << J << " T=" << T << " t0=" << os.t0 << " fronts=" << os.state.fronts() << "\n";
    auto m = exact_bar::front_monodromy(s, os.state, T);
    std::cout << "ok " << m.ok << " " << m.message << " leak " << m.value_leak << " iso " << m.isometry_error
              << " shift " << m.time_shift_error << " ret " << m.return_error << "\n" << m.K << "\n";
    if (m.ok) {
      Eigen::EigenSolver<Eigen::MatrixXd> es(m.K);
      std::cout << es.eigenvalues().transpose() << "\n";
    }
  }
}
TEST(FrontMonodromy, Explore2) {
  auto report = [](const char* name, bar::BarSetup s, double T) {
    exact_bar::ExactBarSolution orbit(s, 2 * T);
    auto os = exact_bar::free_flight_state(orbit, T);
    auto m = exact_bar::front_monodromy(s, os.state, T);
    std::cout << name << " T=" << T << " fronts=" << os.state.fronts() << " ok " << m.ok << " " << m.message
              << " leak " << m.value_leak << " iso " << m.isometry_error << " shift " << m.time_shift_error
              << " ret " << m.return_error << " det " << (m.ok ? m.K.determinant() : 0) << "\n";
    if (m.ok) {
      Eigen::EigenSolver<Eigen::MatrixXd> es(m.K);
      for (auto e : es.eigenvalues()) std::cout << fmt::format(" ({:.6f},{:.6f})|{:.3e}|", e.real(), e.imag(), std::abs(e) - 1);
      std::cout << "\n";
    }
  };
  bar::BarSetup s = paper();
  for (double f : {1.01, 1.5, 10.0, 100.0}) {
    contact_bar::ContactFamily fam(s.material, 1e-3, 2);
    const double E = f * fam.grazing_energy();
    s.u0 = fam.u0(E);
    report(fmt::format("mode2 E/Eg={}", f).c_str(), s, fam.period(E));
  }
  for (double shape : {0.05, 0.25, 0.5, 0.75, 0.95}) {
    contact_bar::ContactFamily fam(s.material, 1e-3, 2);
    const double E = 3 * fam.grazing_energy();
    auto m = contact_bar::subharmonic_member(s.material, 1e-3, E, shape);
    s.u0 = m.u0;
    report(fmt::format("subh shape={}", shape).c_str(), s, m.period);
  }
  for (double gb : {1e-3, 3e-3}) for (int J : {1, 2}) {
    bar::BarSetup c = paper();
    c.right = {bar::EndType::clearance, 1e-3, gb};
    contact_bar::ClearanceMode m(c.material, 1e-3, gb, J);
    for (double f : {2.0, 20.0}) {
      const double E = f * m.back_grazing_energy();
      c.u0 = m.u0(E);
      report(fmt::format("clear gb={} J={} f={}", gb, J, f).c_str(), c, m.period(E));
    }
  }
}
TEST(FrontMonodromy, Explore3) {
  bar::BarSetup s = paper();
  for (double E : {2.4e-3, 2.9e-3, 1e-2, 1.0}) {
    contact_bar::ContactFamily fam(s.material, 1e-3, 2);
    s.u0 = fam.u0(E);
    const double T = fam.period(E);
    exact_bar::ExactBarSolution orbit(s, 2 * T);
    auto os = exact_bar::free_flight_state(orbit, T);
    auto m = exact_bar::front_monodromy(s, os.state, T);
    std::cout << "E=" << E << " t0 " << os.t0 << "\n" << m.K << "\n";
    for (double x : os.state.a_start) std::cout << x << " "; std::cout << "| ";
    for (double x : os.state.b_start) std::cout << x << " "; std::cout << "\n";
  }
}
