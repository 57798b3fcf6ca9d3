// The exact solution started from a state in characteristic form, its tangent in the fronts and
// values of that state, and the reader of the state at any time (exact_solution.hpp,
// README.md 'Fronts').
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/errors.hpp"
#include "problems/exact_bar/exact_solution.hpp"

namespace backbone::exact_bar {

using core::InputError;

namespace {

constexpr double epsilon = std::numeric_limits<double>::epsilon();

void check_signal(const char* key, const std::vector<double>& start,
                  const std::vector<double>& value, double tau) {
  if (start.empty() || start.size() != value.size())
    throw InputError(key, fmt::format("needs one value per piece, at least one ({} vs {})",
                                      value.size(), start.size()));
  if (start.front() != 0) throw InputError(key, "the first piece must start at 0");
  for (std::size_t i = 0; i < start.size(); ++i) {
    if (!std::isfinite(start[i]) || !std::isfinite(value[i]))
      throw InputError(key, fmt::format("piece {} is not finite", i));
    if (i > 0 && !(start[i] > start[i - 1]))
      throw InputError(
          key, fmt::format("starts must increase strictly ({} after {})", start[i], start[i - 1]));
  }
  if (!(start.back() < tau))
    throw InputError(
        key, fmt::format("every start must lie below tau = {} (got {})", tau, start.back()));
}

}  // namespace

bar::BarSetup with_characteristic_state(bar::BarSetup setup, const CharacteristicState& state) {
  const double length = setup.material.length, c = setup.material.wave_speed();
  const double tau = length / c;
  check_signal("a_signal", state.a_start, state.a_value, tau);
  check_signal("b_signal", state.b_start, state.b_value, tau);
  // R+(x) = A((L - x) / c), R-(x) = B(x / c): breakpoints at L - c r (A) and c r (B).
  std::vector<double> cuts{0.0, length};
  for (std::size_t i = 1; i < state.a_start.size(); ++i)
    cuts.push_back(length - c * state.a_start[i]);
  for (std::size_t i = 1; i < state.b_start.size(); ++i) cuts.push_back(c * state.b_start[i]);
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
  auto value_at = [](const std::vector<double>& start, const std::vector<double>& value, double r) {
    const auto it = std::upper_bound(start.begin(), start.end(), r);
    return value[static_cast<std::size_t>(it - start.begin()) - 1];
  };
  std::vector<double> ux{0.0}, u{0.0}, vx, v;
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    const double mid = 0.5 * (cuts[i] + cuts[i + 1]);
    const double plus = value_at(state.a_start, state.a_value, (length - mid) / c);
    const double minus = value_at(state.b_start, state.b_value, mid / c);
    ux.push_back(cuts[i + 1]);
    u.push_back(u.back() + (minus - plus) / (2 * c) * (cuts[i + 1] - cuts[i]));
    vx.insert(vx.end(), {cuts[i], cuts[i + 1]});
    v.insert(v.end(), 2, 0.5 * (plus + minus));
  }
  setup.u0 = bar::PiecewiseLinear(std::move(ux), std::move(u));
  setup.v0 = bar::PiecewiseLinear::with_jumps(std::move(vx), std::move(v));
  return setup;
}

ExactBarSolution::ExactBarSolution(const bar::BarSetup& setup, double t_end,
                                   CharacteristicState initial, bool tangent)
    : setup_(setup), t_end_(t_end), initial_(std::move(initial)) {
  setup_.validate();
  if (!std::isfinite(t_end) || t_end < 0)
    throw InputError("t_end", fmt::format("must be finite and >= 0 (got {})", t_end));
  if (setup_.left.type != bar::EndType::fixed)
    throw InputError("left_end", "a state in characteristic form needs the left end fixed");
  if (setup_.body_force != 0)
    throw InputError("body_force", "a state in characteristic form needs no body force");
  c_ = setup_.material.wave_speed();
  tau_ = setup_.material.length / c_;
  b_ = 0;
  check_signal("a_signal", initial_->a_start, initial_->a_value, tau_);
  check_signal("b_signal", initial_->b_start, initial_->b_value, tau_);
  if (tangent) tangent_size_ = initial_->fronts() + initial_->pieces();
  march();
}

// Window 0 from the given pieces; u(L) = int_0^L (R- - R+) / (2 c) dx = (sum_B y dr - sum_A y dr)
// / 2 from the fixed end u(0) = 0. Tangent parameters: A's fronts, B's fronts, A's values, B's.
void ExactBarSolution::seed_characteristic_state(EndState& left_state, EndState& right_state) {
  const CharacteristicState& s = *initial_;
  const int n = tangent_size_;
  const int fa = static_cast<int>(s.a_start.size()) - 1;
  const int fronts = s.fronts();
  const int na = static_cast<int>(s.a_value.size());
  auto unit = [&](int i) {
    Sensitivity e(n);
    e.insert(i) = 1.0;
    return e;
  };
  const Sensitivity zero(n);
  Eigen::VectorXd du = Eigen::VectorXd::Zero(n);
  double u_right = 0;
  auto push = [&](bool of_a) {
    const auto& start = of_a ? s.a_start : s.b_start;
    const auto& value = of_a ? s.a_value : s.b_value;
    const int front0 = of_a ? 0 : fa, value0 = of_a ? fronts : fronts + na;
    const double sign = of_a ? -0.5 : 0.5;  // A carries R+, B carries R-
    auto& sig = of_a ? a_ : b_sig_;
    auto& tan = of_a ? a_tan_ : b_tan_;
    for (std::size_t i = 0; i < start.size(); ++i) {
      const bool last = i + 1 == start.size();
      const double r1 = last ? tau_ : start[i + 1];
      sig.segments.push_back({0, start[i], r1, value[i], 0.0});
      u_right += sign * value[i] * (r1 - start[i]);
      if (n == 0) continue;
      const int j = static_cast<int>(i);
      tan.push_back(
          {i == 0 ? zero : unit(front0 + j - 1), last ? zero : unit(front0 + j), unit(value0 + j)});
      du[value0 + j] += sign * (r1 - start[i]);
      if (i > 0) du[front0 + j - 1] += sign * (value[i - 1] - value[i]);
    }
  };
  push(true);
  push(false);
  const bar::End& right = setup_.right;
  const bool on_a_wall = (right.has_wall() && !(u_right < right.gap)) ||
                         (right.has_back_wall() && !(u_right > -right.gap_back));
  if (right.type == bar::EndType::fixed || on_a_wall)
    throw InputError("right_end", fmt::format("a state in characteristic form needs the right end "
                                              "free of its walls (u(L) = {})",
                                              u_right));
  left_state = EndState{false, 1, 0.0, 0.0, {}};
  right_state = EndState{false, 1, u_right, 0.0, {}};
  if (n > 0) {
    left_state.du = Eigen::VectorXd::Zero(n);
    right_state.du = du;
  }
}

std::vector<SignalPiece> ExactBarSolution::signal_pieces(double t) const {
  check_time(t);
  const Local lt = to_local(t);
  const long k = lt.k;
  const double rt = lt.r, rest = tau_ - lt.r;
  const bool tangent = tangent_size_ > 0;
  const Sensitivity zero(tangent_size_);
  std::vector<SignalPiece> pieces;
  auto read = [&](const Chunked<Segment>& sig, const std::vector<SegmentTangent>& tan, bool of_a) {
    for (long kk : {k, k + 1}) {
      if (kk >= static_cast<long>(sig.first.size())) continue;
      for (std::size_t i = sig.first[kk]; i < sig.end_of(kk); ++i) {
        const Segment& seg = sig.segments[i];
        double s0, s1;
        bool cut;  // starts at t (a window cut, not a breakpoint of the signal)
        if (kk == k) {
          if (!(seg.r1 > rt)) continue;
          cut = !(seg.r0 > rt);
          s0 = cut ? 0.0 : seg.r0 - rt;
          s1 = seg.r1 - rt;
        } else {
          if (!(seg.r0 < rt)) break;
          cut = false;
          s0 = seg.r0 + rest;
          s1 = std::min(seg.r1, rt) + rest;
        }
        if (!(s1 > s0)) continue;
        if (seg.slope != 0)
          throw InputError("t", fmt::format("the signals are not constant near t = {}", t));
        SignalPiece p{of_a, s0, s1, seg.y0, {}, {}};
        if (tangent) {
          p.d_start = cut ? zero : tan[i].dr0;
          p.d_value = tan[i].dy0;
        }
        pieces.push_back(std::move(p));
      }
    }
  };
  read(a_, a_tan_, true);
  read(b_sig_, b_tan_, false);
  return pieces;
}

CharacteristicState ExactBarSolution::characteristic_state(double t) const {
  CharacteristicState s;
  for (const SignalPiece& p : signal_pieces(t)) {
    auto& start = p.of_a ? s.a_start : s.b_start;
    auto& value = p.of_a ? s.a_value : s.b_value;
    if (!value.empty() && std::abs(value.back() - p.value) <=
                              8 * epsilon * (std::abs(value.back()) + std::abs(p.value)))
      continue;
    start.push_back(value.empty() ? 0.0 : p.start);
    value.push_back(p.value);
  }
  return s;
}

}  // namespace backbone::exact_bar
