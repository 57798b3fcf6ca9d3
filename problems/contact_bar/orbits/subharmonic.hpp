// The contact structure of an orbit of the contact bar, counted from an exact simulation over
// its period (problems/exact_bar): how many contact phases, how many grazing instants, the
// smallest gap. It tells the members of the subharmonic continuum near omega2 / 2 (two phases)
// from its grazing limits (one phase plus one grazing instant); README.md, section
// 'Subharmonic continuum'.
//
//   const SubharmonicMember m = subharmonic_member(material, 1e-3, 1.25e-5, 0.3);
//   bar::BarSetup s = ...; s.u0 = m.u0;                    // starts on the wall
//   const ContactStructure c = contact_structure(s, m.period);
//   c.contact_phases;     // 2
//   c.grazing_instants;   // 0 (1 at the limits shape = 0 and 1)
//   c.min_gap;            // 0: it touches; never < 0 (no penetration)
//   write_subharmonic_outputs(problem, ContactFamily(material, g0, 2), branch, out, 1e-5);
#pragma once

#include <filesystem>
#include <limits>

#include "continuation/branch.hpp"
#include "problems/bar/bar.hpp"
#include "problems/contact_bar/orbits/family.hpp"
#include "problems/contact_bar/orbits/periodic_bar.hpp"

namespace backbone::contact_bar {

struct ContactStructure {
  bool ok = false;           // false when the exact simulation failed
  int contact_phases = 0;    // closed intervals of positive duration per period (a phase that
                             // straddles t = 0 = T counts once)
  int grazing_instants = 0;  // instants where the open end reaches the wall and leaves it
  // Instants in (0, T] where the end reaches a wall (front or back) as a front with a jump
  // arrives, to round-off (exact_bar::ExactBarSolution::closings_on_fronts): the kinks of the
  // period map.
  int closings_on_fronts = 0;
  double min_gap = 0;        // min over the period of g0 - u(L, t) [m]
  double first_contact = 0;  // duration of the phase that contains t = 0 (0 if none) [s]
  double contact_time = 0;   // total duration of the phases per period [s]
  // A clearance end: phases on the wall behind it, and min over the period of
  // gap_back + u(L, t) on the 4000-sample scan [m] (NaN without a back wall).
  int back_contact_phases = 0;
  double back_contact_time = 0;  // [s]
  double min_back_gap = std::numeric_limits<double>::quiet_NaN();
};

// The observed (right) end must be a contact or clearance end with a gap > 0 (InputError "right"
// otherwise); contact_phases and grazing_instants count the front wall.
// Grazing: a local maximum of u(L, t) off the contact phases within 1e-9 g0 of the wall, located
// by refining the local maxima of a 4000-sample scan (u(L, t) is piecewise linear).
ContactStructure contact_structure(const bar::BarSetup& setup, double period);

// After a subharmonic trace: DIR/subharmonic_check.csv, per point the energy, the period against
// 2 T2 of mode 2 at that energy, the shape, the contact structure, the exact-oracle return error
// and the verified dimension of the periodicity residual F alone (path rows off: dimension_F,
// nullity_F, gap_F). branch.csv gains the columns contact_phases, grazing_instants
// and min_gap; when rank_threshold is a number its dimension column is replaced by dimension_F
// (the traced system F plus its path row has one dimension less).
void write_subharmonic_outputs(const ContactBarOrbitProblem& problem, const ContactFamily& mode2,
                               const continuation::Branch& branch, const std::filesystem::path& out,
                               double rank_threshold);

}  // namespace backbone::contact_bar
