#include "continuation/dimension_evidence.hpp"

#include <fmt/format.h>

#include <chrono>

#include "continuation/scaled_problem.hpp"

namespace backbone::continuation {

std::string DimensionEvidence::text() const {
  std::string s = fmt::format("dimension {} (candidates {}, rank {} of {} unknowns)\n",
                              report.verified_dimension, report.nullity, report.rank,
                              report.rank + report.nullity);
  s += fmt::format(
      "threshold {:.3e} = max({:.1e} x sigma_max, floor), gap sigma_rank / "
      "sigma_rank+1 = {:.3e}\n",
      report.threshold, report.relative_threshold, report.gap);
  if (beside)
    s += "candidates from J one probe step towards the neighbouring point (J here verified "
         "fewer: F is not differentiable here)\n";
  s += "singular values (relative to sigma_max), smallest kept and all dropped:\n";
  const auto n = report.singular_values.size();
  const double top = n > 0 ? report.singular_values[0] : 1.0;
  for (Eigen::Index i = std::max<Eigen::Index>(0, report.rank - 3); i < n; ++i)
    s += fmt::format("  sigma_{:<3d} {:.6e}  {:.3e}  {}\n", i + 1, report.singular_values[i],
                     report.singular_values[i] / top, i < report.rank ? "kept" : "dropped");
  s += fmt::format("probes (step {:g} scaled units along +d, else -d; real when drift <= {:g}):\n",
                   step, drift_ratio);
  for (std::size_t i = 0; i < probes.size(); ++i)
    s += fmt::format("  direction {} ({}): {}, residual {:.2e}, drift {:.3e}: {}\n", i + 1,
                     probes[i].side > 0 ? "+" : "-",
                     probes[i].converged ? "re-corrected" : "not re-corrected", probes[i].residual,
                     probes[i].drift, probes[i].real ? "neighbour found" : "no neighbour");
  s += fmt::format("{:.2f} s\n", seconds);
  return s;
}

DimensionEvidence dimension_evidence(const core::Problem& problem, const core::Vector& x,
                                     const core::RankOptions& rank,
                                     const core::VerifyOptions& verify,
                                     const core::Vector& neighbour) {
  const auto start = std::chrono::steady_clock::now();
  DimensionEvidence e;
  e.step = verify.step;
  e.drift_ratio = verify.drift_ratio;
  const ScaledProblem scaled(problem);
  const core::Vector z = scaled.to_scaled(x);
  core::Matrix J;
  if (scaled.jacobian(z, J) != core::EvalStatus::ok) return e;
  e.report = core::rank_report(J, rank);
  auto verifier = core::make_verifier(verify, rank);
  core::verify_null_directions(scaled, z, *verifier, verify, e.report);
  if (neighbour.size() == x.size()) {
    core::RankReport beside =
        core::rank_report_beside(scaled, z, scaled.to_scaled(neighbour) - z, verify.step, rank);
    if (beside.nullity > e.report.verified_dimension) {
      core::verify_null_directions(scaled, z, *verifier, verify, beside);
      if (beside.verified_dimension > e.report.verified_dimension) {
        e.report = std::move(beside);
        e.beside = true;
      }
    }
  }
  // The distances along the final (possibly rotated) basis: the probes verify ran, repeated, on
  // the same sides: +d, then -d when +d finds no neighbour (at a point on the boundary of the
  // solution set only one side holds solutions).
  for (Eigen::Index i = 0; i < e.report.null_directions.cols(); ++i) {
    const core::Vector d = e.report.null_directions.col(i);
    core::NeighbourProbe found =
        core::probe_neighbour(scaled, z, d, verify.step, *verifier, verify);
    double side = 1;
    if (!found.found) {
      core::NeighbourProbe back =
          core::probe_neighbour(scaled, z, d, -verify.step, *verifier, verify);
      if (back.found) found = back, side = -1;
    }
    NullProbe p;
    p.converged = found.converged;
    p.residual = found.residual;
    p.drift = found.drift;
    p.side = side;
    p.real = e.report.direction_verified[static_cast<std::size_t>(i)];
    e.probes.push_back(p);
  }
  e.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return e;
}

}  // namespace backbone::continuation
