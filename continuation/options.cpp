#include "continuation/options.hpp"

#include <fmt/format.h>

#include <cmath>

#include "core/errors.hpp"

namespace backbone::continuation {

const char* to_string(Method m) {
  switch (m) {
    case Method::natural:
      return "natural";
    case Method::arclength:
      return "arclength";
    case Method::natural_then_arclength:
      return "natural_then_arclength";
  }
  return "?";
}
const char* to_string(Predictor p) {
  return p == Predictor::secant ? "secant" : p == Predictor::quadratic ? "quadratic" : "tangent";
}

Method parse_method(const std::string& name) {
  if (name == "natural") return Method::natural;
  if (name == "arclength" || name == "pseudo_arclength" || name == "palc") return Method::arclength;
  if (name == "natural_then_arclength") return Method::natural_then_arclength;
  throw core::InputError("method", fmt::format("must be natural, arclength or "
                                               "natural_then_arclength (got '{}')",
                                               name));
}

Predictor parse_predictor(const std::string& name) {
  if (name == "secant") return Predictor::secant;
  if (name == "tangent") return Predictor::tangent;
  if (name == "quadratic") return Predictor::quadratic;
  throw core::InputError("predictor",
                         fmt::format("must be tangent, secant or quadratic (got '{}')", name));
}

namespace {
void require_positive(const char* key, double v) {
  if (!(v > 0) || !std::isfinite(v))
    throw core::InputError(key, fmt::format("must be finite and > 0 (got {})", v));
}
}  // namespace

void ContinuationOptions::validate() const {
  if (!boundary.observable.empty() && !(boundary.within >= 0 && std::isfinite(boundary.within)))
    throw core::InputError("boundary",
                           fmt::format("within must be finite and >= 0 (got {})", boundary.within));
  require_positive("ds", ds);
  require_positive("ds_min", ds_min);
  require_positive("ds_max", ds_max);
  if (ds_min > ds)
    throw core::InputError("ds_min", fmt::format("must be <= ds ({} > {})", ds_min, ds));
  if (ds > ds_max)
    throw core::InputError("ds", fmt::format("must be <= ds_max ({} > {})", ds, ds_max));
  if (fast_iterations < 0)
    throw core::InputError("fast_iterations",
                           fmt::format("must be >= 0 (got {})", fast_iterations));
  if (slow_iterations <= fast_iterations)
    throw core::InputError("slow_iterations", fmt::format("must be > fast_iterations ({} vs {})",
                                                          slow_iterations, fast_iterations));
  if (!(grow_factor >= 1) || !std::isfinite(grow_factor))
    throw core::InputError("grow_factor",
                           fmt::format("must be finite and >= 1 (got {})", grow_factor));
  if (!(shrink_factor > 0 && shrink_factor < 1))
    throw core::InputError("shrink_factor",
                           fmt::format("must be in (0, 1) (got {})", shrink_factor));
  if (max_points < 1)
    throw core::InputError("max_points", fmt::format("must be >= 1 (got {})", max_points));
  if (rank_check_every < 0)
    throw core::InputError("rank_check_every",
                           fmt::format("must be >= 0 (got {})", rank_check_every));
  for (const Bound& b : bounds) {
    if (b.observable.empty()) throw core::InputError("bound", "observable name is empty");
    if (std::isnan(b.min) || std::isnan(b.max) || !(b.min < b.max))
      throw core::InputError(b.observable + "_min", fmt::format("must be < {}_max ({} vs {})",
                                                                b.observable, b.min, b.max));
  }
  rank.validate();
  verification.validate();
  floquet.validate();
  branch_points.validate();
}

void BranchPointOptions::validate() const {
  if (!(max_turn_degrees >= 0 && max_turn_degrees < 180))
    throw core::InputError("max_turn_degrees",
                           fmt::format("must be in [0, 180) (got {})", max_turn_degrees));
  if (!(dip_ratio > 0 && dip_ratio < 1))
    throw core::InputError("branch_points.dip_ratio",
                           fmt::format("must be in (0, 1) (got {})", dip_ratio));
  require_positive("branch_points.location_tolerance", location_tolerance);
  require_positive("branch_points.probe_step", probe_step);
  if (max_probes < 1)
    throw core::InputError("branch_points.max_probes",
                           fmt::format("must be >= 1 (got {})", max_probes));
  if (max_location_steps < 1)
    throw core::InputError("branch_points.max_location_steps",
                           fmt::format("must be >= 1 (got {})", max_location_steps));
}

}  // namespace backbone::continuation
