// The tangent of the exact solution (exact_solution.hpp, README.md 'Tangent'): the seed of the
// initial signals and the derivatives of the hat projections of v. The march itself carries
// the derivatives of its segments (ExactBarSolution::march_end, emit).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/errors.hpp"
#include "problems/exact_bar/exact_solution.hpp"

namespace backbone::exact_bar {

using core::InputError;

// Window 0 of both signals from u0 alone (v0 = 0, no body force): on the element [x_j, x_j+1]
// of slope s_j, B = c s_j on [x_j, x_j+1] / c and A = -c s_j on [L - x_j+1, L - x_j] / c, so
// d(value) = +-c d s_j and the breakpoints move with the knots.
void ExactBarSolution::seed_initial_signals(const std::vector<double>& xs) {
  const std::vector<double>& knots = setup_.u0.knots();
  const std::vector<double>& values = setup_.u0.values();
  if (xs.size() != knots.size())
    throw InputError("tangent", "u0's knots must include 0 and L and hold every breakpoint");
  const std::size_t elements = xs.size() - 1;
  std::vector<Sensitivity> d_slope(elements);
  for (std::size_t j = 0; j < elements; ++j) {
    const double width = knots[j + 1] - knots[j];
    const double slope = (values[j + 1] - values[j]) / width;
    d_slope[j] = ((seed_.d_value[j + 1] - seed_.d_value[j]) -
                  slope * (seed_.d_knot[j + 1] - seed_.d_knot[j])) /
                 width;
  }
  const Sensitivity zero(tangent_size_);
  b_tan_.clear();
  a_tan_.clear();
  for (std::size_t j = 0; j < elements; ++j)  // B, in the order march() pushes it
    b_tan_.push_back({seed_.d_knot[j] / c_, j + 1 == elements ? zero : seed_.d_knot[j + 1] / c_,
                      c_ * d_slope[j]});
  for (std::size_t j = elements; j > 0; --j)  // A, from x = L down
    a_tan_.push_back({-seed_.d_knot[j] / c_, j == 1 ? zero : Sensitivity(-seed_.d_knot[j - 1] / c_),
                      -c_ * d_slope[j - 1]});
}

ProjectedVelocityTangent ExactBarSolution::projected_velocity_tangent(double t,
                                                                      int elements) const {
  if (tangent_size_ == 0)
    throw std::logic_error("projected_velocity_tangent: the solution carries no tangent");
  if (elements < 1) throw InputError("elements", fmt::format("must be >= 1 (got {})", elements));
  check_time(t);
  const double L = setup_.material.length;
  const Local lt = to_local(t);
  const long k = lt.k;
  const double rt = lt.r;
  const int n = tangent_size_;

  // The fronts at t, as profile() finds them, with their derivatives in p (factor times a
  // segment's d r0, read in place) and their speed. Fronts of A and of B that coincide at t (as
  // a mode's closing and release fronts do at T/2) pass through each other: each keeps its own
  // motion, so a breakpoint carries both.
  struct Motion {
    const Sensitivity* dr0 = nullptr;  // none: no front of that signal here
    double factor = 0;
  };
  struct Front {
    double x;
    bool of_a;  // a front of A (runs towards x = 0 as t grows), else of B
    Motion dx;
  };
  struct Breakpoint {
    double x;
    Motion dx_a, dx_b;
  };
  std::vector<Front> fronts;
  auto add_fronts = [&](const Chunked<Segment>& sig, const std::vector<SegmentTangent>& tan,
                        bool from_right) {
    for_each_front(sig, from_right, t, [&](std::size_t i, double x) {
      fronts.push_back({x, from_right, {&tan[i].dr0, from_right ? -c_ : c_}});
    });
  };
  add_fronts(a_, a_tan_, true);
  add_fronts(b_sig_, b_tan_, false);
  std::stable_sort(fronts.begin(), fronts.end(),
                   [](const Front& a, const Front& b) { return a.x < b.x; });
  const double tol = front_tolerance(t);
  std::vector<Breakpoint> kept{{0.0, {}, {}}};
  for (const Front& f : fronts) {
    if (!(L - f.x > tol)) continue;
    if (f.x - kept.back().x > tol) kept.push_back({f.x, {}, {}});
    if (kept.size() == 1) continue;  // at x = 0
    Motion& m = f.of_a ? kept.back().dx_a : kept.back().dx_b;
    if (!m.dr0) m = f.dx;
  }
  kept.push_back({L, {}, {}});

  // A signal's value at argument t + offset, from the segment that holds t + mid_offset (the
  // piece's own side of a front), with that segment's tangent and slope: the value's derivative
  // at fixed argument is dy0 - slope dr0.
  struct Value {
    double y;
    const SegmentTangent* g;
    double slope;
  };
  auto value = [&](const Chunked<Segment>& sig, const std::vector<SegmentTangent>& tan,
                   double offset, double mid_offset) {
    const double rm = rt + mid_offset;
    const long kk = rm < tau_ ? k : k + 1;
    const double shift = kk == k ? 0.0 : tau_;
    const long kc = std::clamp<long>(kk, 0, static_cast<long>(sig.first.size()) - 1);
    const auto first = sig.segments.begin() + static_cast<std::ptrdiff_t>(sig.first[kc]);
    const auto last = sig.segments.begin() + static_cast<std::ptrdiff_t>(sig.end_of(kc));
    auto it = std::upper_bound(first, last, rm - shift,
                               [](double x, const Segment& seg) { return x < seg.r0; });
    if (it != first) --it;
    const auto i = static_cast<std::size_t>(it - sig.segments.begin());
    return Value{it->at(rt + offset - shift), &tan[i], it->slope};
  };

  Eigen::MatrixXd d_pt = Eigen::MatrixXd::Zero(n, elements + 1);  // one column per node
  Eigen::VectorXd d_t = Eigen::VectorXd::Zero(elements + 1);
  // column += w * (derivative of the value), read from the sparse tangent in place.
  auto add_value = [&](int column, double w, const Value& v) {
    double* col = d_pt.col(column).data();
    for (Sensitivity::InnerIterator e(v.g->dy0); e; ++e) col[e.index()] += w * e.value();
    if (v.slope != 0)
      for (Sensitivity::InnerIterator e(v.g->dr0); e; ++e)
        col[e.index()] -= w * v.slope * e.value();
  };
  auto add_motion = [&](int column, double w, const Motion& m) {
    if (!m.dr0 || w == 0) return;
    double* col = d_pt.col(column).data();
    for (Sensitivity::InnerIterator e(*m.dr0); e; ++e) col[e.index()] += w * m.factor * e.value();
  };
  const double h = L / elements;
  auto hat = [&](int i, double x) { return std::max(0.0, 1 - std::abs(x - i * h) / h); };
  // Per breakpoint between two pieces: the jumps of A and of B, each moved by its own front,
  // add jump psi_i(x_f) dx_f (v = (A + B) / 2); as t grows A's fronts move by +c, B's by -c.
  double a_left = 0, b_left = 0;  // A and B just left of the breakpoint (from the piece before)
  for (std::size_t j = 0; j + 1 < kept.size(); ++j) {
    const double xa = kept[j].x, xb = kept[j + 1].x, xm = 0.5 * (xa + xb);
    const Value pa = value(a_, a_tan_, (L - xa) / c_, (L - xm) / c_);
    const Value pb = value(a_, a_tan_, (L - xb) / c_, (L - xm) / c_);
    const Value ma = value(b_sig_, b_tan_, xa / c_, xm / c_);
    const Value mb = value(b_sig_, b_tan_, xb / c_, xm / c_);
    const double vt = 0.5 * (pb.slope + mb.slope);  // dv/dt at fixed x
    if (j > 0) {                                    // the breakpoint at xa
      const double jump_a = 0.5 * (a_left - pa.y), jump_b = 0.5 * (b_left - ma.y);
      const double dx_dt = (jump_a - jump_b) * c_;
      const int cell = static_cast<int>(std::floor(xa / h));
      for (int i = std::max(0, cell); i <= std::min(elements, cell + 1); ++i) {
        const double w = hat(i, xa);
        if (w == 0) continue;
        add_motion(i, w * jump_a, kept[j].dx_a);
        add_motion(i, w * jump_b, kept[j].dx_b);
        d_t[i] += w * dx_dt;
      }
    }
    a_left = pb.y;
    b_left = mb.y;
    if (!(xb > xa)) continue;
    // int g psi_i and int vt psi_i over the piece: g linear, psi_i linear on each cell, so
    // Simpson's rule on every (piece x cell) intersection is exact; with g = ga + f (gb - ga),
    // f = (x - xa) / (xb - xa), ga = (pa + ma) / 2 and gb = (pb + mb) / 2, each weight splits
    // into a multiple of ga and one of gb - ga.
    const double width = xb - xa;
    const int first_cell = std::clamp(static_cast<int>(std::floor(xa / h)), 0, elements - 1);
    for (int cell = first_cell; cell < elements && cell * h < xb; ++cell) {
      const double a = std::max(xa, cell * h), b = std::min(xb, (cell + 1) * h);
      if (!(b > a)) continue;
      const double m = 0.5 * (a + b), w = (b - a) / 6;
      const double fa = (a - xa) / width, fm = (m - xa) / width, fb = (b - xa) / width;
      for (int i : {cell, cell + 1}) {
        const double ha = hat(i, a), hm = hat(i, m), hb = hat(i, b);
        const double whole = w * (ha + 4 * hm + hb), along = w * (ha * fa + 4 * hm * fm + hb * fb);
        add_value(i, 0.5 * (whole - along), pa);
        add_value(i, 0.5 * (whole - along), ma);
        add_value(i, 0.5 * along, pb);
        add_value(i, 0.5 * along, mb);
        d_t[i] += whole * vt;
      }
    }
  }
  return {std::move(d_pt), std::move(d_t)};
}

}  // namespace backbone::exact_bar
