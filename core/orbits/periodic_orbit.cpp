#include "core/orbits/periodic_orbit.hpp"

#include <fmt/format.h>

#include "core/errors.hpp"

namespace backbone::core {

const char* to_string(ShootingFormulation f) {
  switch (f) {
    case ShootingFormulation::displacement_periodicity:
      return "displacement_periodicity";
    case ShootingFormulation::half_period_velocity:
      return "half_period_velocity";
  }
  return "?";
}

const char* scene_name(ShootingFormulation f) {
  return f == ShootingFormulation::displacement_periodicity ? "paper" : "regular";
}

ShootingFormulation parse_formulation(const std::string& name) {
  if (name == "paper" || name == "displacement_periodicity")
    return ShootingFormulation::displacement_periodicity;
  if (name == "regular" || name == "half_period_velocity")
    return ShootingFormulation::half_period_velocity;
  throw InputError("formulation",
                   fmt::format("unknown formulation '{}' (expected paper, "
                               "displacement_periodicity, regular or half_period_velocity)",
                               name));
}

void PeriodicOrbitProblem::initial_state_samples(const Vector& x, Vector& coordinates,
                                                 Vector& values) const {
  coordinates = state_coordinates();
  values = x.head(state_size());
}

Vector PeriodicOrbitProblem::state_coordinates() const {
  const int s = state_size();
  return Vector::LinSpaced(s, 0.0, static_cast<double>(s - 1));
}

Observables PeriodicOrbitProblem::observables(const Vector& x) const {
  return {{"period", period(x)}, {"frequency", frequency(x)}, {"energy", energy(x)}};
}

}  // namespace backbone::core
