// What an orbit attached to a traced branch adds to it: the extra content of the contacting-end
// displacement, computed from simulations (problems/contact_bar/orbits/README.md, section
// 'Dimension changes').
//
// Both orbits (the point on the branch and a nearby point of the attached family, e.g. the probe
// of a branch point, continuation/branch_points/branch_points.hpp) are re-simulated over their own
// period by the given solver (the exact oracle), the end displacement sampled at `samples` instants
// of one period each; their difference is the attached content. Its spectrum over the period gives
// the dominant harmonic (frequency_ratio: the content's frequency over the orbit's), and its sign
// changes give the oscillations per period (half the number of zero crossings). No formula of
// the ratio is used.
//
//   const AttachedContent c = attached_content(problem, on_branch, attached, oracle);
//   fmt::print("ratio {} ({} oscillations per period)\n", c.frequency_ratio,
//              c.oscillations_per_period);
#pragma once

#include "problems/bar/bar.hpp"
#include "problems/contact_bar/orbits/periodic_bar.hpp"

namespace backbone::contact_bar {

struct AttachedContent {
  double frequency_ratio = 0;          // dominant harmonic of the difference (NaN: failed)
  double oscillations_per_period = 0;  // zero crossings of the difference / 2
  double amplitude = 0;                // max |difference| [m]
  // The content's spatial wavenumber p (README.md, 'Attached families: the law'): the attached
  // u0 is a warp of the branch's, |u0_a'| = s X' with X' - 1 made of cos(j p pi x / L); p is the
  // gcd of the harmonics n >= 1 of X' - 1 above 1e-3 of the largest (exact integrals of the
  // piecewise-constant slope; a grid's aliases 2N +- p are multiples of p when p divides 2N).
  // resonance_order = p T c / (2L): q of the law, an integer on a branch point (NaN: failed).
  double content_wavenumber = 0;
  double resonance_order = 0;
};

AttachedContent attached_content(const ContactBarOrbitProblem& problem,
                                 const core::Vector& on_branch, const core::Vector& attached,
                                 const bar::BarSolver& solver, int samples = 4096);

}  // namespace backbone::contact_bar
