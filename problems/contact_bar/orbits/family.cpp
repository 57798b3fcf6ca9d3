#include "problems/contact_bar/orbits/family.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "core/errors.hpp"

namespace backbone::contact_bar {

namespace {

// u0 of slopes +-s on [0, L] from its end value u0(L): slope -s back to the last kink, +s to
// the one before, ...; u0(0) = 0 exactly (the sum of the segments rounds).
bar::PiecewiseLinear zigzag_from_end(double length, double end, double s,
                                     const std::vector<double>& kinks) {
  std::vector<double> x{length}, y{end};
  double sign = -1;  // u0' on the segment ending at the current knot
  for (auto k = kinks.rbegin(); k != kinks.rend(); ++k) {
    y.push_back(y.back() - sign * s * (x.back() - *k));
    x.push_back(*k);
    sign = -sign;
  }
  x.push_back(0.0);
  y.push_back(0.0);
  std::reverse(x.begin(), x.end());
  std::reverse(y.begin(), y.end());
  return bar::PiecewiseLinear(std::move(x), std::move(y));
}

}  // namespace

ContactFamily::ContactFamily(const bar::Material& material, double gap, int mode)
    : material_(material), gap_(gap), mode_(mode) {
  if (mode < 1) throw core::InputError("mode", fmt::format("must be >= 1 (got {})", mode));
  if (!(gap > 0) || !std::isfinite(gap))
    throw core::InputError("gap", fmt::format("the contact family needs a gap > 0 (got {})", gap));
}

double ContactFamily::slope(double energy) const {
  return std::sqrt(2 * energy / (material_.axial_stiffness() * material_.length));
}

double ContactFamily::grazing_energy() const {
  const double g = (2 * mode_ - 1) * gap_;  // mode 2 grazes when s L = 3 g0
  return material_.axial_stiffness() * g * g / (2 * material_.length);
}

// Mode 1: README.md, section 'Mode 1'. Mode 2 closed form. With c = L = 1 and u = F(t + x) - F(t -
// x), let H(t) = F'(t - 1) be the wave arriving at x = L. Free end: H(t + 2) = -H(t) and the end
// moves at -2 H(t); closed contact: H(t + 2) = H(t) while H(t) <= 0. v0 = 0 makes H symmetric about
// t = 1 on [0, 2], H(1 +- x) = u0'(x) / 2. Take H = +h on (1 - b, 1 + b), -h elsewhere (the tent u0
// of slopes s = 2h, -2h with crest at b). The end approaches for 2b, sticks for 1 - 3b, recedes for
// 2b: the pattern is periodic with T = 1 + b iff the approach from u0(1) = s (2b - 1) reaches g0 in
// 2b, i.e. b = (1 + g0 / s) / 4, in [1/4, 1/3] (grazing at s = 3 g0). E = s^2 / 2 (EA = 1).
double ContactFamily::period(double energy) const {
  const double length = material_.length, s = slope(energy);
  if (!(s * length >= (2 * mode_ - 1) * gap_)) return std::nan("");
  if (mode_ == 1) return (3 * length + gap_ / s) / material_.wave_speed();
  if (mode_ == 2) return (5 * length + gap_ / s) / (4 * material_.wave_speed());
  const double j = mode_;
  return ((2 * j + 1) * length + gap_ / s) / (j * j * material_.wave_speed());
}

double ContactFamily::frequency(double energy) const {
  return 2 * std::numbers::pi / period(energy);
}

double ContactFamily::linear_frequency() const {
  return (2 * mode_ - 1) * std::numbers::pi * material_.wave_speed() / (2 * material_.length);
}

double ContactFamily::asymptotic_frequency() const {
  const double c = material_.wave_speed(), length = material_.length;
  if (mode_ == 1) return 2 * std::numbers::pi * c / (3 * length);
  if (mode_ == 2) return 8 * std::numbers::pi * c / (5 * length);
  const double j = mode_;
  return 2 * std::numbers::pi * j * j * c / ((2 * j + 1) * length);
}

double ContactFamily::node(double energy) const {
  const double s = slope(energy), length = material_.length;
  if (mode_ != 2 || !(s * length >= 3 * gap_)) return std::nan("");
  const double b = 0.25 * (1 + gap_ / (s * length));
  return 2 * b * length;
}

// Mode J (README.md, section 'Mode J'): with gamma = g0 / (s L), A = (J + 1 - (J - 1) gamma) /
// J^2, B = (1 + gamma) / J and P = A + B (lengths in L), u0' = -s where the distance from the
// end, xi = L - x, has xi mod P L in [0, A L), +s elsewhere: kinks at xi = A, P, P + A, 2P, ...
std::vector<double> ContactFamily::kinks(double energy) const {
  const double length = material_.length, s = slope(energy);
  std::vector<double> at;
  if (!(s * length >= (2 * mode_ - 1) * gap_) || !std::isfinite(s)) return at;
  const double j = mode_, gamma = gap_ / (s * length);
  const double a = (j + 1 - (j - 1) * gamma) / (j * j), b = (1 + gamma) / j, p = a + b;
  for (int k = 1; static_cast<int>(at.size()) < mode_ - 1; ++k) {
    at.push_back(length * (1 - ((k - 1) * p + a)));                                   // xi_{2k-1}
    if (static_cast<int>(at.size()) < mode_ - 1) at.push_back(length * (1 - k * p));  // xi_{2k}
  }
  std::reverse(at.begin(), at.end());
  return at;
}

bar::PiecewiseLinear ContactFamily::u0(double energy) const {
  const double length = material_.length, s = slope(energy);
  if (!(s * length >= (2 * mode_ - 1) * gap_) || !std::isfinite(s))
    throw core::InputError("energy",
                           fmt::format("mode {} exists from its grazing energy {} (got {})", mode_,
                                       grazing_energy(), energy));
  return zigzag_from_end(length, -(s * length - (mode_ - 1) * gap_) / mode_, s, kinks(energy));
}

ClearanceMode::ClearanceMode(const bar::Material& material, double gap, double gap_back, int mode)
    : material_(material), gap_(gap), gap_back_(gap_back), mode_(mode) {
  if (mode < 1) throw core::InputError("mode", fmt::format("must be >= 1 (got {})", mode));
  if (!(gap > 0) || !std::isfinite(gap))
    throw core::InputError("gap", fmt::format("the clearance modes need a gap > 0 (got {})", gap));
  if (!(gap_back >= gap) || !std::isfinite(gap_back))
    throw core::InputError("gap_back",
                           fmt::format("the clearance modes start on the nearer wall, the front "
                                       "one: gap_back >= gap = {} (got {}); mirror the scene",
                                       gap, gap_back));
}

double ClearanceMode::slope(double energy) const {
  return std::sqrt(2 * energy / (material_.axial_stiffness() * material_.length));
}

double ClearanceMode::grazing_energy() const {
  const double g = (2 * mode_ - 1) * gap_;
  return material_.axial_stiffness() * g * g / (2 * material_.length);
}

double ClearanceMode::back_grazing_energy() const {
  const double g = mode_ * gap_back_ + (mode_ - 1) * gap_;
  return material_.axial_stiffness() * g * g / (2 * material_.length);
}

// Derivation (README.md, 'Modes in a clearance'; c = L = 1, H as in 'Mode J'): H T-periodic,
// -h for A and +h for B. With 2 = J T - delta the shift by 2 is -delta modulo T: where
// H(t - delta) = H(t) the end is closed (front while H = -h, back while H = +h), elsewhere free,
// so each wall holds for A - delta resp. B - delta and the flights last delta. The walls:
// w = int_t^{t+2} H at the start of each phase gives J h (B - A) + h delta = g and
// J h (B - A) - h delta = -g_back, so delta = gamma + gamma_b, A = (1 + gamma_b) / J,
// B = (1 + gamma) / J. The back phase exists while B > delta; at B = delta, A equals mode J's
// one-sided A, so the two regimes join continuously.
ClearanceMode::Blocks ClearanceMode::blocks(double energy) const {
  const double s = slope(energy), length = material_.length, nan = std::nan("");
  if (!(s * length >= (2 * mode_ - 1) * gap_) || !std::isfinite(s)) return {nan, nan, nan};
  const double j = mode_, gamma = gap_ / (s * length), gamma_b = gap_back_ / (s * length);
  const double b = (1 + gamma) / j;
  // One wall: mode J's A (README.md, 'Mode J'); the end recedes for B and approaches for B.
  if (energy <= back_grazing_energy()) return {(j + 1 - (j - 1) * gamma) / (j * j), b, b};
  return {(1 + gamma_b) / j, b, gamma + gamma_b};
}

double ClearanceMode::period(double energy) const {
  const Blocks k = blocks(energy);
  return (k.a + k.b) * material_.travel_time();
}

double ClearanceMode::frequency(double energy) const {
  return 2 * std::numbers::pi / period(energy);
}

double ClearanceMode::front_contact(double energy) const {
  const Blocks k = blocks(energy);
  return (k.a - k.delta) * material_.travel_time();
}

double ClearanceMode::back_contact(double energy) const {
  const Blocks k = blocks(energy);
  return (k.b - k.delta) * material_.travel_time();
}

std::vector<double> ClearanceMode::kinks(double energy) const {
  const double length = material_.length;
  const Blocks k = blocks(energy);
  std::vector<double> at;
  if (!std::isfinite(k.a)) return at;
  // In units of L: C/2 + i T and C/2 + B + i T from the end (C = A - delta the front phase,
  // T = A + B), the first J of them.
  const double half = 0.5 * (k.a - k.delta), p = k.a + k.b;
  for (int i = 0; static_cast<int>(at.size()) < mode_; ++i) {
    at.push_back(length * (1 - (half + i * p)));
    if (static_cast<int>(at.size()) < mode_) at.push_back(length * (1 - (half + k.b + i * p)));
  }
  std::reverse(at.begin(), at.end());
  return at;
}

bar::PiecewiseLinear ClearanceMode::u0(double energy) const {
  const double length = material_.length, s = slope(energy);
  if (!(s * length >= (2 * mode_ - 1) * gap_) || !std::isfinite(s))
    throw core::InputError("energy",
                           fmt::format("clearance mode {} exists from its grazing energy {} (got "
                                       "{})",
                                       mode_, grazing_energy(), energy));
  return zigzag_from_end(length, gap_, s, kinks(energy));  // on the front wall
}

double node_of(const bar::PiecewiseLinear& u0) {
  const auto& xs = u0.knots();
  const auto& ys = u0.values();
  for (std::size_t i = 2; i < xs.size(); ++i)
    if ((ys[i - 1] > 0 && ys[i] <= 0) || (ys[i - 1] < 0 && ys[i] >= 0))
      return xs[i - 1] + (xs[i] - xs[i - 1]) * ys[i - 1] / (ys[i - 1] - ys[i]);
  return std::nan("");
}

// Derivation (c = L = 1, u = F(t + x) - F(t - x), H(t) = F'(t - 1) the wave arriving at x = 1,
// README.md sections 'Subharmonic continuum' and 'Subharmonic continuum of mode J'): over
// 2 T_J, two pulses of width B and two stretches A_a + A_b = 2A; for even J each pulse is its
// own echo under the shift by 2, so every split with A_a, A_b >= B holds, and the wall condition
// is mode J's. J = 2: B = 2b, b = (1 + g0/s)/4, kinks at (1 - c -+ b) L with c = b + shape D.
SubharmonicMember subharmonic_member(const bar::Material& material, double gap, double energy,
                                     double shape, int mode) {
  if (mode < 2 || mode % 2 != 0)
    throw core::InputError("mode", fmt::format("the subharmonic continuum over two periods "
                                               "exists for even modes only (got {})",
                                               mode));
  const double length = material.length;
  const double s = std::sqrt(2 * energy / (material.axial_stiffness() * length));
  if (!(s * length >= (2 * mode - 1) * gap) || !std::isfinite(s))
    throw core::InputError(
        "energy", fmt::format("the subharmonic continuum needs E >= the mode-{} "
                              "grazing energy {} (got {})",
                              mode, ContactFamily(material, gap, mode).grazing_energy(), energy));
  if (!(shape >= 0 && shape <= 1))
    throw core::InputError("shape", fmt::format("must be in [0, 1] (got {})", shape));
  const double tau = length / material.wave_speed();
  // Mode J even (README.md, 'Subharmonic continuum of mode J'), lengths in L: gamma = g0 / (sL),
  // B = (1 + gamma) / J, A = (J + 1 - (J - 1) gamma) / J^2, T_J = A + B, D = A - B. Kinks at
  // L - x = o_k + k T_J and o_k + k T_J + B for k = 0 .. J/2 - 1, o_k = shape D (k even) or
  // (1 - shape) D (k odd); slopes -s, +s, ..., -s from x = 0; u0(L) = g0.
  const double j = mode;
  const double gamma = gap / (s * length);
  const double B = (1 + gamma) / j, A = (j + 1 - (j - 1) * gamma) / (j * j);
  const double T = A + B, D = A - B;
  std::vector<double> kinks;
  for (int k = 0; k < mode / 2; ++k) {
    const double o = (k % 2 == 0 ? shape : 1 - shape) * D + k * T;
    kinks.push_back((1 - o) * length);
    kinks.push_back((1 - o - B) * length);
  }
  std::sort(kinks.begin(), kinks.end());
  std::vector<double> knots{0.0}, values{0.0};
  double slope = -s;
  for (const double x : kinks) {
    if (x >= length) break;  // shape 0: the kink nearest the end sits on it
    values.push_back(values.back() + slope * (x - knots.back()));
    knots.push_back(x);
    slope = -slope;
  }
  knots.push_back(length);
  values.push_back(gap);  // the slopes sum to g0 (README.md), up to rounding
  return {bar::PiecewiseLinear(std::move(knots), std::move(values)), 2 * T * tau,
          2 * shape * D * tau, 2 * (1 - shape) * D * tau, std::move(kinks)};
}

}  // namespace backbone::contact_bar
