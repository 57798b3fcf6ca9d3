#include "core/rank/rank_report.hpp"

#include <fmt/format.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/errors.hpp"
#include "core/rank/few_singular_values.hpp"

namespace backbone::core {

void RankOptions::validate() const {
  if (!(relative_threshold > 0 && relative_threshold < 1))
    throw InputError("rank.relative_threshold",
                     fmt::format("must be in (0, 1) (got {})", relative_threshold));
  if (!(absolute_threshold >= 0) || !std::isfinite(absolute_threshold))
    throw InputError("rank.absolute_threshold",
                     fmt::format("must be finite and >= 0 (got {})", absolute_threshold));
}

namespace {

// threshold, rank, nullity and gap from the descending singular values (entry 0 sigma_max;
// entries not computed are NaN and count as kept).
void count_rank(RankReport& report, const RankOptions& options, Eigen::Index n) {
  const Vector& sv = report.singular_values;
  const double sigma_max = sv.size() > 0 ? sv[0] : 0.0;
  report.threshold = std::max(options.relative_threshold * sigma_max, options.absolute_threshold);
  int rank = 0;
  for (Eigen::Index i = 0; i < sv.size(); ++i)
    if (!(sv[i] <= report.threshold)) ++rank;  // NaN (not computed) lies above the threshold
  report.rank = rank;
  report.nullity = static_cast<int>(n) - rank;
  if (rank == 0) {
    report.gap = 0;
  } else if (rank < sv.size() && sv[rank] > 0) {
    report.gap = sv[rank - 1] / sv[rank];
  } else {
    report.gap = std::numeric_limits<double>::infinity();
  }
}

}  // namespace

RankReport rank_report(const Matrix& J, const RankOptions& options) {
  options.validate();
  const Eigen::Index n = J.cols();
  RankReport report;
  report.relative_threshold = options.relative_threshold;
  SmallestSingularValues few;
  if (!options.full_spectrum &&
      smallest_singular_values(J, options.relative_threshold, options.absolute_threshold, few)) {
    report.singular_values = Vector::Constant(n, std::numeric_limits<double>::quiet_NaN());
    report.singular_values[0] = few.largest;
    report.singular_values.tail(few.values.size()) = few.values;
    count_rank(report, options, n);
    report.null_directions = few.right.rightCols(report.nullity);
    return report;
  }
  // Full V: for m < n the null space includes the n - m directions without a singular value.
  Eigen::BDCSVD<Matrix> svd(J, Eigen::ComputeFullV);
  report.singular_values = svd.singularValues();
  count_rank(report, options, n);
  report.null_directions = svd.matrixV().rightCols(report.nullity);
  return report;
}

std::string RankReport::summary() const {
  const double sigma_max = singular_values.size() > 0 ? singular_values[0] : 0.0;
  const std::string verified =
      verified_dimension >= 0 ? fmt::format(" (verified {})", verified_dimension) : "";
  return fmt::format(
      "rank {}/{}, nullity {}{}, sigma_max {:.3e}, threshold {:.3e} (relative {:.1e}), gap "
      "{:.3e}",
      rank, rank + nullity, nullity, verified, sigma_max, threshold, relative_threshold, gap);
}

RankReport rank_report_beside(const Problem& problem, const Vector& x, const Vector& into,
                              double step, const RankOptions& options) {
  RankReport best;
  best.null_directions = Matrix(x.size(), 0);
  const double norm = into.norm();
  if (into.size() != x.size() || !(norm > 0) || !std::isfinite(norm)) return best;
  for (const double side : {1.0, -1.0}) {
    Matrix J;
    if (problem.jacobian(x + (side * step / norm) * into, J) != EvalStatus::ok) continue;
    RankReport there = rank_report(J, options);
    if (there.nullity > best.nullity) best = std::move(there);
  }
  return best;
}

}  // namespace backbone::core
