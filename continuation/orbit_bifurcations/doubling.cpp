#include "continuation/orbit_bifurcations/doubling.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>

#include "continuation/methods/pseudo_arclength.hpp"
#include "core/solvers/bordered_system.hpp"
#include "core/stability/floquet.hpp"

namespace backbone::continuation {

DoubledBranch follow_period_doubling(const core::Problem& problem, const OrbitBifurcation& doubling,
                                     core::Corrector& corrector, const ContinuationOptions& options,
                                     const ContinuationHooks& hooks) {
  DoubledBranch d;
  const auto* orbit = dynamic_cast<const core::FloquetProblem*>(&problem);
  if (!orbit) {
    d.message = "the problem gives no monodromy: no switch";
    return d;
  }
  d.problem = orbit->doubled_problem();
  if (!d.problem) {
    d.message = fmt::format("{} has no problem of twice the period: no switch", problem.name());
    return d;
  }
  const core::Vector& x = doubling.x;
  core::Matrix M, J;
  if (orbit->monodromy(x, M) != core::EvalStatus::ok ||
      problem.jacobian(x, J) != core::EvalStatus::ok) {
    d.message = "the monodromy or the Jacobian at the period doubling could not be evaluated";
    return d;
  }
  // The eigenvector of the multiplier nearest -1 (real for a real multiplier).
  Eigen::EigenSolver<core::Matrix> eigen(M);
  Eigen::Index nearest = 0;
  for (Eigen::Index i = 1; i < eigen.eigenvalues().size(); ++i)
    if (std::abs(eigen.eigenvalues()[i] + 1.0) < std::abs(eigen.eigenvalues()[nearest] + 1.0))
      nearest = i;
  const Eigen::Index n = M.rows();
  core::Vector w = core::Vector::Zero(x.size());
  w.head(n) = eigen.eigenvectors().col(nearest).real();
  // The period-1 tangent: J's right singular vector of the smallest singular value.
  Eigen::JacobiSVD<core::Matrix> svd(J, Eigen::ComputeFullV);
  const core::Vector t = svd.matrixV().col(svd.matrixV().cols() - 1);
  w -= w.dot(t) * t;
  if (!(w.norm() > 0)) {
    d.message = "the doubling direction lies along the period-1 branch: no switch";
    return d;
  }
  w.normalize();
  const core::Vector x2 = orbit->doubled_unknowns(x);
  const double size = std::max(x.head(n).lpNorm<Eigen::Infinity>(), 1e-8);
  core::Vector r;
  for (const double fraction : {1e-2, 2.5e-3, 6.25e-4}) {
    const core::Vector guess = x2 + fraction * size * w;
    core::BorderedSystem system(*d.problem, {core::BorderRow::hyperplane(w, guess)});
    core::Vector y = guess;
    if (!corrector.solve(system, y).converged()) continue;
    // Still an orbit of period 1: the switch fell back onto the traced branch.
    if (problem.residual(y, r) == core::EvalStatus::ok && r.lpNorm<Eigen::Infinity>() < 1e-6)
      continue;
    d.start = y;
    break;
  }
  if (d.start.size() == 0) {
    d.message = "no orbit of twice the period was corrected next to the period doubling";
    return d;
  }
  ContinuationOptions o = options;
  o.method = Method::arclength;
  o.branch_points.detect = false;
  d.branch = pseudo_arclength(*d.problem, d.start, d.start - x2, corrector, o, hooks);
  d.message = d.branch.message;
  return d;
}

}  // namespace backbone::continuation
