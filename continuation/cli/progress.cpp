#include "continuation/cli/progress.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace backbone::cli {

using namespace continuation;  // the algorithms whose settings and points this file handles

ProgressLine::ProgressLine(const ContinuationOptions& options)
    : ProgressLine(options, ::isatty(STDERR_FILENO) == 1) {}

ProgressLine::ProgressLine(const ContinuationOptions& options, bool enabled)
    : options_(options), enabled_(enabled), start_(std::chrono::steady_clock::now()) {}

namespace {

// Fraction of the way from `first` to the bound the observable is heading for (NaN if none).
double bound_fraction(const Bound& bound, double first, double now) {
  const double target = now >= first ? bound.max : bound.min;
  if (!std::isfinite(target) || !std::isfinite(now) || now == first) return std::nan("");
  if (first > 0 && now > 0 && target > 0) return std::log(now / first) / std::log(target / first);
  return (now - first) / (target - first);
}

std::string duration(double seconds) {
  if (!std::isfinite(seconds)) return "?";
  if (seconds < 120) return fmt::format("{:.0f} s", seconds);
  if (seconds < 7200) return fmt::format("{:.0f} min", seconds / 60);
  return fmt::format("{:.1f} h", seconds / 3600);
}

// " period 3.6 frequency 1.74 ...": each observable to ten digits.
std::string observables_text(const core::Observables& observables) {
  std::string text;
  for (const auto& [key, value] : observables) text += fmt::format(" {} {:.10g}", key, value);
  return text;
}

}  // namespace

std::string point_line(const BranchPoint& p) {
  const std::string observables = observables_text(p.observables);
  return fmt::format("point {:4d}{}  dim {}  |F| {:.1e}  newton {}  ds {:.3g}  {:.3f} s", p.index,
                     observables, p.dimension, p.residual, p.newton_iterations, p.step_size,
                     p.seconds);
}

std::string branch_point_line(const BranchPointReport& r) {
  const std::string observables = observables_text(r.observables);
  std::string verdict = r.verified() ? fmt::format("verified, attached dimension {} (nullity {})",
                                                   r.attached_dimension, r.nullity)
                                     : fmt::format("not verified (nullity {})", r.nullity);
  if (r.probed < r.candidates)
    verdict += fmt::format(" [a lower bound: {} of {} candidate directions probed, max_probes]",
                           r.probed, r.candidates);
  if (r.verified())
    for (const auto& [key, value] : r.attached_description)
      verdict += fmt::format(" {} {:.6g}", key, value);
  return fmt::format("branch point after point {}:{}  {}  {} Jacobians  {:.3f} s", r.after_point,
                     observables, verdict, r.jacobian_evaluations, r.seconds);
}

std::string ProgressLine::text(const BranchPoint& point, double elapsed) {
  ++points_;
  const Bound* bound = options_.bounds.empty() ? nullptr : &options_.bounds.front();
  const double value = bound ? point.observable(bound->observable) : std::nan("");
  if (!have_first_) first_value_ = value, have_first_ = true;
  const double rate = elapsed > 0 ? points_ / elapsed : std::nan("");
  double left = (options_.max_points - point.index - 1) / rate;
  if (bound) {
    const double f = bound_fraction(*bound, first_value_, value);
    if (f > 0 && f <= 1) left = std::min(left, elapsed * (1 - f) / f);
  }
  std::string line = fmt::format("point {}", point.index);
  const double energy = point.observable("energy"), frequency = point.observable("frequency");
  if (!std::isnan(energy)) line += fmt::format("  E {:.4g}", energy);
  if (!std::isnan(frequency)) line += fmt::format("  omega {:.6g}", frequency);
  line += fmt::format("  {:.3g} points/s  ETA {}", rate, duration(left));
  if (bound)
    line += fmt::format(" ({} bound {:.3g})", bound->observable,
                        value >= first_value_ ? bound->max : bound->min);
  return line;
}

void ProgressLine::update(const BranchPoint& point) {
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const std::string line = text(point, elapsed);
  if (enabled_) std::fprintf(stderr, "\r\033[K%s", line.c_str()), std::fflush(stderr);
}

void ProgressLine::finish() {
  if (enabled_) std::fprintf(stderr, "\r\033[K"), std::fflush(stderr);
}

}  // namespace backbone::cli
