#include "problems/bar/bar.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/errors.hpp"

namespace backbone::bar {

using core::InputError;

const char* to_string(EndType e) {
  switch (e) {
    case EndType::fixed:
      return "fixed";
    case EndType::free:
      return "free";
    case EndType::contact:
      return "contact";
    case EndType::clearance:
      return "clearance";
  }
  return "?";
}

EndType parse_end_type(const std::string& key, const std::string& value) {
  if (value == "fixed") return EndType::fixed;
  if (value == "free") return EndType::free;
  if (value == "contact") return EndType::contact;
  if (value == "clearance") return EndType::clearance;
  throw InputError(key,
                   fmt::format("must be one of fixed, free, contact, clearance (got '{}')", value));
}

double Material::wave_speed() const {
  return std::sqrt(youngs_modulus / density);
}
double Material::axial_stiffness() const {
  return youngs_modulus * area;
}
double Material::impedance() const {
  return density * area * wave_speed();
}
double Material::travel_time() const {
  return length / wave_speed();
}

PiecewiseLinear::PiecewiseLinear(std::vector<double> x, std::vector<double> y)
    : PiecewiseLinear(std::move(x), std::move(y), false) {}

PiecewiseLinear PiecewiseLinear::with_jumps(std::vector<double> x, std::vector<double> y) {
  return {std::move(x), std::move(y), true};
}

PiecewiseLinear::PiecewiseLinear(std::vector<double> x, std::vector<double> y, bool jumps)
    : x_(std::move(x)), y_(std::move(y)) {
  if (x_.empty() || x_.size() != y_.size())
    throw InputError("knots", fmt::format("need as many values as knots, at least one ({} vs {})",
                                          y_.size(), x_.size()));
  for (std::size_t i = 0; i < x_.size(); ++i) {
    if (!std::isfinite(x_[i]) || !std::isfinite(y_[i]))
      throw InputError("knots", fmt::format("knot {} is not finite ({}, {})", i, x_[i], y_[i]));
    // A jump sits between interior knots: neither end's value is ambiguous.
    const bool jump =
        jumps && i >= 2 && i + 1 < x_.size() && x_[i] == x_[i - 1] && x_[i - 1] != x_[i - 2];
    has_jumps_ = has_jumps_ || jump;
    if (i > 0 && !(x_[i] > x_[i - 1]) && !jump)
      throw InputError("knots", fmt::format("knots must increase strictly ({} after {}){}", x_[i],
                                            x_[i - 1], jumps ? ", or once by a jump" : ""));
  }
  // Near uniform: every knot within a quarter spacing of its grid point, so that the guessed
  // index is at most one off and the corrective walk is a step or two.
  const std::size_t n = x_.size();
  if (n >= 3) {
    const double spacing = (x_.back() - x_.front()) / static_cast<double>(n - 1);
    bool uniform = spacing > 0 && std::isfinite(1 / spacing);
    for (std::size_t i = 1; uniform && i + 1 < n; ++i)
      uniform = std::abs(x_[i] - (x_.front() + static_cast<double>(i) * spacing)) <= 0.25 * spacing;
    if (uniform) inverse_spacing_ = 1 / spacing;
  }
}

std::size_t PiecewiseLinear::first_knot_above(double x, bool or_equal) const {
  const auto above = [&](double knot) { return or_equal ? knot >= x : knot > x; };
  if (inverse_spacing_ == 0 || !(x > x_.front() && x < x_.back()))
    return static_cast<std::size_t>((or_equal ? std::lower_bound(x_.begin(), x_.end(), x)
                                              : std::upper_bound(x_.begin(), x_.end(), x)) -
                                    x_.begin());
  // x_front < x < x_back: the answer i is in [1, n - 1], with x_[i - 1] not above x and x_[i]
  // above it. Guess from the grid, then walk down while x_[i - 1] is above x and up while x_[i]
  // is not: the result is the binary search's from any start.
  const std::size_t last = x_.size() - 1;
  const double guess = (x - x_.front()) * inverse_spacing_;  // in (0, last] up to rounding
  std::size_t i = guess < static_cast<double>(last) ? static_cast<std::size_t>(guess) + 1 : last;
  while (i > 1 && above(x_[i - 1])) --i;
  while (i < last && !above(x_[i])) ++i;
  return i;
}

double PiecewiseLinear::operator()(double x) const {
  if (x <= x_.front()) return y_.front();
  if (x >= x_.back()) return y_.back();
  const std::size_t i = first_knot_above(x, false);  // x_[i-1] <= x < x_[i]
  const double w = (x - x_[i - 1]) / (x_[i] - x_[i - 1]);
  return (1 - w) * y_[i - 1] + w * y_[i];
}

double PiecewiseLinear::slope(double x, int side) const {
  if (x_.size() < 2) return 0;
  if (x < x_.front() || (x == x_.front() && side < 0)) return 0;
  if (x > x_.back() || (x == x_.back() && side > 0)) return 0;
  const std::size_t i = std::clamp<std::size_t>(first_knot_above(x, side <= 0), 1, x_.size() - 1);
  return (y_[i] - y_[i - 1]) / (x_[i] - x_[i - 1]);
}

double PiecewiseLinear::integral(double a, double b) const {
  if (a == b) return 0;
  if (a > b) return -integral(b, a);
  if (has_jumps_) return integral_with_jumps(a, b);
  // Points where the integrand changes form: a, the knots inside (a, b), b.
  double total = 0;
  double left = a;
  auto piece = [&](double l, double r) { total += 0.5 * ((*this)(l) + (*this)(r)) * (r - l); };
  for (std::size_t i = first_knot_above(a, false); i < x_.size(); ++i) {
    const double k = x_[i];
    if (k >= b) break;
    piece(left, k);
    left = k;
  }
  piece(left, b);
  return total;
}

// Segment by segment from the knots' own values: at a jump operator() gives the right limit,
// and the segment that ends there needs the left one.
double PiecewiseLinear::integral_with_jumps(double a, double b) const {
  double total = 0;
  if (a < x_.front()) {
    const double e = std::min(b, x_.front());
    total += y_.front() * (e - a);
    a = e;
  }
  if (b > x_.back()) {
    const double s = std::max(a, x_.back());
    total += y_.back() * (b - s);
    b = s;
  }
  for (std::size_t i = std::max<std::size_t>(first_knot_above(a, false), 1);
       i < x_.size() && x_[i - 1] < b; ++i) {
    const double x0 = x_[i - 1], x1 = x_[i];
    if (!(x1 > x0)) continue;
    const double l = std::max(a, x0), r = std::min(b, x1);
    const auto at = [&](double x) {
      return y_[i - 1] + (y_[i] - y_[i - 1]) * (x - x0) / (x1 - x0);
    };
    if (r > l) total += 0.5 * (at(l) + at(r)) * (r - l);
  }
  return total;
}

void BarSetup::validate() const {
  auto positive = [](const char* key, double v) {
    if (!std::isfinite(v) || !(v > 0))
      throw InputError(key, fmt::format("must be > 0 (got {})", v));
  };
  positive("length", material.length);
  positive("youngs_modulus", material.youngs_modulus);
  positive("density", material.density);
  positive("area", material.area);
  for (const auto& [key, end] : {std::pair{"gap", left}, std::pair{"gap", right}}) {
    if (!std::isfinite(end.gap) || end.gap < 0)
      throw InputError(key, fmt::format("must be >= 0 (got {})", end.gap));
    if (!std::isfinite(end.gap_back) || end.gap_back < 0)
      throw InputError("gap_back", fmt::format("must be >= 0 (got {})", end.gap_back));
    if (end.has_back_wall() && !(end.gap + end.gap_back > 0))
      throw InputError("gap_back",
                       "gap + gap_back must be > 0 for a clearance end (the two "
                       "walls may not coincide)");
  }
  if (!std::isfinite(body_force))
    throw InputError("body_force", fmt::format("must be finite (got {})", body_force));
  const double L = material.length;
  for (const auto& [key, f] : {std::pair{"u0", &u0}, std::pair{"v0", &v0}}) {
    if (f->knots().front() < 0 || f->knots().back() > L * (1 + 1e-12))
      throw InputError(key, fmt::format("knots must lie in [0, length] = [0, {}] (got [{}, {}])", L,
                                        f->knots().front(), f->knots().back()));
  }
  // A contact end must start on the admissible side of its walls.
  if (right.has_wall() && u0(L) > right.gap * (1 + 1e-12) + 1e-300)
    throw InputError("u0",
                     fmt::format("u0(L) = {} penetrates the wall at gap {}", u0(L), right.gap));
  if (left.has_wall() && -u0(0.0) > left.gap * (1 + 1e-12) + 1e-300)
    throw InputError("u0",
                     fmt::format("u0(0) = {} penetrates the wall at gap {}", u0(0.0), left.gap));
  if (right.has_back_wall() && -u0(L) > right.gap_back * (1 + 1e-12) + 1e-300)
    throw InputError("u0", fmt::format("u0(L) = {} penetrates the back wall at gap_back {}", u0(L),
                                       right.gap_back));
  if (left.has_back_wall() && u0(0.0) > left.gap_back * (1 + 1e-12) + 1e-300)
    throw InputError("u0", fmt::format("u0(0) = {} penetrates the back wall at gap_back {}",
                                       u0(0.0), left.gap_back));
}

bool BarSetup::observed_end_is_right() const {
  return right.has_wall() || !left.has_wall();
}

void SimulationOptions::validate() const {
  if (!std::isfinite(t_end) || !(t_end > 0))
    throw InputError("t_end", fmt::format("must be > 0 (got {})", t_end));
  if (!std::isfinite(dt) || !(dt > 0))
    throw InputError("dt", fmt::format("must be > 0 (got {})", dt));
  if (elements < 1) throw InputError("elements", fmt::format("must be >= 1 (got {})", elements));
  if (history_samples < 2)
    throw InputError("history_samples", fmt::format("must be >= 2 (got {})", history_samples));
  for (double p : probes)
    if (!std::isfinite(p)) throw InputError("probes", "must be finite");
}

core::Table History::to_table() const {
  std::vector<std::string> cols{"t", "u_contact", "contact_force", "energy"};
  for (std::size_t k = 0; k < probes.size(); ++k) cols.push_back(fmt::format("u_probe{}", k));
  core::Table table(cols);
  for (std::size_t i = 0; i < t.size(); ++i) {
    std::vector<double> row{t[i], u_contact[i], contact_force[i],
                            i < energy.size() ? energy[i] : std::nan("")};
    for (const auto& p : probe_u) row.push_back(p[i]);
    table.add_row(row);
  }
  return table;
}

}  // namespace backbone::bar
