// The figure cells of the manifold's atlas (problems/contact_bar/orbits/manifold.hpp,
// plane_cells): overlapping polygons are cut at the bisector of their centres, and the box alone
// gives the Voronoi diagram, which tiles the box.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "problems/contact_bar/orbits/manifold.hpp"

namespace backbone::contact_bar {
namespace {

double area(const std::vector<PlanePoint>& p) {  // shoelace
  double twice = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const PlanePoint& a = p[i];
    const PlanePoint& b = p[(i + 1) % p.size()];
    twice += a[0] * b[1] - b[0] * a[1];
  }
  return std::abs(twice) / 2;
}

std::vector<PlanePoint> square(const PlanePoint& c, double half) {
  return {c + PlanePoint(-half, -half), c + PlanePoint(half, -half), c + PlanePoint(half, half),
          c + PlanePoint(-half, half)};
}

// Two squares of half-width 0.25 around (0.3, 0.5) and (0.6, 0.5) overlap on [0.35, 0.55]; the
// bisector u = 0.45 splits them into [0.05, 0.45] and [0.45, 0.85] x [0.25, 0.75], areas 0.2 each
// (exact up to round-off, 1e-14).
TEST(ManifoldCells, OverlappingPolygonsAreCutAtTheBisector) {
  const std::vector<PlanePoint> centres{{0.3, 0.5}, {0.6, 0.5}};
  const auto cells = plane_cells(centres, {square(centres[0], 0.25), square(centres[1], 0.25)});
  ASSERT_EQ(cells.size(), 2u);
  EXPECT_NEAR(area(cells[0]), 0.2, 1e-14);
  EXPECT_NEAR(area(cells[1]), 0.2, 1e-14);
  for (const PlanePoint& q : cells[0]) EXPECT_LE(q[0], 0.45 + 1e-15);
  for (const PlanePoint& q : cells[1]) EXPECT_GE(q[0], 0.45 - 1e-15);
  // A polygon reaching beyond the box is cut to it: [0.65, 1] x [0.25, 0.75].
  const auto clipped = plane_cells({{0.9, 0.5}}, {square({0.9, 0.5}, 0.25)});
  EXPECT_NEAR(area(clipped[0]), 0.175, 1e-14);
}

// The box as every polygon: the Voronoi cells of random centres tile the box, so their areas add
// up to 1 (round-off, 1e-12), and each centre lies in its own cell (convex: on the inner side of
// every edge).
TEST(ManifoldCells, VoronoiCellsTileTheBox) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<PlanePoint> centres;
  for (int i = 0; i < 60; ++i) centres.emplace_back(u(rng), u(rng));
  const std::vector<PlanePoint> box{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const auto cells = plane_cells(centres, std::vector<std::vector<PlanePoint>>(60, box));
  double total = 0;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    total += area(cells[i]);
    const auto& c = cells[i];
    for (std::size_t k = 0; k < c.size(); ++k) {
      const PlanePoint e = c[(k + 1) % c.size()] - c[k], r = centres[i] - c[k];
      EXPECT_GE(e[0] * r[1] - e[1] * r[0], -1e-15) << "cell " << i;  // counter-clockwise box
    }
  }
  EXPECT_NEAR(total, 1.0, 1e-12);
}

}  // namespace
}  // namespace backbone::contact_bar
