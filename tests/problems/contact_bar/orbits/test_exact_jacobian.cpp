// The Jacobian of the regular shooting residual from the exact solution's tangent
// (OrbitOptions::exact_jacobian; problems/exact_bar/README.md, 'Tangent') against central
// finite differences, at points away from kinks: mode 1 (no free knot), mode 2 (one knot on
// its crest), a member of the subharmonic continuum and a clearance mode (started on the wall,
// knots), with the exact solver and the TD-BEM.
#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <cmath>
#include <functional>
#include <memory>

#include "core/jacobians/finite_difference.hpp"
#include "problems/contact_bar/orbits/family.hpp"
#include "problems/contact_bar/orbits/periodic_bar.hpp"
#include "problems/contact_bar/solver/tdbem.hpp"
#include "problems/exact_bar/exact_bar_solver.hpp"
#include "problems/exact_bar/exact_solution.hpp"

namespace backbone::contact_bar {
namespace {

struct Case {
  const char* name;
  bar::BarSetup setup;
  OrbitOptions options;
  std::function<core::Vector(const ContactBarOrbitProblem&)> point;
};

// The paper's bar (gap 1e-3) and its shooting grid of 20 intervals, 40 test elements.
bar::BarSetup one_wall() {
  bar::BarSetup s;
  s.left = {bar::EndType::fixed, 0};
  s.right = {bar::EndType::contact, 1e-3};
  return s;
}
OrbitOptions grid_of_twenty() {
  OrbitOptions o;
  o.elements = 20;
  o.steps_per_period = 40;
  o.test_elements = 40;
  return o;
}

std::vector<Case> cases() {
  std::vector<Case> out;
  const OrbitOptions o = grid_of_twenty();
  out.push_back({"mode 1", one_wall(), o,
                 [](const ContactBarOrbitProblem& p) { return p.contact_family_guess(1, 1.7); }});
  OrbitOptions o2 = o;
  o2.free_knots = 1;
  o2.knot_node = 6;
  o2.test_elements = 42;
  out.push_back({"mode 2", one_wall(), o2,
                 [](const ContactBarOrbitProblem& p) { return p.contact_family_guess(2, 2.3); }});
  OrbitOptions os = o;
  os.start_on_wall = true;
  os.free_knots = 2;
  os.knot_nodes = {7, 19};
  out.push_back({"subharmonic member", one_wall(), os,
                 [](const ContactBarOrbitProblem& p) { return p.subharmonic_guess(1e-4, 0.3); }});
  bar::BarSetup clearance = one_wall();
  clearance.right = {bar::EndType::clearance, 1e-3, 3e-3};
  OrbitOptions oc = o;
  oc.start_on_wall = true;
  oc.free_knots = 1;
  oc.knot_nodes = {11};
  oc.test_elements = 40;
  out.push_back({"clearance mode 1", clearance, oc,
                 [](const ContactBarOrbitProblem& p) { return p.clearance_guess(1, 2e-5); }});
  return out;
}

TEST(ExactJacobian, MatchesCentralDifferencesAwayFromKinks) {
  for (const Case& c : cases()) {
    for (bool exact_solver : {true, false}) {
      std::shared_ptr<const bar::BarSolver> solver;
      if (exact_solver)
        solver = std::make_shared<exact_bar::ExactBarSolver>();
      else
        solver = std::make_shared<TdbemSolver>(ContactMethod::event);
      OrbitOptions o = c.options;
      o.exact_jacobian = true;
      ContactBarOrbitProblem p(c.setup, solver, o);
      ASSERT_TRUE(p.exact_jacobian_applies());
      core::Vector x = c.point(p);
      // Off the closed form (a rough u0, a period off the orbit's): a generic state.
      for (int i = 0; i < p.options().nodal_unknowns(); ++i) x[i] += 2e-5 * std::sin(1.7 * i + 0.3);
      x[p.period_index()] *= 1.003;
      core::Matrix exact, fd;
      ASSERT_EQ(p.jacobian(x, exact), core::EvalStatus::ok) << c.name;
      core::FiniteDifferenceOptions central;
      central.scheme = core::FiniteDifferenceOptions::Scheme::central;
      central.relative_step = 1e-6;
      ASSERT_EQ(core::finite_difference_jacobian(p, x, fd, central), core::EvalStatus::ok);
      const double scale = fd.cwiseAbs().maxCoeff();
      const double worst = (exact - fd).cwiseAbs().maxCoeff();
      // Central differences with a step of 1e-6 of each unknown: truncation about 1e-12 and
      // round-off about 1e-16 / 1e-6 of the largest entry (measured: at most 3.4e-10 relative);
      // a wrong event or front derivative shows at 1e-1 (the jump of v times the front's
      // motion), so 1e-7 separates the two.
      EXPECT_LT(worst / scale, 1e-7) << c.name << (exact_solver ? " exact" : " tdbem");
    }
  }
}

// On mode 1's closed-form orbits, where at T/2 the front of the closing and the front of the
// release coincide (they pass through each other: the map is smooth there): the exact Jacobian
// against central differences, and the closed-form tangent d x / d amplitude in its null space
// (the branch is a curve: J t = 0 exactly). Forward differences leave |J t| / |J| about 1e-10.
TEST(ExactJacobian, AnnihilatesModeOnesTangentOnItsClosedForm) {
  OrbitOptions o = grid_of_twenty();
  o.exact_jacobian = true;
  ContactBarOrbitProblem p(one_wall(), std::make_shared<TdbemSolver>(ContactMethod::event), o);
  for (double ratio : {1.7, 2.2, 3.0}) {
    const core::Vector x = p.contact_family_guess(1, ratio);
    core::Vector t = p.contact_family_guess(1, ratio * (1 + 1e-6)) -
                     p.contact_family_guess(1, ratio * (1 - 1e-6));
    t /= t.norm();  // u0 = -s x and T = 3 + g0/s: central differences of a rational curve
    core::Matrix exact, fd;
    ASSERT_EQ(p.jacobian(x, exact), core::EvalStatus::ok);
    core::FiniteDifferenceOptions central;
    central.scheme = core::FiniteDifferenceOptions::Scheme::central;
    central.relative_step = 1e-6;
    ASSERT_EQ(core::finite_difference_jacobian(p, x, fd, central), core::EvalStatus::ok);
    const double scale = fd.cwiseAbs().maxCoeff();
    EXPECT_LT((exact - fd).cwiseAbs().maxCoeff() / scale, 1e-7) << ratio;
    // t from differences of the closed form (error 1e-12 relative): |J t| at that level.
    EXPECT_LT((exact * t).norm() / exact.norm(), 1e-11) << ratio;
  }
}

// Mode 1 at T = 3.8 L/c (end amplitude 1.25 g0, the bench's start) is a branch point: with
// 2 / T = p / q = 10 / 19 the warps u0 = u0(L) (x + sum_j a_j sin(j p pi x)) are orbits of the
// same period (orbits/README.md, 'Dimension changes'), and a grid of 40 intervals holds
// ceil(40 / 10) - 1 = 3 of them. The closing at 1 + g0 / s = 1.8 L/c meets the echo of node 32
// (x = 0.8 L), a front of no strength, where the tangent must take the closing's own motion.
// The law's directions are the independent oracle: J annihilates them and the mode's tangent,
// and nothing else.
TEST(ExactJacobian, AnnihilatesTheAttachedWarpsAtABranchPoint) {
  OrbitOptions o = grid_of_twenty();
  o.elements = 40;
  o.test_elements = 80;
  o.exact_jacobian = true;
  ContactBarOrbitProblem p(one_wall(), std::make_shared<TdbemSolver>(ContactMethod::event), o);
  const double ratio = 1.25;
  const core::Vector x = p.contact_family_guess(1, ratio);
  ASSERT_DOUBLE_EQ(x[p.period_index()], 3.8);
  // The closing meets a front without a jump: no kink of the map.
  EXPECT_TRUE(exact_bar::ExactBarSolution(p.setup_at(x), 3.8).closings_on_fronts().empty());
  core::Matrix J;
  ASSERT_EQ(p.jacobian(x, J), core::EvalStatus::ok);
  std::vector<core::Vector> family;
  core::Vector t =
      p.contact_family_guess(1, ratio * (1 + 1e-6)) - p.contact_family_guess(1, ratio * (1 - 1e-6));
  family.push_back(t / t.norm());
  for (int j = 1; j <= 3; ++j) {
    core::Vector d = core::Vector::Zero(x.size());
    for (int i = 0; i < o.elements; ++i)  // node i + 1 at x = (i + 1) / 40 (L = 1)
      d[i] = std::sin(j * 10 * M_PI * (i + 1) / 40.0);
    family.push_back(d / d.norm());
  }
  const double norm = J.norm();
  // Each direction is exact to round-off (t: central differences of a rational curve, 1e-12),
  // so |J d| sits at round-off of |J|. A closing moved with the front instead leaves
  // |J t| / |J| = 3.5e-4 and a fifth singular value of 1e-3 |J|.
  for (std::size_t k = 0; k < family.size(); ++k)
    EXPECT_LT((J * family[k]).norm() / norm, 1e-11) << "direction " << k;
  // Nothing else: the fifth smallest singular value, 2.3e-2 |J|, is the grid spectrum.
  const Eigen::VectorXd sv = Eigen::JacobiSVD<core::Matrix>(J).singularValues();
  const Eigen::Index n = sv.size();
  EXPECT_LT(sv[n - 4] / sv[0], 1e-12);
  EXPECT_GT(sv[n - 5] / sv[0], 1e-2);
}

// Two tangents of one map: the TD-BEM march's own (OrbitOptions::tdbem_jacobian: the march's
// derivative in the grid's hats, the period column from the field's time derivative) and the
// exact solution's. The event march reproduces the exact solution on shooting states, so off
// kinks the two are the same matrix up to round-off (measured at most 1.8e-14 of the largest
// entry here: 1e-12 asserted; a missed front or event term shows at 1e-2 or more). Mode 1 at
// 20 intervals at three amplitudes, on the closed form, whose tangent the TD-BEM's Jacobian
// annihilates too, and moved off it.
TEST(ExactJacobian, TheTdbemTangentGivesTheSameJacobian) {
  const auto solver = std::make_shared<TdbemSolver>(ContactMethod::event);
  OrbitOptions exact_options = grid_of_twenty(), tdbem_options = grid_of_twenty();
  exact_options.exact_jacobian = true;
  tdbem_options.tdbem_jacobian = true;
  const ContactBarOrbitProblem by_exact(one_wall(), solver, exact_options);
  const ContactBarOrbitProblem by_tdbem(one_wall(), solver, tdbem_options);
  ASSERT_TRUE(by_tdbem.tdbem_jacobian_applies());
  EXPECT_EQ(by_tdbem.jacobian_description(), "tdbem");
  for (double ratio : {1.7, 2.2, 3.0}) {
    for (double wiggle : {0.0, 2e-5}) {
      core::Vector x = by_exact.contact_family_guess(1, ratio);
      for (int i = 0; i < 20; ++i) x[i] += wiggle * std::sin(1.7 * i + 0.3);
      if (wiggle > 0) x[by_exact.period_index()] *= 1.003;
      core::Matrix a, b;
      ASSERT_EQ(by_exact.jacobian(x, a), core::EvalStatus::ok);
      ASSERT_EQ(by_tdbem.jacobian(x, b), core::EvalStatus::ok);
      const double scale = a.cwiseAbs().maxCoeff();
      EXPECT_LT((a - b).cwiseAbs().maxCoeff() / scale, 1e-12) << ratio << " " << wiggle;
      if (wiggle > 0) continue;
      core::Vector t = by_exact.contact_family_guess(1, ratio * (1 + 1e-6)) -
                       by_exact.contact_family_guess(1, ratio * (1 - 1e-6));
      t /= t.norm();  // as in AnnihilatesModeOnesTangentOnItsClosedForm
      EXPECT_LT((b * t).norm() / b.norm(), 1e-11) << ratio;
    }
  }
}

}  // namespace
}  // namespace backbone::contact_bar
