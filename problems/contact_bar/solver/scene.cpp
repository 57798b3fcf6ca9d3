#include "problems/contact_bar/solver/scene.hpp"

#include <fmt/format.h>

#include <cmath>
#include <sstream>

#include "core/errors.hpp"

namespace backbone::contact_bar {

using core::InputError;

namespace {

// Every dimensional input is of magnitude in [1e-30, 1e30] (or 0 where 0 is allowed): the solvers
// form products of up to about five of them (energy = EA L u_x^2 / 2, ...), which then stay far
// inside double precision (1e-308 .. 1e308) instead of silently underflowing to an energy of 0 J.
constexpr double smallest_magnitude = 1e-30;
constexpr double largest_magnitude = 1e30;

double within_double_range(const std::string& key, double v) {
  if (v != 0 && !(std::abs(v) >= smallest_magnitude && std::abs(v) <= largest_magnitude))
    throw InputError(key, fmt::format("must be of magnitude in [{:g}, {:g}] (got {}): double "
                                      "precision cannot hold the products the solvers form",
                                      smallest_magnitude, largest_magnitude, v));
  return v;
}

// Knots closer than this fraction of the length are below what the solvers resolve: their time
// and position arithmetic carries a relative error of about 1e-14, which closer knots turn into
// an error of the slopes, and so of the energy, far above round-off.
constexpr double knot_resolution = 1e-9;

}  // namespace

po::options_description scene_keys() {
  po::options_description keys("contact bar scene keys");
  keys.add_options()("problem", po::value<std::string>()->default_value("contact_bar"),
                     "problem the scene is for (contact_bar)")(
      "length", po::value<double>()->default_value(1.0), "bar length L [m] (> 0)")(
      "youngs_modulus", po::value<double>()->default_value(1.0), "Young's modulus E [Pa] (> 0)")(
      "density", po::value<double>()->default_value(1.0), "density rho [kg/m^3] (> 0)")(
      "area", po::value<double>()->default_value(1.0), "cross-section area A [m^2] (> 0)")(
      "left_end", po::value<std::string>()->default_value("fixed"),
      "end condition at x = 0: fixed | free | contact | clearance")(
      "right_end", po::value<std::string>()->default_value("contact"),
      "end condition at x = L: fixed | free | contact | clearance (between two walls)")(
      "gap", po::value<double>()->default_value(0.0),
      "distance from a contact or clearance end to its (front) wall at rest [m] (>= 0)")(
      "gap_back", po::value<double>()->default_value(0.0),
      "distance from a clearance end to the wall behind it at rest [m] (> 0 with a clearance "
      "end, else 0)")("body_force", po::value<double>()->default_value(0.0),
                      "constant body force per unit volume along +x [N/m^3]")(
      "u0", po::value<std::string>()->default_value(""),
      "initial displacement, knots \"x:u x:u ...\" (x in [0, L] [m], u [m]; empty = 0)")(
      "v0", po::value<std::string>()->default_value(""),
      "initial velocity, knots \"x:v x:v ...\" (x in [0, L] [m], v [m/s]; empty = 0)")(
      "elements", po::value<long>()->default_value(100),
      "space intervals of the node grid (interior output, FEM mesh) (>= 1)")(
      "dt", po::value<double>()->default_value(1e-3), "time step [s] (> 0; TD-BEM: <= L/c)")(
      "contact", po::value<std::string>()->default_value("event"),
      "contact treatment of the TD-BEM: event (split steps at contact instants) | "
      "projection (paper Algorithm 1)")(
      "period", po::value<double>()->default_value(4.0),
      "reference period of the scene [s] (> 0); --periods P simulates P of them")(
      "history_samples", po::value<long>()->default_value(2000),
      "at most this many rows in the history (>= 2)")(
      "probes", po::value<std::string>()->default_value(""),
      "interior points whose displacement is recorded, \"x x ...\" [m] (in [0, L])");
  return keys;
}

std::vector<double> parse_numbers(const std::string& key, const std::string& text) {
  std::vector<double> values;
  for (const std::string& word : core::list_words(text, ",;")) {
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(word, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != word.size()) throw InputError(key, fmt::format("'{}' is not a number", word));
    if (!std::isfinite(v)) throw InputError(key, fmt::format("must be finite (got {})", word));
    values.push_back(v);
  }
  return values;
}

bar::PiecewiseLinear parse_knots(const std::string& key, const std::string& text, double length) {
  std::istringstream in(text);
  std::vector<double> xs, ys;
  std::string word;
  while (in >> word) {
    const auto colon = word.find(':');
    if (colon == std::string::npos)
      throw InputError(key, fmt::format("knot '{}' is not of the form x:value", word));
    const auto x = parse_numbers(key, word.substr(0, colon));
    const auto y = parse_numbers(key, word.substr(colon + 1));
    if (x.size() != 1 || y.size() != 1)
      throw InputError(key, fmt::format("knot '{}' is not of the form x:value", word));
    if (x[0] < 0 || x[0] > length)
      throw InputError(key,
                       fmt::format("knot position {} outside [0, length] = [0, {}]", x[0], length));
    if (!xs.empty() && !(x[0] > xs.back()))
      throw InputError(
          key, fmt::format("knot positions must increase strictly ({} after {})", x[0], xs.back()));
    if (!xs.empty() && x[0] - xs.back() < knot_resolution * length)
      throw InputError(key,
                       fmt::format("knots {} and {} are closer than {:g} length = {:g} m: "
                                   "double precision does not resolve them on this bar",
                                   xs.back(), x[0], knot_resolution, knot_resolution * length));
    within_double_range(key, y[0]);
    xs.push_back(x[0]);
    ys.push_back(y[0]);
  }
  if (xs.empty()) return bar::PiecewiseLinear::zero(length);
  try {
    return bar::PiecewiseLinear(xs, ys);
  } catch (const InputError& e) {
    throw InputError(key, e.what());
  }
}

bar::BarSetup bar_from_scene(const core::Scene& scene) {
  bar::BarSetup s;
  s.material.length = within_double_range("length", scene.positive("length"));
  s.material.youngs_modulus =
      within_double_range("youngs_modulus", scene.positive("youngs_modulus"));
  s.material.density = within_double_range("density", scene.positive("density"));
  s.material.area = within_double_range("area", scene.positive("area"));
  const double gap = within_double_range("gap", scene.non_negative("gap"));
  const double gap_back = within_double_range("gap_back", scene.non_negative("gap_back"));
  s.left = {bar::parse_end_type("left_end", scene.text("left_end")), gap, gap_back};
  s.right = {bar::parse_end_type("right_end", scene.text("right_end")), gap, gap_back};
  const bool clearance = s.left.has_back_wall() || s.right.has_back_wall();
  if (clearance && !(gap_back > 0))
    throw InputError("gap_back", "must be > 0 with a clearance end (got 0)");
  if (!clearance && gap_back != 0)
    throw InputError("gap_back", fmt::format("is read only with left_end or right_end = "
                                             "clearance (got {} with neither)",
                                             gap_back));
  s.body_force = within_double_range("body_force", scene.number("body_force"));
  s.u0 = bar::PiecewiseLinear::zero(s.material.length);
  s.v0 = bar::PiecewiseLinear::zero(s.material.length);
  s.validate();
  return s;
}

bar::BarSetup setup_from_scene(const core::Scene& scene) {
  bar::BarSetup s = bar_from_scene(scene);
  s.u0 = parse_knots("u0", scene.has("u0") ? scene.text("u0") : "", s.material.length);
  s.v0 = parse_knots("v0", scene.has("v0") ? scene.text("v0") : "", s.material.length);
  s.validate();
  return s;
}

bar::SimulationOptions simulation_from_scene(const core::Scene& scene, double periods) {
  if (!std::isfinite(periods) || !(periods > 0))
    throw InputError("periods", fmt::format("must be > 0 (got {})", periods));
  bar::SimulationOptions o;
  const double period = within_double_range("period", scene.positive("period"));
  o.t_end = periods * period;
  if (!std::isfinite(o.t_end))
    throw InputError("periods",
                     fmt::format("periods * period = {} * {} s overflows", periods, period));
  o.dt = within_double_range("dt", scene.positive("dt"));
  constexpr long most = 100'000'000;
  o.elements = static_cast<int>(scene.integer("elements", 1, most));
  o.history_samples = static_cast<int>(scene.integer("history_samples", 2, most));
  o.probes = parse_numbers("probes", scene.has("probes") ? scene.text("probes") : "");
  const double length = scene.positive("length");
  for (double p : o.probes)
    if (p < 0 || p > length)
      throw InputError("probes",
                       fmt::format("must lie in [0, length] = [0, {}] (got {})", length, p));
  o.validate();
  return o;
}

ContactMethod contact_method_from_scene(const core::Scene& scene) {
  return parse_contact_method("contact", scene.text("contact"));
}

}  // namespace backbone::contact_bar
