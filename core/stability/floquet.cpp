#include "core/stability/floquet.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "core/errors.hpp"

namespace backbone::core {

namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();

// A multiplier counts as real when its imaginary part is below this share of its modulus (an
// eigenvalue solver returns a real pair of a real matrix with imaginary parts of exactly 0, a
// complex pair with parts far above it).
constexpr double real_share = 1e-10;

}  // namespace

void FloquetOptions::validate() const {
  if (!(tolerance > 0 && tolerance < 0.1))
    throw InputError("floquet_tolerance", fmt::format("must be in (0, 0.1) (got {})", tolerance));
  if (!(trivial_tolerance > 0 && trivial_tolerance < 0.5))
    throw InputError("floquet_trivial_tolerance",
                     fmt::format("must be in (0, 0.5) (got {})", trivial_tolerance));
}

Floquet undecided_floquet(int size) {
  Floquet f;
  f.multipliers.assign(size, {nan, nan});
  f.trivial.assign(size, false);
  f.max_modulus = f.trivial_distance = f.determinant = f.pairing_error = nan;
  f.period_doubling_test = f.fold_test = f.torus_test = nan;
  return f;
}

Floquet analyse_monodromy(const Matrix& M, const FloquetStructure& structure,
                          const FloquetOptions& options) {
  const auto n = static_cast<int>(M.rows());
  if (M.rows() != M.cols() || n == 0 || !M.allFinite()) return undecided_floquet(n);
  Eigen::EigenSolver<Matrix> solver(M, /*computeEigenvectors=*/false);
  if (solver.info() != Eigen::Success) return undecided_floquet(n);
  Floquet f;
  f.multipliers.assign(solver.eigenvalues().begin(), solver.eigenvalues().end());
  // By decreasing modulus, then by argument, so that a row order does not depend on the solver.
  std::sort(f.multipliers.begin(), f.multipliers.end(),
            [](std::complex<double> a, std::complex<double> b) {
              if (std::abs(a) != std::abs(b)) return std::abs(a) > std::abs(b);
              return std::arg(a) < std::arg(b);
            });
  f.determinant = M.determinant();
  if (!std::isfinite(f.determinant)) {
    // LU's product of pivots overflows on a large M whose rows carry different units (the
    // contact bar's u and v rows): the product of the multipliers, by decreasing modulus
    // interleaved with the smallest so that it stays in range, is the same number.
    std::complex<double> product = 1;
    for (int i = 0, j = n - 1; i <= j; ++i, --j) {
      product *= f.multipliers[static_cast<std::size_t>(i)];
      if (j != i) product *= f.multipliers[static_cast<std::size_t>(j)];
    }
    f.determinant = product.real();
  }

  // The trivial ones: the structure's count nearest to +1.
  f.trivial.assign(n, false);
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return std::abs(f.multipliers[a] - 1.0) < std::abs(f.multipliers[b] - 1.0);
  });
  const int trivial = std::min(structure.trivial, n);
  for (int k = 0; k < trivial; ++k) {
    f.trivial[order[k]] = true;
    f.trivial_distance = std::max(f.trivial_distance, std::abs(f.multipliers[order[k]] - 1.0));
  }

  f.max_modulus = nan;
  f.torus_test = nan;
  // Over a real M's non-trivial multipliers, closed under conjugation: the products are real.
  std::complex<double> doubling = 1, fold = 1;
  for (int i = 0; i < n; ++i) {
    if (f.trivial[i]) continue;
    const std::complex<double> mu = f.multipliers[i];
    const double modulus = std::abs(mu);
    f.max_modulus = std::isnan(f.max_modulus) ? modulus : std::max(f.max_modulus, modulus);
    const double weight = std::max(1.0, modulus);
    doubling *= (mu + 1.0) / weight;
    fold *= (mu - 1.0) / weight;
    if (std::abs(mu.imag()) > real_share * modulus)
      f.torus_test = std::isnan(f.torus_test) ? modulus - 1 : std::max(f.torus_test, modulus - 1);
    if (modulus > 1 + options.tolerance) {
      ++f.unstable;
      if (std::abs(mu.imag()) > real_share * modulus)
        ++f.outside.complex;
      else if (mu.real() > 0)
        ++f.outside.real_positive;
      else
        ++f.outside.real_negative;
    }
  }
  f.period_doubling_test = doubling.real();
  f.fold_test = fold.real();
  f.pairing_error = nan;
  if (structure.conservative) {
    f.pairing_error = 0;
    for (int i = 0; i < n; ++i) {
      double best = std::numeric_limits<double>::infinity();
      for (int j = 0; j < n; ++j)
        best = std::min(best, std::abs(f.multipliers[i] * f.multipliers[j] - 1.0));
      f.pairing_error = std::max(f.pairing_error, best);
    }
  }
  if (f.trivial_distance > options.trivial_tolerance)
    f.stable = -1;
  else
    f.stable = f.unstable == 0 ? 1 : 0;
  return f;
}

std::optional<Floquet> floquet_at(const Problem& problem, const Vector& x,
                                  const FloquetOptions& options) {
  const auto* orbit = dynamic_cast<const FloquetProblem*>(&problem);
  if (!orbit) return std::nullopt;
  Matrix M;
  if (orbit->monodromy(x, M) != EvalStatus::ok) return undecided_floquet(0);
  return analyse_monodromy(M, orbit->floquet_structure(), options);
}

}  // namespace backbone::core
