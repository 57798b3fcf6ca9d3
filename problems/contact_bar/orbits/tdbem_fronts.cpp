#include "problems/contact_bar/orbits/tdbem_fronts.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <functional>
#include <limits>
#include <vector>

#include "core/errors.hpp"
#include "problems/exact_bar/front_monodromy.hpp"

namespace backbone::contact_bar {

namespace {

constexpr double epsilon = std::numeric_limits<double>::epsilon();

// The jump-weighted position of the breakpoints of `s` near each front of `base` (within
// `window`), the fronts in base's order: to first order a front that comes back as a few
// breakpoints acts as one at that position (as in exact_bar::front_monodromy); a sliver's
// value, inexact, moves that position by its error times the sliver's length only. Empty, with
// the reason, when jumps over `jump` (summed over breakpoints within `sliver` of each other)
// have no front of base near them or a front of base gets back less than half its jump.
Eigen::VectorXd front_positions(const exact_bar::CharacteristicState& base,
                                const exact_bar::CharacteristicState& s, double window, double jump,
                                double sliver, std::string& why) {
  const int fa = static_cast<int>(base.a_start.size()) - 1;
  Eigen::VectorXd total = Eigen::VectorXd::Zero(base.fronts());
  Eigen::VectorXd moment = Eigen::VectorXd::Zero(base.fronts());
  // Breakpoints with no front of base near them: a run of them within `sliver` of each other
  // counts by its summed jump (a sliver's two jumps cancel but for its value's round-off).
  double stray = 0, stray_at = -1;
  auto stray_ok = [&] {
    if (!(std::abs(stray) > jump)) return true;
    why = fmt::format(
        "a front at r = {} (a jump of {} of the largest value) has none within {} "
        "at t0 to match",
        stray_at, std::abs(stray) / jump * exact_bar::default_jump_tolerance, window);
    return false;
  };
  for (bool of_a : {true, false}) {
    const auto& start0 = of_a ? base.a_start : base.b_start;
    const auto& start = of_a ? s.a_start : s.b_start;
    const auto& value = of_a ? s.a_value : s.b_value;
    stray = 0;
    stray_at = -1;
    for (std::size_t k = 1; k < start.size(); ++k) {
      const double step = value[k] - value[k - 1];
      const auto it = std::min_element(start0.begin() + 1, start0.end(), [&](double a, double b) {
        return std::abs(a - start[k]) < std::abs(b - start[k]);
      });
      if (it != start0.end() && std::abs(*it - start[k]) <= window) {
        const int i = static_cast<int>(it - start0.begin()) - 1 + (of_a ? 0 : fa);
        total[i] += step;
        moment[i] += step * start[k];
        continue;
      }
      if (!(stray_at >= 0 && start[k] - stray_at <= sliver)) {
        if (!stray_ok()) return {};
        stray = 0;
      }
      stray += step;
      stray_at = start[k];
    }
    if (!stray_ok()) return {};
  }
  Eigen::VectorXd position(base.fronts());
  for (int i = 0; i < base.fronts(); ++i) {
    const bool of_a = i < fa;
    const auto k = static_cast<std::size_t>(of_a ? i + 1 : i - fa + 1);
    const auto& value0 = of_a ? base.a_value : base.b_value;
    const double jump0 = value0[k] - value0[k - 1];
    if (!(std::abs(total[i] - jump0) <= 0.5 * std::abs(jump0))) {
      why = fmt::format("front {} (r = {}) does not come back", i,
                        of_a ? base.a_start[k] : base.b_start[k]);
      return {};
    }
    position[i] = moment[i] / total[i];
  }
  return position;
}

}  // namespace

exact_bar::CharacteristicState tdbem_characteristic_state(const TdbemMarch& march) {
  const bar::BarSetup& setup = march.setup();
  const double length = setup.material.length, c = setup.material.wave_speed();
  const std::vector<double> cuts = march.breakpoints();
  struct Piece {
    double x0, x1, plus, minus, spread;  // spread: R+- at the quarter points, largest difference
  };
  std::vector<Piece> pieces;
  auto riemann = [&](double x, double& plus, double& minus) {
    const double v = march.velocity(x), cux = c * march.strain(x);
    plus = v - cux;
    minus = v + cux;
  };
  double scale = 0;
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    const double a = cuts[i], b = cuts[i + 1];
    if (!(b - a > 1e-12 * length)) continue;
    Piece p{a, b, 0, 0, 0};
    riemann(0.5 * (a + b), p.plus, p.minus);
    double plus1, minus1, plus3, minus3;
    riemann(0.75 * a + 0.25 * b, plus1, minus1);
    riemann(0.25 * a + 0.75 * b, plus3, minus3);
    // A sliver's value is formed from knots that close in time, with round-off over its length:
    // only longer pieces are checked.
    if (b - a > 1e-9 * length)
      p.spread = std::max(std::abs(plus1 - plus3), std::abs(minus1 - minus3));
    scale = std::max({scale, std::abs(p.plus), std::abs(p.minus)});
    pieces.push_back(p);
  }
  for (const Piece& p : pieces)
    if (p.spread > 1e-9 * scale)
      throw core::InputError("tdbem_fronts",
                             fmt::format("the field is not piecewise constant in R+- on [{}, {}] "
                                         "(a state with body force or a smooth v0)",
                                         p.x0, p.x1));
  if (pieces.empty()) throw core::InputError("tdbem_fronts", "the field has no piece");
  // A sliver at an end (a front reflecting there at this instant, or a breakpoint a few ulps
  // off it) belongs to the window's edge, not to the state: its neighbour takes it over.
  if (pieces.size() > 1 && pieces.front().x1 - pieces.front().x0 < 1e-9 * length) {
    pieces[1].x0 = pieces.front().x0;
    pieces.erase(pieces.begin());
  }
  if (pieces.size() > 1 && pieces.back().x1 - pieces.back().x0 < 1e-9 * length) {
    pieces[pieces.size() - 2].x1 = pieces.back().x1;
    pieces.pop_back();
  }
  exact_bar::CharacteristicState s;
  auto push = [&](std::vector<double>& start, std::vector<double>& value, double r, double y) {
    if (!value.empty() &&
        std::abs(value.back() - y) <= 8 * epsilon * (std::abs(value.back()) + std::abs(y)))
      return;
    start.push_back(value.empty() ? 0.0 : r);
    value.push_back(y);
  };
  // A(r) = R+ at x = L - c r: pieces from the right end; B(r) = R- at x = c r: from the left.
  for (auto p = pieces.rbegin(); p != pieces.rend(); ++p)
    push(s.a_start, s.a_value, (length - p->x1) / c, p->plus);
  for (const Piece& p : pieces) push(s.b_start, s.b_value, p.x0 / c, p.minus);
  return s;
}

TdbemFronts tdbem_front_monodromy(const bar::BarSetup& setup, double t0, double period, double dt,
                                  double relative_step) {
  TdbemFronts out;
  try {
    const double tau = setup.material.travel_time();
    TdbemMarch orbit(setup, dt, ContactMethod::event);
    if (!orbit.advance_to(t0)) {
      out.message = "the TD-BEM march to t0 failed";
      return out;
    }
    if (orbit.in_contact(true) || orbit.in_contact(false)) {
      out.message = fmt::format("an end is on a wall at t0 = {}", t0);
      return out;
    }
    out.state = exact_bar::without_small_jumps(tdbem_characteristic_state(orbit),
                                               exact_bar::default_jump_tolerance, tau);
    const exact_bar::CharacteristicState& base = out.state;
    const int fronts = base.fronts(), fa = static_cast<int>(base.a_start.size()) - 1;
    double scale = 0, spacing = tau;
    for (bool of_a : {true, false}) {
      const auto& start = of_a ? base.a_start : base.b_start;
      for (double y : of_a ? base.a_value : base.b_value) scale = std::max(scale, std::abs(y));
      for (std::size_t i = 1; i <= start.size(); ++i)
        spacing = std::min(spacing, (i < start.size() ? start[i] : tau) - start[i - 1]);
    }
    const double h = relative_step * tau;
    const double window = std::min(1e-4 * tau, 0.25 * spacing);
    if (!(h < 0.1 * window)) {
      out.message = fmt::format("the fronts at t0 are {} tau apart: too close for a step of {} tau",
                                spacing / tau, relative_step);
      return out;
    }
    const double jump = exact_bar::default_jump_tolerance * scale;
    std::string why;
    auto fronts_at_t = [&](const exact_bar::CharacteristicState& s) {
      TdbemMarch m(exact_bar::with_characteristic_state(setup, s), dt, ContactMethod::event);
      if (!m.advance_to(period)) {
        why = "the TD-BEM march over a period failed";
        return Eigen::VectorXd{};
      }
      return front_positions(base, tdbem_characteristic_state(m), window, jump, 1e-9 * tau, why);
    };
    const Eigen::VectorXd at_t = fronts_at_t(base);
    if (at_t.size() != fronts) {
      out.message = "the orbit's fronts do not come back: " + why;
      return out;
    }
    out.K.resize(fronts, fronts);
    out.K_forward.resize(fronts, fronts);
    out.K_backward.resize(fronts, fronts);
    for (int i = 0; i < fronts; ++i) {
      Eigen::VectorXd moved[2];
      std::string failed;
      // A large derivative (near a grazing, d sc = -du / y with a small y) moves a front out of
      // the matching window: the step shrinks tenfold, twice, before a side counts as failed.
      double step = h;
      for (int attempt = 0; attempt < 3; ++attempt) {
        if (attempt > 0) step /= 10;
        for (int side = 0; side < 2; ++side) {
          exact_bar::CharacteristicState s = base;
          auto& start = i < fa ? s.a_start : s.b_start;
          start[static_cast<std::size_t>(i < fa ? i + 1 : i - fa + 1)] += side == 0 ? step : -step;
          moved[side] = fronts_at_t(s);
          if (moved[side].size() != fronts)
            failed = fmt::format("front {} moved by {}{} tau: {}", i, side == 0 ? "+" : "-",
                                 step / tau, why);
        }
        if (moved[0].size() == fronts && moved[1].size() == fronts) break;
      }
      const bool forward = moved[0].size() == fronts, backward = moved[1].size() == fronts;
      if (!forward && !backward) {
        out.message = failed;
        return out;
      }
      // A side whose march changes the contact structure within h (a new front appears, one
      // does not come back) leaves the other side's difference: a kink, one-sided.
      if (forward) out.K_forward.col(i) = (moved[0] - at_t) / step;
      if (backward) out.K_backward.col(i) = (at_t - moved[1]) / step;
      if (!forward) out.K_forward.col(i) = out.K_backward.col(i);
      if (!backward) out.K_backward.col(i) = out.K_forward.col(i);
      out.K.col(i) = forward && backward ? Eigen::VectorXd((moved[0] - moved[1]) / (2 * step))
                                         : Eigen::VectorXd(out.K_forward.col(i));
      if (!(forward && backward)) out.kink = std::numeric_limits<double>::infinity();
    }
    out.kink = std::max(out.kink, (out.K_forward - out.K_backward).cwiseAbs().maxCoeff());
    out.ok = out.K.allFinite();
    if (!out.ok) out.message = "K is not finite";
  } catch (const core::InputError& e) {
    out.message = e.what();
  }
  return out;
}

namespace {

// Whether every x pairs with a distinct y over the edges adjacent[i] (Kuhn's augmenting paths).
bool perfect_matching(const std::vector<std::vector<int>>& adjacent, std::size_t n) {
  std::vector<int> partner(n, -1);
  std::vector<char> seen;
  const std::function<bool(std::size_t)> augment = [&](std::size_t i) {
    for (const int j : adjacent[i]) {
      if (seen[static_cast<std::size_t>(j)]) continue;
      seen[static_cast<std::size_t>(j)] = 1;
      const int k = partner[static_cast<std::size_t>(j)];
      if (k < 0 || augment(static_cast<std::size_t>(k))) {
        partner[static_cast<std::size_t>(j)] = static_cast<int>(i);
        return true;
      }
    }
    return false;
  };
  for (std::size_t i = 0; i < n; ++i) {
    seen.assign(n, 0);
    if (!augment(i)) return false;
  }
  return true;
}

}  // namespace

bool front_eigenvalues(const Eigen::MatrixXd& K, Eigen::VectorXcd& mu) {
  const Eigen::EigenSolver<Eigen::MatrixXd> first(K, false);
  if (first.info() == Eigen::Success) {
    mu = first.eigenvalues();
    return true;
  }
  const Eigen::Index n = K.rows();
  Eigen::VectorXd w(n);
  for (Eigen::Index i = 0; i < n; ++i) w[i] = std::sin(1.0 + 0.7 * static_cast<double>(i));
  w.normalize();
  const Eigen::MatrixXd Q = Eigen::MatrixXd::Identity(n, n) - 2 * w * w.transpose();
  const Eigen::EigenSolver<Eigen::MatrixXd> second(Q * K * Q, false);
  if (second.info() != Eigen::Success) return false;
  mu = second.eigenvalues();
  return true;
}

double multiplier_distance(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  if (a.rows() != b.rows()) return std::numeric_limits<double>::infinity();
  Eigen::VectorXcd x, y;
  if (!front_eigenvalues(a, x) || !front_eigenvalues(b, y))
    return std::numeric_limits<double>::quiet_NaN();
  const std::size_t n = static_cast<std::size_t>(x.size());
  if (n == 0) return 0;
  std::vector<double> distances;
  distances.reserve(n * n);
  for (Eigen::Index i = 0; i < x.size(); ++i)
    for (Eigen::Index j = 0; j < y.size(); ++j) distances.push_back(std::abs(x[i] - y[j]));
  std::vector<double> sorted = distances;
  std::sort(sorted.begin(), sorted.end());
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
  // The smallest threshold with a perfect matching: binary search over the distances.
  std::size_t low = 0, high = sorted.size() - 1;
  std::vector<std::vector<int>> adjacent(n);
  while (low < high) {
    const std::size_t middle = (low + high) / 2;
    for (std::size_t i = 0; i < n; ++i) {
      adjacent[i].clear();
      for (std::size_t j = 0; j < n; ++j)
        if (distances[i * n + j] <= sorted[middle]) adjacent[i].push_back(static_cast<int>(j));
    }
    if (perfect_matching(adjacent, n))
      high = middle;
    else
      low = middle + 1;
  }
  return sorted[low];
}

}  // namespace backbone::contact_bar
