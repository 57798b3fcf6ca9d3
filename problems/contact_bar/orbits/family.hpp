// The contact family of the bar: closed forms of its nonlinear modes 1 and 2, in one place.
//
// Every report, figure and benchmark that compares a traced branch with the exact answer asks
// this class (problems/contact_bar/README.md, sections "Exact mode 1" and "Exact mode 2"):
//   mode 1: u0 = eps x, T = (3L + g0/|eps|)/c, grazing at E = EA g0^2 / (2L),
//           omega -> 2 pi c / (3L) as E grows;
//   mode 2: a tent of slopes +-s with its crest at bL, b = (1 + g0/(sL))/4,
//           T = (5L + g0/s) / (4c), grazing at E = EA (3 g0)^2 / (2L), omega -> 8 pi c / (5L);
//           u0 changes sign at x = 2bL, the mode's node (the quasi-node of the space-time
//           figure: the point that moves least).
//   mode J >= 1 (README.md, section 'Mode J'; J = 1, 2 are the two above): u0 of slopes +-s
//           with J - 1 kinks, T = ((2J + 1) L + g0/s) / (J^2 c), grazing at
//           E = EA ((2J - 1) g0)^2 / (2L) with the linear period 4L / ((2J - 1) c),
//           omega -> 2 pi J^2 c / ((2J + 1) L);
// with s = |eps| = sqrt(2E / (EA L)). Frequencies are NaN below grazing.
//
//   ContactFamily mode1(setup.material, setup.right.gap, 1);
//   double w = mode1.frequency(1e-3);                 // closed form at E = 1e-3 J
//   double err = std::abs(point_frequency / w - 1);
//   double e0 = mode1.grazing_energy();               // EA g0^2 / (2L)
//   ContactFamily mode2(setup.material, gap, 2);
//   double x_node = mode2.node(1e-3);                 // 2 b L
//   double x_num = node_of(orbit_u0);                 // where a traced u0 changes sign
//   SubharmonicMember m = subharmonic_member(material, gap, 1e-3, 0.25);  // T = 2 T2
//   m.u0;  m.period;  m.first_contact;  m.second_contact;                 // durations [s]
#pragma once

#include <vector>

#include "problems/bar/bar.hpp"

namespace backbone::contact_bar {

class ContactFamily {
 public:
  // mode >= 1 (InputError "mode" otherwise); gap > 0 (InputError "gap").
  ContactFamily(const bar::Material& material, double gap, int mode);

  int mode() const { return mode_; }
  // Strain magnitude s = sqrt(2E / (EA L)) of the orbit of energy E.
  double slope(double energy) const;
  // Energy at which the family grazes the wall (contact duration -> 0).
  double grazing_energy() const;
  // Closed-form period and frequency 2 pi / T at energy E; NaN below grazing.
  double period(double energy) const;
  double frequency(double energy) const;
  // Linear mode (2k - 1) pi c / (2L), where the family is born, and the limit as E -> inf.
  double linear_frequency() const;
  double asymptotic_frequency() const;
  // Mode 2: position 2bL where u0 changes sign (NaN for mode 1, which has no interior node,
  // for modes above 2, and below grazing).
  double node(double energy) const;
  // The J - 1 kinks of u0 at energy E, increasing in x (empty below grazing), and u0 itself:
  // slopes +-s, u0(0) = 0, u0(L) = -(s L - (J - 1) g0) / J (README.md, section 'Mode J').
  std::vector<double> kinks(double energy) const;
  bar::PiecewiseLinear u0(double energy) const;  // InputError "energy" below grazing

 private:
  bar::Material material_;
  double gap_;
  int mode_;
};

// Mode J of a bar whose end moves in a clearance: a front wall at gap g, a back wall at
// gap_back >= g behind the rest position (README.md, section 'Modes in a clearance'). The orbit
// starts at rest at the centre of a front contact phase, u0(L) = g, with J kinks; slopes +-s,
// E = EA L s^2 / 2. With gamma = g / (s L), gamma_b = g_back / (s L), lengths in L, times in L/c:
//   front grazing at s L = (2J - 1) g (the linear mode J, T = 4 / (2J - 1));
//   back grazing at s L = J g_back + (J - 1) g; below it the orbit is mode J of the one-sided
//   bar (ContactFamily), T = ((2J + 1) + gamma) / J^2; above it
//   T = (2 + gamma + gamma_b) / J, a front phase of (1 + gamma_b) / J - gamma - gamma_b and a
//   back phase of (1 + gamma) / J - gamma - gamma_b per period, free flights of
//   gamma + gamma_b between them;
//   kinks at L - x = C/2 + k T and C/2 + B + k T (k >= 0), C the front phase, B = (1 + gamma) / J.
// The symmetric clearance (g_back = g) touches both walls from grazing on.
//
//   ClearanceMode m(material, 1e-3, 3e-3, 1);
//   m.period(5e-5);  m.u0(5e-5);  m.back_grazing_energy();
class ClearanceMode {
 public:
  // mode >= 1 (InputError "mode"); gap > 0 ("gap"); gap_back >= gap ("gap_back": the orbit
  // starts on the nearer wall, the front one).
  ClearanceMode(const bar::Material& material, double gap, double gap_back, int mode);

  int mode() const { return mode_; }
  double slope(double energy) const;  // s = sqrt(2E / (EA L))
  double grazing_energy() const;      // the front wall: EA ((2J - 1) g)^2 / (2L)
  double back_grazing_energy() const;
  // Closed-form period and frequency; NaN below grazing.
  double period(double energy) const;
  double frequency(double energy) const;
  // Contact phase durations per period on each wall [s] (0 for the back wall below its
  // grazing energy); NaN below grazing.
  double front_contact(double energy) const;
  double back_contact(double energy) const;
  // The J kinks of u0, increasing in x, and u0 itself (u0(0) = 0, u0(L) = g); InputError
  // "energy" below grazing.
  std::vector<double> kinks(double energy) const;
  bar::PiecewiseLinear u0(double energy) const;

 private:
  // The pulse lengths of the wave at the end (units of L/c): -h for a, +h for b, and the
  // flight delta between the walls (b with one wall: recede and approach); NaN below grazing.
  struct Blocks {
    double a, b, delta;
  };
  Blocks blocks(double energy) const;

  bar::Material material_;
  double gap_, gap_back_;
  int mode_;
};

// Where a piecewise-linear u0 first changes sign from + to - (or - to +) inside (0, L),
// linearly interpolated; NaN when it does not. The numerical counterpart of
// ContactFamily::node.
double node_of(const bar::PiecewiseLinear& u0);

// One member of the subharmonic continuum of an even mode J (README.md, sections 'Subharmonic
// continuum' for J = 2 and 'Subharmonic continuum of mode J'): period T = 2 T_J (mode J taken over
// two periods), started at rest at the centre of a contact phase, so u0(L) = g0 with a
// compressive strain there. u0 has slopes -s, +s, ..., -s from x = 0 with J kinks; for J = 2,
// with b = (1 + g0/(sL))/4 and c = b + shape (1 - 3b), at (1 - c - b) L and (1 - c + b) L.
// shape in [0, 1]: 0 and 1 are the grazing limits (one contact phase, one grazing instant; the
// same orbit shifted by T_J), 1/2 is mode J shifted by T_J / 2 (two equal phases). Energy
// EA L s^2 / 2 and period are those of mode J (x2), whatever the shape.
struct SubharmonicMember {
  bar::PiecewiseLinear u0;
  double period = 0;
  double first_contact = 0;   // duration of the phase centred at t = 0 [s]
  double second_contact = 0;  // duration of the phase centred at t = T / 2 [s]
  std::vector<double> kinks;  // the J kinks of u0, increasing [m] (the last is L at shape 0)
};
// InputError "mode" for an odd mode (no continuum over two periods), "energy" below the
// mode-J grazing energy, "shape" outside [0, 1].
SubharmonicMember subharmonic_member(const bar::Material& material, double gap, double energy,
                                     double shape, int mode = 2);

}  // namespace backbone::contact_bar
