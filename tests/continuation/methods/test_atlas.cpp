// The 2D atlas (continuation/methods/atlas.hpp) on the unit 2-sphere, whose points are known
// exactly: a band between two latitudes is covered without holes (random exact points within one
// chart radius of a chart centre), every centre lies on the sphere, inside the band, and neighbours
// are mutual; the whole sphere closes on itself; configuration errors name their field.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "continuation/methods/atlas.hpp"
#include "core/errors.hpp"
#include "core/solvers/newton.hpp"
#include "problems/algebraic/algebraic.hpp"

namespace backbone::continuation {
namespace {

core::NewtonOptions tight() {
  core::NewtonOptions o;
  o.residual_tolerance = 1e-13;
  return o;
}

// Largest distance from a random point of the exact sphere (z in [z_min, z_max]) to its nearest
// chart centre.
double largest_gap(const Atlas& atlas, double z_min, double z_max, int samples) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> height(z_min, z_max), angle(0, 2 * M_PI);
  double worst = 0;
  for (int k = 0; k < samples; ++k) {
    // Uniform on the sphere: z uniform (Archimedes), azimuth uniform.
    const double z = height(rng), phi = angle(rng), rho = std::sqrt(1 - z * z);
    const core::Vector p =
        (core::Vector(3) << rho * std::cos(phi), rho * std::sin(phi), z).finished();
    double nearest = 1e300;
    for (const Chart& c : atlas.charts) nearest = std::min(nearest, (c.x - p).norm());
    worst = std::max(worst, nearest);
  }
  return worst;
}

TEST(Atlas, CoversABandOfTheSphereWithoutHoles) {
  const algebraic::Sphere sphere;
  AtlasOptions options;
  options.radius = 0.2;
  options.scale_unknowns = false;
  auto corrector = core::make_corrector("eigen", tight());
  const double z_min = -0.5, z_max = 0.8;
  auto inside = [&](const core::Vector& x) { return x[2] >= z_min && x[2] <= z_max; };
  const core::Vector guess = (core::Vector(3) << 1.1, 0.1, 0.05).finished();
  const Atlas atlas = cover_manifold(sphere, guess, *corrector, options, inside);
  ASSERT_TRUE(atlas.complete) << atlas.message;
  EXPECT_EQ(atlas.closed_by_failure, 0);  // a sphere of radius 5 R turns 11 degrees per chart
  std::printf("band: %zu charts, %d corrections, %d failed\n", atlas.charts.size(),
              atlas.corrections, atlas.failed_corrections);

  int boundary = 0;
  for (std::size_t i = 0; i < atlas.charts.size(); ++i) {
    const Chart& c = atlas.charts[i];
    // Newton stops at |F| <= 1e-13 with |grad F| = 2: the centre is within 1e-13 of the sphere.
    EXPECT_NEAR(c.x.norm(), 1.0, 1e-10) << "chart " << i;
    EXPECT_TRUE(inside(c.x)) << "chart " << i;
    // The tangent basis is orthonormal and orthogonal to the normal x.
    EXPECT_NEAR((c.tangent.transpose() * c.tangent - Eigen::Matrix2d::Identity()).norm(), 0, 1e-12);
    EXPECT_NEAR((c.tangent.transpose() * c.x).norm(), 0, 1e-9);
    for (int j : c.neighbours) {
      const auto& back = atlas.charts[static_cast<std::size_t>(j)].neighbours;
      EXPECT_NE(std::find(back.begin(), back.end(), static_cast<int>(i)), back.end());
    }
    // Adjacent charts (polygons sharing an edge) are neighbours; an interior cell of a closed
    // polygon tiling has at least three.
    for (int j : c.adjacent)
      EXPECT_NE(std::find(c.neighbours.begin(), c.neighbours.end(), j), c.neighbours.end());
    if (!c.on_boundary) {
      EXPECT_GE(c.adjacent.size(), 3u) << "chart " << i;
    }
    boundary += c.on_boundary;
  }
  // No holes: every point of the band is within R of a centre (a chart's disk covers it). The
  // polygon construction guarantees this for interior points; near the bounds a direction is
  // closed only when the bound is within boundary_fraction * R, still inside the disk.
  EXPECT_LE(largest_gap(atlas, z_min, z_max, 4000), options.radius);
  // Count: at least area / (pi R^2) disks to cover the band (area 2 pi (z_max - z_min)). Each
  // new centre is predicted inside its parent's polygon, i.e. at least R from every other centre
  // in the tangent plane, so disks of radius R / 2 around the centres hardly overlap: at most
  // the area of the band widened by R / 2 on each side over pi R^2 / 4 (boundary charts, which
  // may sit nearer, are counted apart).
  const double area = 2 * M_PI * (z_max - z_min), r2 = options.radius * options.radius;
  const double widened = 2 * M_PI * (z_max - z_min + options.radius);
  const auto charts = static_cast<double>(atlas.charts.size());
  EXPECT_GE(charts, area / (M_PI * r2));
  EXPECT_LE(charts - boundary, widened / (M_PI * r2 / 4));
  EXPECT_GT(boundary, 0);  // both bounds were reached
}

TEST(Atlas, ClosesOnTheWholeSphere) {
  const algebraic::Sphere sphere;
  AtlasOptions options;
  options.radius = 0.3;
  options.scale_unknowns = false;
  auto corrector = core::make_corrector("eigen", tight());
  const core::Vector guess = (core::Vector(3) << 0.0, 0.0, 1.2).finished();
  const Atlas atlas = cover_manifold(sphere, guess, *corrector, options);
  ASSERT_TRUE(atlas.complete) << atlas.message;
  EXPECT_LE(largest_gap(atlas, -1, 1, 4000), options.radius);
  for (const Chart& c : atlas.charts) EXPECT_NEAR(c.x.norm(), 1.0, 1e-10);
  // Area 4 pi over disks of pi R^2 at least, over disks of pi R^2 / 4 at most (as above).
  const double charts = static_cast<double>(atlas.charts.size()),
               r2 = options.radius * options.radius;
  EXPECT_GE(charts, 4 / r2);
  EXPECT_LE(charts, 16 / r2);
}

// The plane x3 = 0 whose residual exists only inside the square |x1|, |x2| <= 1, as a family
// that ends where no solution exists (the contact bar's subharmonic manifold past its grazing
// limits): outside, the evaluation fails.
class SquareOfAPlane : public core::Problem {
 public:
  int num_unknowns() const override { return 3; }
  int num_equations() const override { return 1; }

 protected:
  core::EvalStatus compute_residual(const core::Vector& x, core::Vector& r) const override {
    if (!(std::abs(x[0]) <= 1 && std::abs(x[1]) <= 1)) return core::EvalStatus::failed;
    r = x.tail(1);
    return core::EvalStatus::ok;
  }
  core::EvalStatus compute_jacobian(const core::Vector& x, core::Matrix& J) const override {
    if (!(std::abs(x[0]) <= 1 && std::abs(x[1]) <= 1)) return core::EvalStatus::failed;
    J = (core::Matrix(1, 3) << 0, 0, 1).finished();
    return core::EvalStatus::ok;
  }
};

// Predictions beyond the bounds are cut back to the bound on the tangent line before any
// correction: on a plane the tangent line is the manifold, so every correction converges on its
// prediction, none is evaluated outside the square and none is bisected; boundary charts sit on
// the bound to the 1e-3 step resolution of that cut, which never overshoots.
TEST(Atlas, CutsPredictionsAtTheBoundsBeforeCorrecting) {
  const SquareOfAPlane plane;
  AtlasOptions options;
  options.radius = 0.25;
  options.scale_unknowns = false;
  auto corrector = core::make_corrector("eigen", tight());
  auto inside = [](const core::Vector& x) { return std::abs(x[0]) <= 1 && std::abs(x[1]) <= 1; };
  const core::Vector guess = (core::Vector(3) << 0.1, -0.2, 0.3).finished();
  const Atlas atlas = cover_manifold(plane, guess, *corrector, options, inside);
  ASSERT_TRUE(atlas.complete) << atlas.message;
  EXPECT_EQ(atlas.failed_corrections, 0);
  EXPECT_EQ(atlas.not_converged, 0);
  EXPECT_EQ(atlas.outside, 0);
  EXPECT_EQ(atlas.corrections, static_cast<int>(atlas.charts.size()));  // one each, no bisection
  int boundary = 0;
  for (const Chart& c : atlas.charts) {
    EXPECT_TRUE(inside(c.x));
    EXPECT_NEAR(c.x[2], 0, 1e-13);  // F linear: one Newton step, to the tolerance 1e-13
    if (!c.on_boundary) continue;
    ++boundary;
    const double to_bound = 1 - c.x.head(2).lpNorm<Eigen::Infinity>();
    EXPECT_GE(to_bound, 0);
    EXPECT_LE(to_bound, 1e-3 * options.radius);
  }
  EXPECT_GT(boundary, 4);  // every side of the square is reached
}

// Where J has three null directions, the chart's plane is the one of them nearest its
// parent's: here span(e1, e2, e3) and a parent plane spanned by (e1 + e4) / sqrt 2 and e2,
// whose projection spans e1, e2 exactly.
TEST(Atlas, TangentPlaneOfADegenerateJacobianFollowsItsParent) {
  const core::Matrix J = (core::Matrix(1, 4) << 0, 0, 0, 2).finished();
  core::Matrix parent = core::Matrix::Zero(4, 2);
  parent(0, 0) = parent(3, 0) = std::sqrt(0.5);
  parent(1, 1) = 1;
  core::Matrix expected = core::Matrix::Zero(4, 2);
  expected(0, 0) = expected(1, 1) = 1;
  const core::Matrix t = tangent_plane(J, parent, 1e-3);
  EXPECT_NEAR((t.transpose() * t - Eigen::Matrix2d::Identity()).norm(), 0, 1e-14);
  EXPECT_LT(plane_angle(t, expected), 1e-7);  // acos near 1 resolves angles to ~sqrt(eps)
  // Two null directions: the null space itself, whatever the parent.
  const core::Matrix J2 = (core::Matrix(2, 4) << 0, 0, 1, 0, 0, 0, 0, 3).finished();
  EXPECT_LT(plane_angle(tangent_plane(J2, parent, 1e-3), expected), 1e-7);
}

TEST(Atlas, BadOptionsNameTheirField) {
  const algebraic::Sphere sphere;
  auto corrector = core::make_corrector("eigen", tight());
  AtlasOptions options;
  options.radius = -1;
  try {
    cover_manifold(sphere, core::Vector::Ones(3), *corrector, options);
    FAIL() << "no InputError";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("atlas.radius"), std::string::npos) << e.what();
  }
  EXPECT_THROW(cover_manifold(sphere, core::Vector::Ones(2), *corrector, AtlasOptions{}),
               core::InputError);
}

}  // namespace
}  // namespace backbone::continuation
