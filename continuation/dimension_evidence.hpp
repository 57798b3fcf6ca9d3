// The dimension of the solution set at one point, with its evidence: the singular values of the
// column-scaled Jacobian, the threshold and the gap of the rank report, then every probe along
// a candidate null direction (core/rank/rank_report.hpp) with the distance the re-corrected point
// kept from the stepped one. Generic over core::Problem; `backbone inspect` prints it
// (continuation/cli/inspect.hpp).
//
//   core::RankOptions rank; rank.relative_threshold = 1e-5;
//   const DimensionEvidence e = dimension_evidence(problem, x, rank, core::VerifyOptions{});
//   fmt::print("{}", e.text());     // "dimension 2 (candidates 2) ..." then one line per probe
//   int d = e.report.verified_dimension;
#pragma once

#include <string>
#include <vector>

#include "core/problem.hpp"
#include "core/rank/rank_report.hpp"

namespace backbone::continuation {

struct NullProbe {
  bool converged = false;  // the re-corrected point reached VerifyOptions::residual_tolerance
  double residual = 0;     // ||F||_inf there
  double drift = 0;        // |corrected - stepped| / step, scaled units (real if <= drift_ratio)
  bool real = false;       // verified: a neighbour exists along this direction
  double side = 1;         // the side shown: +1, or -1 when +d found no neighbour
};

struct DimensionEvidence {
  core::RankReport report;  // on the column-scaled Jacobian (x ./ typical_scale)
  double step = 0;          // probe step (scaled units)
  double drift_ratio = 0;
  std::vector<NullProbe> probes;  // one per (rotated) candidate null direction
  // The candidates came from J a probe step towards the neighbour (core::rank_report_beside),
  // because J(x) verified fewer directions: F is not differentiable at x.
  bool beside = false;
  double seconds = 0;
  std::string text() const;  // the report `backbone inspect` prints
};

// Never throws on numerical failure (a failed Jacobian gives an empty report, dimension -1).
// neighbour: another point of the same family (unknowns of the problem, e.g. the next member of
// a branch) or empty. With it, the candidates of J one probe step along the chord towards it,
// on either side, are verified too, and kept when they verify more directions (beside).
DimensionEvidence dimension_evidence(const core::Problem& problem, const core::Vector& x,
                                     const core::RankOptions& rank,
                                     const core::VerifyOptions& verify,
                                     const core::Vector& neighbour = {});

}  // namespace backbone::continuation
