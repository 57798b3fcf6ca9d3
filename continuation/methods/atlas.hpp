// Covering a 2D solution manifold of F(x) = 0 with an atlas of charts (Henderson's
// multiple-parameter continuation, COCO's atlas_kd; continuation/README.md, section 'Covering a
// 2D manifold').
//
// A chart is a point z_c on the manifold (scaled unknowns, scaled_problem.hpp), an orthonormal
// basis T (n x 2) of its tangent plane (the two smallest right singular vectors of the Jacobian)
// and a radius R: its disk is {z_c + T s, |s| <= R}. Each chart keeps a polygon in its tangent
// coordinates, first the regular polygon around its disk, clipped by the half-plane of every
// neighbour (Henderson's: 2 s . c <= R^2 - R_j^2 + |c|^2, c = T^T (z_j - z_c)). A vertex outside
// the disk marks uncovered boundary: the next chart is predicted at z_c + T R v / |v| and
// corrected with F plus the two tangent rows T^T (z - z_c) = R v / |v| (core::BorderedSystem).
// A prediction outside the problem's bounds (inside(x) false) is first pulled back along the
// tangent line to the bound, where no correction is needed to find it. The correction is
// accepted when Newton converges within max_distance_ratio * step of the prediction, its
// tangent plane turns by at most max_angle_degrees and accept(x) agrees; too far or turned too
// much halves R. A corrected point that fails, is refused or lies outside the bounds is
// bisected back; the last good point becomes a boundary chart when it lies at least
// boundary_fraction * R away, otherwise the direction is closed. The atlas is complete when no
// chart has an open vertex.
//
//   algebraic::Sphere sphere;
//   AtlasOptions options;  options.radius = 0.2;  options.scale_unknowns = false;
//   auto corrector = core::make_corrector("eigen", core::NewtonOptions{});
//   auto inside = [](const core::Vector& x) { return x[2] >= -0.5 && x[2] <= 0.8; };
//   Atlas atlas = cover_manifold(sphere, guess, *corrector, options, inside);
//   for (const Chart& c : atlas.charts) use(c.x, c.neighbours);
//   atlas.complete;  atlas.charts.size();  atlas.seconds;
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "core/problem.hpp"
#include "core/solvers/newton.hpp"
#include "core/types.hpp"

namespace backbone::continuation {

struct AtlasOptions {
  double radius = 0.1;       // chart radius R (scaled units when scale_unknowns)
  double radius_min = 1e-3;  // a direction whose step would fall below this is closed (failed)
  double max_distance_ratio = 0.5;  // |z - z_predicted| <= ratio * step
  double max_angle_degrees = 30;    // largest principal angle between neighbouring tangent planes
  // Singular values of J at most this fraction of the largest count as null: where more than
  // two do (a degenerate residual), the chart's tangent plane is the plane of that null space
  // nearest its parent's, not an arbitrary pair of its directions.
  double null_threshold = 1e-3;
  // A bisected boundary point nearer than this fraction of R to its chart adds no chart: the
  // chart's own disk reaches the bound there.
  double boundary_fraction = 0.25;
  int bisection_steps = 6;
  int polygon_vertices = 8;
  int max_charts = 2000;
  bool scale_unknowns = true;  // work in z = x ./ typical scale (scaled_problem.hpp)
  void validate() const;       // InputError "atlas.<field>"
};

struct Chart {
  core::Vector x;        // centre, the problem's unknowns
  core::Vector z;        // centre, the scaled unknowns the atlas works in
  core::Matrix tangent;  // n x 2, orthonormal (scaled)
  double radius = 0;
  // At a bound (on the tangent line or by bisection), or where corrections stop converging or
  // are refused.
  bool on_boundary = false;
  std::vector<int> neighbours;  // charts whose disks overlap this one's (mutual)
  // Neighbours whose half-plane bounds an edge of this chart's final polygon: the cells that
  // touch (a Delaunay-like subset of neighbours, what a figure draws).
  std::vector<int> adjacent;
  core::Observables observables;
  double residual = 0;  // ||F||_inf of the problem at x
  int newton_iterations = 0;
  // Tangent-plane coordinates of the polygon (Henderson's), and the directions closed at a
  // bound or by failure.
  std::vector<Eigen::Vector2d> polygon;
  std::vector<Eigen::Vector2d> closed;
};

struct Atlas {
  std::vector<Chart> charts;
  bool complete = false;  // no open vertex left (else max_charts or a failed first point)
  std::string message;
  int corrections = 0;  // bordered solves, bisections included
  // not_converged + too_far + rejected; a converged correction outside the bounds is no failure
  // (it is counted in `outside`).
  int failed_corrections = 0;
  int not_converged = 0;      // Newton did not converge (or the Jacobian failed at its end)
  int too_far = 0;            // converged beyond max_distance_ratio * step or turned too much
  int rejected = 0;           // converged, near, and refused by accept(x)
  int outside = 0;            // converged, accepted, outside the bounds (bisected back)
  int closed_by_failure = 0;  // directions given up at radius_min
  double seconds = 0;
};

// inside(x): the problem's bounds (x in its own unknowns); an empty function means no bounds.
// on_chart: called after each accepted chart (index). accept(x): an independent check of a
// converged correction near its prediction (e.g. the contact bar's exact-oracle return); false
// counts as a failed correction (Atlas::rejected). Throws InputError for bad options, a guess
// of the wrong size or a problem whose solution set cannot be 2D (n - rank(J) < 2 at the guess is
// not checked: the chart basis is the two smallest singular directions).
Atlas cover_manifold(const core::Problem& problem, const core::Vector& guess,
                     core::Corrector& corrector, const AtlasOptions& options,
                     const std::function<bool(const core::Vector& x)>& inside = {},
                     const std::function<void(const Atlas& atlas, int chart)>& on_chart = {},
                     const std::function<bool(const core::Vector& x)>& accept = {});

// Orthonormal basis (n x 2) of the two right singular vectors of J with the smallest singular
// values: the tangent plane of a 2D solution manifold.
core::Matrix tangent_plane(const core::Matrix& J);

// The same where J may have more than two negligible singular values (<= threshold times the
// largest): the plane of their right singular vectors nearest the plane `near` (n x 2,
// orthonormal), i.e. near's projection onto that null space, orthonormalized.
core::Matrix tangent_plane(const core::Matrix& J, const core::Matrix& near, double threshold);

// Largest principal angle between two planes with orthonormal bases [rad].
double plane_angle(const core::Matrix& a, const core::Matrix& b);

}  // namespace backbone::continuation
