#include "problems/exact_bar/front_monodromy.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace backbone::exact_bar {

namespace {

// The largest |value| of the state: the scale of its jumps.
double value_scale(const CharacteristicState& state) {
  double scale = 0;
  for (const auto* v : {&state.a_value, &state.b_value})
    for (double y : *v) scale = std::max(scale, std::abs(y));
  return scale;
}

}  // namespace

CharacteristicState without_small_jumps(const CharacteristicState& state, double tolerance,
                                        double tau) {
  const double scale = value_scale(state);
  const double sliver = 1e-9 * tau;
  CharacteristicState out;
  for (bool of_a : {true, false}) {
    const auto& start = of_a ? state.a_start : state.b_start;
    const auto& value = of_a ? state.a_value : state.b_value;
    auto& out_start = of_a ? out.a_start : out.b_start;
    auto& out_value = of_a ? out.a_value : out.b_value;
    double weight = 0;  // of the last output piece, for its running average
    for (std::size_t i = 0; i < start.size(); ++i) {
      const double length = (i + 1 < start.size() ? start[i + 1] : tau) - start[i];
      // A sliver is dropped; the piece after it starts where it did.
      if (length < sliver && i + 1 < start.size()) continue;
      if (!out_value.empty() && std::abs(value[i] - out_value.back()) <= tolerance * scale) {
        out_value.back() = (out_value.back() * weight + value[i] * length) / (weight + length);
        weight += length;
        continue;
      }
      out_start.push_back(out_start.empty()                           ? 0.0
                          : i > 0 && start[i] - start[i - 1] < sliver ? start[i - 1]
                                                                      : start[i]);
      out_value.push_back(value[i]);
      weight = length;
    }
  }
  return out;
}

OrbitState free_flight_state(const ExactBarSolution& orbit, double period, double jump_tolerance) {
  const bar::BarSetup& setup = orbit.setup();
  const double tau = setup.material.length / setup.material.wave_speed();
  std::vector<double> events;
  std::vector<std::pair<double, double>> flights;  // the free flights within [0, T)
  double free_from = 0;
  for (const ContactInterval& c : orbit.contact_intervals(Side::right)) {
    events.push_back(c.t_close);
    events.push_back(c.t_release);
    if (c.t_close > free_from) flights.emplace_back(free_from, std::min(c.t_close, period));
    free_from = c.t_release;
  }
  if (free_from < period) flights.emplace_back(free_from, period);
  OrbitState best{std::numeric_limits<double>::quiet_NaN(), {}};
  if (flights.empty()) return best;

  // A front with start r at t_ref reaches an end at t_ref + r + k tau. The tangent march from t0
  // reads the fronts at t0 + T, and its windows start at t0 + k tau: a front on a window's edge
  // there or at t0 has no derivative of its own. So the fronts' phases at t0 must stay away from
  // 0 and from -T (mod tau): t0's phase (from t_ref) away from every r and every r + T.
  // Candidates: 16 evenly spaced times in each flight (a flight may be far shorter than T / 16
  // when both walls of a clearance are near) and the middle of each gap between those phases
  // that falls in a flight (a followed family has a front on every node).
  const double t_ref = flights.front().first;
  auto wrap = [&](double r) {
    r = std::fmod(r, tau);
    return r < 0 ? r + tau : r;
  };
  // t_ref is a flight's start or 0, where a front may sit at an end (a release emits one): its
  // phase, 0, counts too.
  std::vector<double> phases{0.0, wrap(period)};
  {
    const CharacteristicState ref =
        without_small_jumps(orbit.characteristic_state(t_ref), jump_tolerance, tau);
    for (const auto* start : {&ref.a_start, &ref.b_start})
      for (std::size_t i = 1; i < start->size(); ++i) {
        phases.push_back((*start)[i]);
        phases.push_back(wrap((*start)[i] + period));
      }
    std::sort(phases.begin(), phases.end());
  }
  auto margin = [&](double t, double a, double b) {
    double m = std::min({tau, t - a, b - t});
    for (double e : events) m = std::min(m, std::abs(e - t));
    const double r = wrap(t - t_ref);
    auto it = std::lower_bound(phases.begin(), phases.end(), r);
    const double above = it != phases.end() ? *it : phases.front() + tau;
    const double below = it != phases.begin() ? *(it - 1) : phases.back() - tau;
    return std::min({m, above - r, r - below});
  };
  std::vector<double> gaps;  // the middle of each gap between consecutive phases
  for (std::size_t i = 0; i < phases.size(); ++i)
    gaps.push_back(
        wrap(0.5 * (phases[i] + (i + 1 < phases.size() ? phases[i + 1] : phases.front() + tau))));
  double best_margin = -1, best_t = 0;
  auto consider = [&](double t, double a, double b) {
    if (!(t > a && t < b)) return;
    const double m = margin(t, a, b);
    if (m > best_margin) {
      best_margin = m;
      best_t = t;
    }
  };
  constexpr int per_flight = 16;
  for (const auto& [a, b] : flights) {
    for (int j = 0; j < per_flight; ++j) consider(a + (b - a) * (j + 0.5) / per_flight, a, b);
    for (double g : gaps)
      for (double t = t_ref + g + std::floor((a - t_ref - g) / tau) * tau; t < b; t += tau)
        consider(t, a, b);
  }
  if (!(best_margin > 0) || orbit.in_contact(Side::right, best_t)) return best;
  best.t0 = best_t;
  best.state = without_small_jumps(orbit.characteristic_state(best_t), jump_tolerance, tau);
  return best;
}

FrontMonodromy front_monodromy(const bar::BarSetup& setup, const CharacteristicState& state,
                               double period, double jump_tolerance) {
  FrontMonodromy out;
  const ExactBarSolution sol(setup, period, state, true);
  if (!sol.ok()) {
    out.message = sol.message();
    return out;
  }
  const double tau = setup.material.length / setup.material.wave_speed();
  const int fronts = state.fronts(), pieces = state.pieces();
  const int fa = static_cast<int>(state.a_start.size()) - 1;
  const double scale = value_scale(state);
  if (!(scale > 0)) {
    out.message = "the state is at rest with no strain";
    return out;
  }
  const std::vector<SignalPiece> at_t = sol.signal_pieces(period);

  // The fronts at T. A front of the state at 0 may come back as a few breakpoints within round-
  // off of each other (events re-created from a traced orbit's slightly imperfect data), each
  // with part of its jump: to first order they act as one front at their jump-weighted mean
  // position, so each state front's row is sum(jump_i d_start_i) / sum(jump_i) over the
  // breakpoints within 1e-6 tau of it. A breakpoint with a jump over the tolerance and no
  // state front near it means the orbit did not come back.
  out.K.setZero(fronts, fronts);
  out.C.setZero(fronts, pieces);
  const double match = 1e-6 * tau, jump = jump_tolerance * scale;
  Eigen::MatrixXd weighted = Eigen::MatrixXd::Zero(fronts, fronts + pieces);
  Eigen::VectorXd total = Eigen::VectorXd::Zero(fronts), position = Eigen::VectorXd::Zero(fronts);
  for (bool of_a : {true, false}) {
    const auto& start = of_a ? state.a_start : state.b_start;
    const auto& value = of_a ? state.a_value : state.b_value;
    const SignalPiece* previous = nullptr;
    for (const SignalPiece& p : at_t) {
      if (p.of_a != of_a) continue;
      if (previous) {
        const double step = p.value - previous->value;
        auto it = std::min_element(start.begin() + 1, start.end(), [&](double a, double b) {
          return std::abs(a - p.start) < std::abs(b - p.start);
        });
        if (it != start.end() && std::abs(*it - p.start) <= match) {
          const int i = static_cast<int>(it - start.begin()) - 1 + (of_a ? 0 : fa);
          total[i] += step;
          position[i] += step * p.start;
          for (Sensitivity::InnerIterator e(p.d_start); e; ++e)
            weighted(i, e.index()) += step * e.value();
        } else if (std::abs(step) > jump) {
          out.message = fmt::format("a front at T (r = {}) has none at 0 to match", p.start);
          return out;
        }
      }
      previous = &p;
    }
    // Values: each piece at T (but slivers between parts of one front) against the state's
    // value at the same r.
    for (const SignalPiece& p : at_t) {
      if (p.of_a != of_a || p.end - p.start <= match) continue;
      const double mid = 0.5 * (p.start + p.end);
      const auto j = static_cast<std::size_t>(std::upper_bound(start.begin(), start.end(), mid) -
                                              start.begin() - 1);
      out.return_error = std::max(out.return_error, std::abs(p.value - value[j]) / scale);
    }
  }
  // A state front is found when its jump comes back (to half of it: the orbit's error is far
  // smaller, and a front near the tolerance may come back as parts under it).
  int matched = 0;
  for (int i = 0; i < fronts; ++i) {
    const bool of_a = i < fa;
    const auto k = static_cast<std::size_t>(of_a ? i + 1 : i - fa + 1);
    const auto& value = of_a ? state.a_value : state.b_value;
    const double jump0 = value[k] - value[k - 1];
    if (!(std::abs(total[i] - jump0) <= 0.5 * std::abs(jump0))) continue;
    ++matched;
    out.K.row(i) = weighted.row(i).head(fronts) / total[i];
    out.C.row(i) = weighted.row(i).tail(pieces) / total[i];
    const double r0 = of_a ? state.a_start[k] : state.b_start[k];
    out.return_error = std::max(out.return_error, std::abs(position[i] / total[i] - r0) / tau);
  }
  if (matched != fronts) {
    out.message = fmt::format("{} of the {} fronts at 0 found at T", matched, fronts);
    return out;
  }

  // The values' images: no front shift may reach them, and they keep the L2 product.
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(at_t.size()), pieces);
  Eigen::VectorXd w_out(static_cast<Eigen::Index>(at_t.size()));
  for (std::size_t i = 0; i < at_t.size(); ++i) {
    const SignalPiece& p = at_t[i];
    w_out[static_cast<Eigen::Index>(i)] = p.end - p.start;
    for (Sensitivity::InnerIterator e(p.d_value); e; ++e) {
      if (e.index() < fronts)
        out.value_leak = std::max(out.value_leak, std::abs(e.value()) / scale);
      else
        D(static_cast<Eigen::Index>(i), e.index() - fronts) = e.value();
    }
  }
  Eigen::VectorXd w_in(pieces);
  int j = 0;
  for (bool of_a : {true, false}) {
    const auto& start = of_a ? state.a_start : state.b_start;
    for (std::size_t i = 0; i < start.size(); ++i, ++j)
      w_in[j] = (i + 1 < start.size() ? start[i + 1] : tau) - start[i];
  }
  const Eigen::MatrixXd G = D.transpose() * w_out.asDiagonal() * D;
  const Eigen::MatrixXd W = w_in.asDiagonal();
  out.isometry_error = (G - W).cwiseAbs().maxCoeff() / w_in.maxCoeff();
  out.time_shift_error =
      (out.K * Eigen::VectorXd::Ones(fronts) - Eigen::VectorXd::Ones(fronts)).cwiseAbs().maxCoeff();
  out.ok = true;
  return out;
}

}  // namespace backbone::exact_bar
