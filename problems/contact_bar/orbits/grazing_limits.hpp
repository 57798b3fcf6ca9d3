// The two grazing limits of the subharmonic continuum at one energy, located by constrained
// optimisation on the solution manifold with NLopt (README.md, section 'Subharmonic continuum').
//
// At energy E the members form a curve (shape in [0, 1]); at its ends one contact phase shrinks
// to a grazing instant. Each limit is the minimiser of that phase's duration, computed by an
// exact simulation of the member over its period, subject to the periodicity residual F = 0
// (the regular half-period residual of ContactBarOrbitProblem, every test row an equality) and
// the energy row (E(x) - E) / E = 0, solved by NLopt's SLSQP with forward-difference gradients
// in the scaled unknowns x ./ typical_scale():
//   - shape 1 (the phase around T/2 vanishes): the two-knot chart of the continuum, started
//     from the closed-form member at shape 1 - start_distance;
//   - shape 0 (the phase around t = 0 vanishes): its second kink sits at x = L, outside the
//     two-knot chart, so the one-knot chart (start_on_wall, one free knot), started from the
//     member at shape start_distance sampled on it (its second kink cut off: not a solution).
// A limit that fails (no tolerance reached, or an exact return above 1e-6) is retried twice
// from start_distance / 4, / 16. Shape 1 gets a second pass from the first one's result with a
// 100x smaller difference step in a box of 1e-3 (the kink is located to the gradients'
// resolution). Each pass ends with a least-squares Newton polish onto all rows.
// The two are one orbit shifted by T2 = T / 2: shift_distance simulates the shape-1 limit by
// T2 with the exact oracle and compares with the shape-0 limit's u0 (relative to max |u0|).
//
//   GrazingLimitOptions o;  o.elements = 20;
//   const GrazingLimits g = grazing_limits(setup, TdbemSolver(ContactMethod::event), 1.25e-5, o);
//   g.limits[0].structure.contact_phases;     // 1 (plus g.limits[0].structure.grazing_instants 1)
//   g.limits[0].x;                            // the member in its chart's unknowns
//   g.shift_distance;                         // ~1e-12: the same orbit shifted by T2
//   grazing_limit_table(g).write_csv(out / "limits.csv");
#pragma once

#include <string>
#include <vector>

#include "core/io/table.hpp"
#include "core/types.hpp"
#include "problems/bar/bar.hpp"
#include "problems/contact_bar/orbits/subharmonic.hpp"

namespace backbone::contact_bar {

struct GrazingLimitOptions {
  int elements = 20;                   // u0 grid of both charts (shooting_elements)
  int steps_per_period = 40;           // dt = T / steps_per_period (even)
  double start_distance = 0.02;        // start from the members at shapes 1 - d and d, in (0, 0.5)
  double tolerance = 1e-12;            // NLopt: relative tolerance on x and on the objective
  double constraint_tolerance = 1e-8;  // of each projected equality row (units of g0)
  int max_evaluations = 400;           // objective evaluations per limit (each an FD gradient)
  int mode = 2;                        // J of the continuum (even): charts of J and J - 1 knots
  void validate() const;               // InputError naming the field
};

struct GrazingLimit {
  std::string name;           // "shape_1" (phase around T/2 vanishes) or "shape_0" (around 0)
  bool ok = false;            // NLopt reached a tolerance and the member is an orbit
  std::string message;        // NLopt's result, or why the limit is not accepted
  int free_knots = 0;         // chart: 2 (shape 1) or 1 (shape 0)
  core::Vector x;             // the member in its chart's unknowns [u0 | knots | T]
  bar::PiecewiseLinear u0;    // its initial displacement (v0 = 0)
  double period = 0;          // [s]
  double energy = 0;          // [J]
  double phase_duration = 0;  // the minimised duration of the vanishing phase [s]
  double residual = 0;        // max |F| of the periodicity rows [units of g0]
  double return_error = 0;    // exact oracle over T, relative (ReturnError::worst)
  ContactStructure structure;
  int evaluations = 0;  // objective evaluations (each with its FD gradient)
  double seconds = 0;
};

struct GrazingLimits {
  std::vector<GrazingLimit> limits;  // shape_1, shape_0
  double half_period = 0;            // T2 = T / 2 of the shape-1 limit [s]
  double shift_distance = 0;         // |u(shape_1 limit, T2) - u0(shape_0 limit)| / max |u0|
};

// setup: the bar (right = contact, gap > 0); solver: the residual's solver (the TD-BEM).
// InputError for bad options or an energy below the mode-2 grazing energy.
GrazingLimits grazing_limits(const bar::BarSetup& setup, const bar::BarSolver& solver,
                             double energy, const GrazingLimitOptions& options);

// limits.csv: one row per limit (limit 1 = shape 1, 0 = shape 0), its contact structure,
// period, energy, minimised phase duration, residual, return error, evaluations and seconds,
// and shift_distance (the same on both rows).
core::Table grazing_limit_table(const GrazingLimits& limits);

}  // namespace backbone::contact_bar
