#include "core/jacobians/compressed_jacobian.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>

#include "core/errors.hpp"

namespace backbone::core {

namespace {

// The pattern by columns, and the colouring.
struct Colouring {
  std::vector<std::vector<int>> column_rows;  // rows of each sparse column (empty for dense)
  std::vector<char> dense;
  std::vector<int> colour;  // -1: a column without rows (J_.j = 0, no residual)
  int colours = 0;
};

Colouring colour(const JacobianPattern& pattern, int m, int n) {
  if (static_cast<int>(pattern.row_columns.size()) != m)
    throw InputError("jacobian_pattern", fmt::format("needs one column list per equation, {} "
                                                     "(got {})",
                                                     m, pattern.row_columns.size()));
  Colouring c;
  c.column_rows.resize(static_cast<std::size_t>(n));
  c.dense.assign(static_cast<std::size_t>(n), 0);
  c.colour.assign(static_cast<std::size_t>(n), -1);
  auto check_column = [n](int j) {
    if (j < 0 || j >= n)
      throw InputError("jacobian_pattern",
                       fmt::format("column indices must be in 0..{} (got {})", n - 1, j));
  };
  for (int j : pattern.dense_columns) {
    check_column(j);
    c.dense[static_cast<std::size_t>(j)] = 1;
  }
  for (int i = 0; i < m; ++i)
    for (int j : pattern.row_columns[static_cast<std::size_t>(i)]) {
      check_column(j);
      std::vector<int>& rows = c.column_rows[static_cast<std::size_t>(j)];
      if (!c.dense[static_cast<std::size_t>(j)] && (rows.empty() || rows.back() != i))
        rows.push_back(i);
    }
  // Largest column first (ties by index): the usual greedy order, deterministic.
  std::vector<int> order;
  for (int j = 0; j < n; ++j)
    if (!c.dense[static_cast<std::size_t>(j)] &&
        !c.column_rows[static_cast<std::size_t>(j)].empty())
      order.push_back(j);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return c.column_rows[static_cast<std::size_t>(a)].size() >
           c.column_rows[static_cast<std::size_t>(b)].size();
  });
  std::vector<int> forbidden_by(static_cast<std::size_t>(n) + 1, -1);  // colour -> column
  for (int j : order) {
    for (int i : c.column_rows[static_cast<std::size_t>(j)])
      for (int k : pattern.row_columns[static_cast<std::size_t>(i)]) {
        const int ck = c.colour[static_cast<std::size_t>(k)];
        if (ck >= 0 && !c.dense[static_cast<std::size_t>(k)])
          forbidden_by[static_cast<std::size_t>(ck)] = j;
      }
    int free_colour = 0;
    while (forbidden_by[static_cast<std::size_t>(free_colour)] == j) ++free_colour;
    c.colour[static_cast<std::size_t>(j)] = free_colour;
    c.colours = std::max(c.colours, free_colour + 1);
  }
  for (int j = 0; j < n; ++j)
    if (c.dense[static_cast<std::size_t>(j)]) c.colour[static_cast<std::size_t>(j)] = c.colours++;
  return c;
}

// The colouring of the last pattern seen on this thread: a trace asks for the same pattern
// at Jacobian after Jacobian (the contact bar's depends on x only through its contact phases),
// and colouring costs O(entries x row width), about a tenth of a mode-1 trace at N = 160
// (perf record); comparing the pattern costs O(entries). The colouring is a function of the
// pattern alone, so the cache changes no result.
// Shared, so that a wider pattern's colouring (which may evict this one) leaves it intact.
std::shared_ptr<const Colouring> cached_colour(const JacobianPattern& pattern, int m, int n) {
  struct Entry {
    std::vector<std::vector<int>> row_columns;
    std::vector<int> dense_columns;
    int m = -1, n = -1;
    std::shared_ptr<const Colouring> colouring;
  };
  // Two entries, the most recent first: a narrow pattern and the `wider` one behind it.
  thread_local std::array<Entry, 2> cache;
  for (std::size_t e = 0; e < cache.size(); ++e) {
    const Entry& entry = cache[e];
    if (entry.m == m && entry.n == n && entry.row_columns == pattern.row_columns &&
        entry.dense_columns == pattern.dense_columns) {
      if (e > 0) std::swap(cache[0], cache[e]);
      return cache[0].colouring;
    }
  }
  Entry fresh{pattern.row_columns, pattern.dense_columns, m, n,
              std::make_shared<const Colouring>(
                  colour(pattern, m, n))};  // throws on a malformed pattern: nothing cached
  cache[1] = std::move(cache[0]);
  cache[0] = std::move(fresh);
  return cache[0].colouring;
}

}  // namespace

std::vector<int> colour_columns(const JacobianPattern& pattern, int m, int n) {
  return colour(pattern, m, n).colour;
}

namespace {

// Each column's step h_j, its entry p_j of the check direction (0 for a dense column) and the
// columns of each colour.
struct ColourSteps {
  Vector h, p;
  std::vector<std::vector<int>> groups;
};

ColourSteps colour_steps(const Vector& x, const Vector& scale, double rel, const Colouring& c) {
  const Eigen::Index n = x.size();
  ColourSteps out;
  out.h.resize(n);
  out.p.resize(n);
  out.groups.resize(static_cast<std::size_t>(c.colours));
  for (int j = 0; j < n; ++j) {
    out.h[j] = finite_difference_step(x[j], scale[j], rel);
    // Dense columns are differenced alone, as column by column: the check leaves them out (it
    // would only add their second-order terms, or a kink of F along them, to its error).
    volatile double shifted = x[j] + fixed_weight(static_cast<std::uint64_t>(j)) * out.h[j];
    out.p[j] = c.dense[static_cast<std::size_t>(j)] ? 0.0 : shifted - x[j];
    if (c.colour[static_cast<std::size_t>(j)] >= 0)
      out.groups[static_cast<std::size_t>(c.colour[static_cast<std::size_t>(j)])].push_back(j);
  }
  return out;
}

// The residuals the compressed Jacobian is made of: per colour F(x + its steps) (and F(x - its
// steps), central), then F(x + p) (the check), then F(x).
struct ColourResiduals {
  Vector r0;                       // F(x)
  std::vector<Vector> plus;        // colours, then the check direction
  std::vector<Vector> minus;       // central only
  std::vector<EvalStatus> status;  // per task; the last, F(x)'s
};

// Task t < colours: that colour's step(s); task colours: the check direction; the last, F(x)
// itself, which the differences need only at the end: with threads, no residual runs alone.
ColourResiduals colour_residuals(const Problem& problem, const Vector& x, const ColourSteps& steps,
                                 int colours, bool central, int threads) {
  ColourResiduals out;
  const int tasks = colours + 2;
  const int base = colours + 1;
  out.plus.resize(static_cast<std::size_t>(base));
  out.minus.resize(static_cast<std::size_t>(central ? base : 0));
  out.status.assign(static_cast<std::size_t>(tasks), EvalStatus::ok);
  auto task = [&](int t) {
    const std::size_t ts = static_cast<std::size_t>(t);
    if (t == base) {
      out.status[ts] = problem.residual(x, out.r0);
      return;
    }
    const bool check = t == colours;
    Vector xs = x;
    if (check)
      xs += steps.p;
    else
      for (int j : steps.groups[ts]) xs[j] = x[j] + steps.h[j];
    EvalStatus st = problem.residual(xs, out.plus[ts]);
    if (st == EvalStatus::ok && central) {
      xs = x;
      if (check)
        xs -= steps.p;
      else
        for (int j : steps.groups[ts]) xs[j] = x[j] - steps.h[j];
      st = problem.residual(xs, out.minus[ts]);
    }
    out.status[ts] = st;
  };
  run_tasks(tasks, threads, task);
  return out;
}

// The check: with the pattern right, J p and F(x + p) - F(x) (d) agree to the finite-difference
// error: the second-order terms of F over the steps (O(h) relative), the round-off of F
// (O(eps / h) relative) and, where F has a kink (the contact bar's contact events), the
// difference between the secants of the columns and of p across it. Per row the tolerance is
// tau * (a_i + sigma max_k a_k), a_i = sum_j |J_ij p_j| the size of the first-order terms of
// that row; the floor covers rows whose terms nearly vanish, since F's round-off is shared by
// all rows (one simulation), not proportional to each row. tau = 1e-3, sigma = 1e-2: on the
// contact bar's smooth points the error stays below 5e-6 in these units (modes 1 and 2, both
// formulations, energies from grazing to 2e4 times it, tests/problems/contact_bar/
// test_jacobian_pattern.cpp), and at its kinks (the grazing start, the resonance at T = 3.2)
// it reaches 1.5e-3 in a few of ~370 Jacobians of a mode-1 branch, whose compressed J still
// equals the column-by-column one to 1.4e-6 (so those fallbacks are false alarms; 1e-4 raises
// 12 of them). A missed entry J_ij shows up in row i as |J_ij h_j| |w_j - w_k| (w_k the weight
// of the column it was read for, or 0), of the order of the entry itself, and is caught once
// that exceeds the tolerance: a pattern can only drop entries below about 1e-3 of their row's
// size unnoticed (a structural mistake drops entries of the row's own size).
// The largest error over its tolerance (the check passes at 1 or below).
double check_error(const Matrix& J, const Vector& p, const Vector& d, const Colouring& c,
                   double tau) {
  const Eigen::Index m = J.rows(), n = J.cols();
  Vector jp = Vector::Zero(m), size = Vector::Zero(m);
  for (int j = 0; j < n; ++j) {
    if (c.dense[static_cast<std::size_t>(j)]) {
      jp += J.col(j) * p[j];
      size += J.col(j).cwiseAbs() * std::abs(p[j]);
    } else {
      for (int i : c.column_rows[static_cast<std::size_t>(j)]) {
        jp[i] += J(i, j) * p[j];
        size[i] += std::abs(J(i, j) * p[j]);
      }
    }
  }
  constexpr double sigma = 1e-2;
  const double floor = sigma * (m > 0 ? size.maxCoeff() : 0.0);
  double worst = 0;
  for (int i = 0; i < m; ++i) {
    const double tolerance = tau * (size[i] + floor);
    const double error = std::abs(jp[i] - d[i]);
    worst = std::max(worst, tolerance > 0 ? error / tolerance : (error > 0 ? HUGE_VAL : 0.0));
  }
  return worst;
}

}  // namespace

EvalStatus compressed_finite_difference_jacobian(const Problem& problem, const Vector& x,
                                                 const JacobianPattern& pattern, Matrix& J,
                                                 const FiniteDifferenceOptions& options,
                                                 CompressedJacobianReport* report) {
  CompressedJacobianReport local;
  CompressedJacobianReport& out = report ? *report : local;
  out = {};
  const int n = problem.num_unknowns();
  const int m = problem.num_equations();
  const std::shared_ptr<const Colouring> colouring = cached_colour(pattern, m, n);
  const Colouring& c = *colouring;
  out.colours = c.colours;
  const bool central = options.scheme == FiniteDifferenceOptions::Scheme::central;
  const ColourSteps steps = colour_steps(x, problem.typical_scale(), relative_step(options), c);
  const ColourResiduals r =
      colour_residuals(problem, x, steps, c.colours, central, options.threads);
  const int base = c.colours + 1;
  out.residuals += 1 + base * (central ? 2 : 1);
  if (r.status[static_cast<std::size_t>(base)] != EvalStatus::ok)
    return r.status[static_cast<std::size_t>(base)];
  auto fall_back = [&] {
    out.fell_back = true;
    const long before = problem.counters().residuals;
    const EvalStatus fs = finite_difference_jacobian(problem, x, J, options);
    out.residuals += static_cast<int>(problem.counters().residuals - before);
    return fs;
  };
  for (EvalStatus st : r.status)
    if (st != EvalStatus::ok) return fall_back();

  auto difference = [&](int t) -> Vector {
    const std::size_t ts = static_cast<std::size_t>(t);
    return central ? Vector(0.5 * (r.plus[ts] - r.minus[ts])) : Vector(r.plus[ts] - r.r0);
  };
  J.setZero(m, n);
  for (int t = 0; t < c.colours; ++t) {
    const Vector d = difference(t);
    for (int j : steps.groups[static_cast<std::size_t>(t)]) {
      if (c.dense[static_cast<std::size_t>(j)])
        J.col(j) = d / steps.h[j];
      else
        for (int i : c.column_rows[static_cast<std::size_t>(j)]) J(i, j) = d[i] / steps.h[j];
    }
  }

  const double tau = std::max(pattern.check_tolerance, CorrectorJacobians::tolerance());
  out.check_error = check_error(J, steps.p, difference(c.colours), c, tau);
  if (out.check_error <= 1) return EvalStatus::ok;
  if (!pattern.wider) {
    // A kink, not a missed entry, and a corrector judges its answer by F: keep J.
    if (pattern.structural && CorrectorJacobians::tolerance() > 0) {
      out.kept_unchecked = true;
      return EvalStatus::ok;
    }
    return fall_back();
  }
  CompressedJacobianReport wider;
  const EvalStatus ws =
      compressed_finite_difference_jacobian(problem, x, pattern.wider(), J, options, &wider);
  out.widened = true;
  out.fell_back = wider.fell_back;
  out.kept_unchecked = wider.kept_unchecked;
  out.residuals += wider.residuals;
  return ws;
}

namespace {
thread_local double corrector_check_tolerance = 0;
}  // namespace

CorrectorJacobians::CorrectorJacobians(double tolerance) : outer_(corrector_check_tolerance) {
  corrector_check_tolerance = tolerance;
}

CorrectorJacobians::~CorrectorJacobians() {
  corrector_check_tolerance = outer_;
}

double CorrectorJacobians::tolerance() {
  return corrector_check_tolerance;
}

}  // namespace backbone::core
