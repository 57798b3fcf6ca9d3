// Compressed (Curtis-Powell-Reid) finite-difference Jacobians: one residual per group of
// structurally independent columns instead of one per column.
//
// Columns that share no row of a JacobianPattern (core/problem.hpp) get the same colour
// (greedy colouring, largest column first); all columns of a colour are stepped together and
// each entry J_ij is read off row i of that colour's difference, which no other column of the
// colour touches. Dense columns get a colour each. Steps, schemes and threads are those of
// finite_difference.hpp, and each colour is assembled by the same operations whatever the
// thread count, so the result is bit-identical to one thread's. With a correct pattern every
// entry equals the column-by-column difference up to round-off.
// Verification at each use: one more residual along a fixed pseudo-random direction p
// (p_j = +-(1..2) h_j, the same for every x) compares J p with F(x + p) - F(x); a pattern that
// misses an entry J_ij shows up there as |J_ij| h_j (the tolerance is in the .cpp). On failure
// the Jacobian is recomputed from pattern.wider when there is one (report->widened, checked
// the same way), else column by column (report->fell_back), except for a structural pattern
// inside a corrector's scope, whose J is kept (report->kept_unchecked).
//
//   JacobianPattern pattern;                 // tridiagonal 5 x 5: 3 colours instead of 5
//   for (int i = 0; i < 5; ++i) for (int j = i - 1; j <= i + 1; ++j)
//       if (j >= 0 && j < 5) pattern.row_columns.resize(5), pattern.row_columns[i].push_back(j);
//   CompressedJacobianReport report;
//   compressed_finite_difference_jacobian(problem, x, pattern, J, {}, &report);
//   // report.colours == 3, report.residuals == 5 (F(x), 3 colours, the check), !report.fell_back
#pragma once

#include <vector>

#include "core/jacobians/finite_difference.hpp"
#include "core/problem.hpp"

namespace backbone::core {

struct CompressedJacobianReport {
  int colours = 0;         // residuals for the columns (dense columns included)
  int residuals = 0;       // all residuals this call took (F(x), colours, check, any fallback)
  bool widened = false;    // the check failed and pattern.wider was used (checked the same way)
  bool fell_back = false;  // the check failed (or a coloured step could not be evaluated):
                           // J is the column-by-column finite-difference Jacobian
  double check_error = 0;  // max_i |(J p)_i - (F(x + p) - F(x))_i| / tolerance_i
  // The check failed on a structural pattern (JacobianPattern::structural, the widest one
  // tried) inside a corrector's scope: J is that pattern's, kept as it is.
  bool kept_unchecked = false;
};

// Greedy colouring of the columns of `pattern` (n columns): colour[j] for each column, two
// columns with a common row (dense columns share every row) never share a colour. Throws
// InputError("jacobian_pattern") when a row count or a column index does not fit m x n.
std::vector<int> colour_columns(const JacobianPattern& pattern, int m, int n);

// J (m x n) from pattern at x. Returns the status of F(x) or of the fallback; options.scheme
// central takes two residuals per colour.
EvalStatus compressed_finite_difference_jacobian(const Problem& problem, const Vector& x,
                                                 const JacobianPattern& pattern, Matrix& J,
                                                 const FiniteDifferenceOptions& options = {},
                                                 CompressedJacobianReport* report = nullptr);

// While one is alive, the compressed Jacobians computed on this thread accept a check error up
// to `tolerance` of a row where their pattern asks for less (JacobianPattern::check_tolerance):
// for a corrector, whose answer is judged by F alone, so that an entry of 1e-3 of its row
// costs at most a slower contraction, not a wider pattern (core/README.md, 'Compressed
// Jacobians'). Nested scopes: the innermost holds.
//
//   { CorrectorJacobians loose(1e-2); problem.jacobian(x, J); }  // checked to 1e-2 only
class CorrectorJacobians {
 public:
  explicit CorrectorJacobians(double tolerance);
  ~CorrectorJacobians();
  CorrectorJacobians(const CorrectorJacobians&) = delete;
  CorrectorJacobians& operator=(const CorrectorJacobians&) = delete;
  // The tolerance in force on this thread (0: none, the patterns' own).
  static double tolerance();

 private:
  double outer_;
};

}  // namespace backbone::core
