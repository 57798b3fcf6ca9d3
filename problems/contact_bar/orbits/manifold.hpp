// The 2D manifold of subharmonic orbits near omega2 / 2 (energy x shape), covered by an atlas
// (continuation/methods/atlas.hpp; README.md, section 'Subharmonic continuum').
//
// `backbone trace SCENE --branch subharmonic_manifold --energy_min E1 --energy_max E2 --out DIR`
// builds the continuum's problem (start on the wall, two free knots), traces its first member
// only (branch.csv, orbits.csv: one point, the atlas's seed at the geometric mean energy and
// shape 0.3), then covers the manifold of the periodicity residual F alone, bounded by
// [energy_min, energy_max] (the scene's energy bounds, given) and the shape window [shape_margin, 1
// - shape_margin] (the grazing limits are shape 0 and 1). Writes DIR/manifold.csv (point, chart,
// energy, period, shape, neighbours, plus the checks) and DIR/manifold.png (energy on a log axis vs
// shape).
//
//   po::options_description keys = manifold_keys();       // chart_radius, shape_margin, ...
//   double e = manifold_seed_energy(scene);               // sqrt(energy_min energy_max)
//   add_manifold_outputs(scene, trace_setup, problem);    // after the continuum's setup
//   AtlasRun run = cover_subharmonic_manifold(problem, seed, options, e1, e2, margin);
#pragma once

#include <Eigen/Core>
#include <array>
#include <boost/program_options.hpp>
#include <filesystem>
#include <vector>

#include "continuation/cli/plugin.hpp"
#include "continuation/methods/atlas.hpp"
#include "core/io/scene.hpp"
#include "core/io/table.hpp"
#include "problems/contact_bar/orbits/periodic_bar.hpp"

namespace backbone::contact_bar {

boost::program_options::options_description manifold_keys();

// sqrt(energy_min * energy_max); InputError "energy_min" / "energy_max" unless
// 0 < energy_min < energy_max.
double manifold_seed_energy(const core::Scene& scene);

struct ManifoldRun {
  int mode = 2;  // J of the continuum (period 2 T_J)
  continuation::Atlas atlas;
  double worst_return = 0;                 // exact oracle over T, relative (ReturnError::worst)
  double worst_period = 0;                 // |T / (2 T_J(E)) - 1| against the closed form
  double energy_low = 0, energy_high = 0;  // range of the chart energies
  // Over 2000 random closed-form members inside the bounds: the largest distance to the nearest
  // chart centre in units of that chart's radius (<= 1: no holes).
  double largest_gap = 0;
  std::vector<double> return_errors, period_errors;  // per chart (period: signed)
  // Per chart, its cell in (shape, energy): the Voronoi cell of its centre in the plane of shape
  // and normalised log energy, clipped to the bounds (plane_cells); what manifold.png draws.
  std::vector<std::vector<std::array<double, 2>>> cells;
};

// Covers the manifold of `problem` (a subharmonic ContactBarOrbitProblem; its path rows are
// switched off on a copy) from `seed`, and checks each chart against the closed form and the
// exact oracle. A chart whose exact re-simulation misses u0 by more than return_tolerance
// (relative; 0: no check) is refused like a failed correction.
ManifoldRun cover_subharmonic_manifold(const ContactBarOrbitProblem& problem,
                                       const core::Vector& seed,
                                       const continuation::AtlasOptions& options, double energy_min,
                                       double energy_max, double shape_margin,
                                       const core::NewtonOptions& newton, double return_tolerance);

// A point of the figure's plane: (shape, normalised log energy), both in [0, 1] inside the bounds.
using PlanePoint = Eigen::Vector2d;

// Non-overlapping cells for a figure of an atlas: cell i is polygon i (any simple polygon, e.g.
// the box itself: the Voronoi diagram of the centres) clipped to the box [0, 1]^2 and to the
// Voronoi cell of centre i among all centres (the half-planes nearer centre i than centre j), so no
// two cells overlap whatever the polygons do; a centre inside its polygon is inside its cell.
std::vector<std::vector<PlanePoint>> plane_cells(
    const std::vector<PlanePoint>& centres, const std::vector<std::vector<PlanePoint>>& polygons);

// manifold.csv: point, chart, energy, period, shape, neighbours (chart indices joined by ';'),
// adjacent (the neighbours whose polygons share an edge: what the figure draws), radius,
// on_boundary, residual, return_error, period_error.
core::Table manifold_table(const ManifoldRun& run);

// Turns the continuum's trace setup into the manifold's: one traced point (the seed), then the
// atlas and its outputs in write_extra_outputs.
void add_manifold_outputs(const core::Scene& scene, cli::TraceSetup& setup,
                          const ContactBarOrbitProblem& problem);

}  // namespace backbone::contact_bar
