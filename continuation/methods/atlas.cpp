#include "continuation/methods/atlas.hpp"

#include <fmt/format.h>

#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>
#include <optional>

#include "continuation/scaled_problem.hpp"
#include "core/errors.hpp"
#include "core/solvers/bordered_system.hpp"

namespace backbone::continuation {

void AtlasOptions::validate() const {
  auto positive = [](double v, const char* key) {
    if (!(v > 0) || !std::isfinite(v))
      throw core::InputError(key, fmt::format("must be finite and > 0 (got {})", v));
  };
  positive(radius, "atlas.radius");
  positive(radius_min, "atlas.radius_min");
  positive(max_distance_ratio, "atlas.max_distance_ratio");
  positive(max_angle_degrees, "atlas.max_angle_degrees");
  if (!(radius_min <= radius))
    throw core::InputError("atlas.radius_min", "must be <= atlas.radius");
  if (!(null_threshold >= 0 && null_threshold < 1))
    throw core::InputError("atlas.null_threshold", "must be in [0, 1)");
  if (!(boundary_fraction >= 0 && boundary_fraction < 1))
    throw core::InputError("atlas.boundary_fraction", "must be in [0, 1)");
  if (bisection_steps < 0) throw core::InputError("atlas.bisection_steps", "must be >= 0");
  if (polygon_vertices < 4) throw core::InputError("atlas.polygon_vertices", "must be >= 4");
  if (max_charts < 1) throw core::InputError("atlas.max_charts", "must be >= 1");
}

core::Matrix tangent_plane(const core::Matrix& J) {
  const Eigen::Index n = J.cols();
  // Pad with zero rows so that the full V of a short J (m < n) holds its null space.
  core::Matrix padded = core::Matrix::Zero(std::max(J.rows(), n), n);
  padded.topRows(J.rows()) = J;
  Eigen::JacobiSVD<core::Matrix> svd(padded, Eigen::ComputeFullV);
  return svd.matrixV().rightCols(2);
}

core::Matrix tangent_plane(const core::Matrix& J, const core::Matrix& near, double threshold) {
  const Eigen::Index n = J.cols();
  core::Matrix padded = core::Matrix::Zero(std::max(J.rows(), n), n);
  padded.topRows(J.rows()) = J;
  Eigen::JacobiSVD<core::Matrix> svd(padded, Eigen::ComputeFullV);
  const core::Vector& sigma = svd.singularValues();  // decreasing
  Eigen::Index k = 2;
  while (k < n && sigma[n - k - 1] <= threshold * sigma[0]) ++k;
  const core::Matrix null_space = svd.matrixV().rightCols(k);
  if (k == 2) return null_space;
  // The plane of the near-null space closest to `near`: its projection, orthonormalized.
  const core::Matrix projected = null_space * (null_space.transpose() * near);
  Eigen::JacobiSVD<core::Matrix> basis(projected, Eigen::ComputeThinU);
  return basis.matrixU();
}

double plane_angle(const core::Matrix& a, const core::Matrix& b) {
  const Eigen::JacobiSVD<core::Matrix> svd(a.transpose() * b);
  return std::acos(std::clamp(svd.singularValues().minCoeff(), -1.0, 1.0));
}

namespace {

using Point2 = Eigen::Vector2d;

// Sutherland-Hodgman with one half-plane n . s <= c.
std::vector<Point2> clip(const std::vector<Point2>& polygon, const Point2& n, double c) {
  std::vector<Point2> out;
  const std::size_t k = polygon.size();
  for (std::size_t i = 0; i < k; ++i) {
    const Point2& a = polygon[i];
    const Point2& b = polygon[(i + 1) % k];
    const double da = n.dot(a) - c, db = n.dot(b) - c;
    if (da <= 0) out.push_back(a);
    if ((da < 0 && db > 0) || (da > 0 && db < 0)) out.push_back(a + (b - a) * (da / (da - db)));
  }
  return out;
}

class AtlasBuilder {
 public:
  AtlasBuilder(const core::Problem& problem, core::Corrector& corrector,
               const AtlasOptions& options, const std::function<bool(const core::Vector&)>& inside,
               const std::function<bool(const core::Vector&)>& accept)
      : problem_(problem),
        corrector_(corrector),
        options_(options),
        inside_(inside),
        accept_(accept) {
    if (options.scale_unknowns)
      scaled_ = std::make_unique<ScaledProblem>(problem);
    else
      scaled_ =
          std::make_unique<ScaledProblem>(problem, core::Vector::Ones(problem.num_unknowns()));
  }

  Atlas run(const core::Vector& guess,
            const std::function<void(const Atlas& atlas, int chart)>& on_chart) {
    const auto start = std::chrono::steady_clock::now();
    auto elapsed = [&] {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    // First chart: the guess corrected in the normal space of its own tangent plane.
    core::Vector z0 = scaled_->to_scaled(guess);
    core::Matrix J;
    if (scaled_->jacobian(z0, J) != core::EvalStatus::ok) {
      atlas_.message = "the Jacobian at the guess cannot be evaluated";
      atlas_.seconds = elapsed();
      return atlas_;
    }
    std::optional<Chart> first = correct(z0, tangent_plane(J), Point2::Zero(), options_.radius);
    if (!first) {
      atlas_.message = "the guess does not correct onto the manifold";
      atlas_.seconds = elapsed();
      return atlas_;
    }
    add_chart(std::move(*first));
    if (on_chart) on_chart(atlas_, 0);

    for (std::size_t i = 0; i < atlas_.charts.size();) {
      const std::optional<Point2> vertex = open_vertex(atlas_.charts[i]);
      if (!vertex) {
        ++i;  // charts are expanded in order of creation: a front that grows outwards
        continue;
      }
      if (static_cast<int>(atlas_.charts.size()) >= options_.max_charts) {
        find_adjacent();
        atlas_.message = fmt::format("max_charts ({}) reached", options_.max_charts);
        atlas_.seconds = elapsed();
        return atlas_;
      }
      if (expand(static_cast<int>(i), *vertex) && on_chart)
        on_chart(atlas_, static_cast<int>(atlas_.charts.size()) - 1);
    }
    find_adjacent();
    atlas_.complete = true;
    atlas_.message = fmt::format("complete: {} charts, no open vertex", atlas_.charts.size());
    atlas_.seconds = elapsed();
    return atlas_;
  }

 private:
  // The vertex of the chart's polygon farthest outside its disk and not closed.
  std::optional<Point2> open_vertex(const Chart& c) const {
    std::optional<Point2> best;
    double best_norm = c.radius * (1 + 1e-9);
    for (const Point2& v : c.polygon) {
      if (v.norm() <= best_norm) continue;
      const Point2 dir = v.normalized();
      const bool closed = std::any_of(c.closed.begin(), c.closed.end(),
                                      [&](const Point2& d) { return (d - dir).norm() < 1e-9; });
      if (closed) continue;
      best = v;
      best_norm = v.norm();
    }
    return best;
  }

  // Corrects F plus the two tangent rows of a chart (centre z_c, basis T) at coordinates s; the
  // new chart gets radius `radius`. Empty when Newton fails or the tangent cannot be computed.
  std::optional<Chart> correct(const core::Vector& z_c, const core::Matrix& T, const Point2& s,
                               double radius) {
    ++atlas_.corrections;
    core::BorderedSystem system(*scaled_,
                                {core::BorderRow::linear(T.col(0), z_c, s[0], "chart 1"),
                                 core::BorderRow::linear(T.col(1), z_c, s[1], "chart 2")});
    core::Vector z = z_c + T * s;
    const core::NewtonSummary summary = corrector_.solve(system, z);
    if (!summary.converged()) return std::nullopt;
    core::Matrix J;
    if (scaled_->jacobian(z, J) != core::EvalStatus::ok) return std::nullopt;
    Chart c;
    c.z = z;
    c.x = scaled_->to_unknowns(z);
    c.tangent = tangent_plane(J, T, options_.null_threshold);
    c.radius = radius;
    c.newton_iterations = summary.iterations;
    core::Vector r;
    c.residual = problem_.residual(c.x, r) == core::EvalStatus::ok ? r.lpNorm<Eigen::Infinity>()
                                                                   : std::nan("");
    c.observables = problem_.observables(c.x);
    return c;
  }

  bool inside(const Chart& c) const { return !inside_ || inside_(c.x); }

  enum class Outcome { accepted, not_converged, too_far, refused };

  // Corrects from chart i along direction dir at distance h: accepted when close to the
  // prediction, not turned too much and agreed by accept_. The geometric test comes first: a
  // correction that lands far away is a step too long (the radius shrinks), whatever accept_
  // would say of the point it found.
  Outcome attempt(int i, const Point2& dir, double h, double radius, std::optional<Chart>& out) {
    const Chart& from = atlas_.charts[static_cast<std::size_t>(i)];
    out = correct(from.z, from.tangent, h * dir, radius);
    if (!out) {
      ++atlas_.failed_corrections;
      ++atlas_.not_converged;
      return Outcome::not_converged;
    }
    const double max_angle = options_.max_angle_degrees * std::numbers::pi / 180;
    if ((out->z - (from.z + from.tangent * (h * dir))).norm() > options_.max_distance_ratio * h ||
        plane_angle(out->tangent, from.tangent) > max_angle) {
      ++atlas_.failed_corrections;
      ++atlas_.too_far;
      out.reset();
      return Outcome::too_far;
    }
    if (accept_ && !accept_(out->x)) {
      ++atlas_.failed_corrections;
      ++atlas_.rejected;
      out.reset();
      return Outcome::refused;
    }
    return Outcome::accepted;
  }

  // Whether the prediction of chart i at distance h along dir lies inside the bounds.
  bool prediction_inside(int i, const Point2& dir, double h) const {
    const Chart& from = atlas_.charts[static_cast<std::size_t>(i)];
    return !inside_ || inside_(scaled_->to_unknowns(from.z + from.tangent * (h * dir)));
  }

  // The longest step in (0, h] whose prediction stays inside the bounds, to 1e-3 h: the bound
  // on the tangent line, found without a correction (a prediction beyond the domain, e.g. past
  // a grazing limit where no solution exists, would only cost a failed Newton solve).
  double reach(int i, const Point2& dir, double h) const {
    if (prediction_inside(i, dir, h)) return h;
    double in = 0, out = h;
    while (out - in > 1e-3 * h) {
      const double mid = (in + out) / 2;
      (prediction_inside(i, dir, mid) ? in : out) = mid;
    }
    return in;
  }

  void close(int i, const Point2& dir) {
    atlas_.charts[static_cast<std::size_t>(i)].closed.push_back(dir);
  }

  // One new chart from chart i towards its open vertex. The step is first cut to the bound of
  // the domain on the tangent line (reach); a step cut below boundary_fraction * R closes the
  // direction. A correction too far from its prediction (or turned too much) halves the chart's
  // radius (Henderson's rule; its polygon and its neighbours' are rebuilt). One that does not
  // converge, is refused or leaves the bounds marks the end of the manifold in that direction:
  // the step is bisected to the last good point, a boundary chart when it is at least
  // boundary_fraction * R away, else the direction closes. Returns true when a chart was added.
  bool expand(int i, const Point2& vertex) {
    const Point2 dir = vertex.normalized();
    const double radius_i = atlas_.charts[static_cast<std::size_t>(i)].radius;
    const double radius = std::min(options_.radius, 2 * radius_i);
    const double h = reach(i, dir, radius_i);
    if (h < options_.boundary_fraction * radius_i) {
      close(i, dir);
      return false;
    }
    std::optional<Chart> c;
    const Outcome outcome = attempt(i, dir, h, radius, c);
    if (outcome == Outcome::too_far) {
      if (radius_i / 2 < options_.radius_min) {
        ++atlas_.closed_by_failure;
        close(i, dir);
      } else {
        shrink(i, radius_i / 2);
      }
      return false;
    }
    if (outcome == Outcome::accepted) {
      if (inside(*c)) {
        c->on_boundary = h < radius_i;
        add_chart(std::move(*c));
        return true;
      }
      ++atlas_.outside;
    }
    return bisect(i, dir, h, radius_i, radius);
  }

  // The last good point between chart i and the failed step h along dir, by bisection: a
  // boundary chart when at least boundary_fraction * R (R: chart i's radius) away, else the
  // direction closes.
  bool bisect(int i, const Point2& dir, double h, double radius_i, double radius) {
    double h_in = 0, h_out = h;
    std::optional<Chart> last_inside;
    for (int k = 0; k < options_.bisection_steps; ++k) {
      const double mid = (h_in + h_out) / 2;
      std::optional<Chart> m;
      const bool accepted = attempt(i, dir, mid, radius, m) == Outcome::accepted;
      if (accepted && inside(*m)) {
        h_in = mid;
        last_inside = std::move(m);
      } else {
        if (accepted) ++atlas_.outside;
        h_out = mid;
      }
    }
    if (!last_inside || h_in < options_.boundary_fraction * radius_i) {
      close(i, dir);
      return false;
    }
    last_inside->on_boundary = true;
    add_chart(std::move(*last_inside));
    return true;
  }

  // Chart i with a smaller radius: its polygon and those of its neighbours start again from
  // their regular polygons, clipped by the neighbours that still overlap.
  void shrink(int i, double radius) {
    Chart& c = atlas_.charts[static_cast<std::size_t>(i)];
    c.radius = radius;
    rebuild(i);
    for (int j : c.neighbours) rebuild(j);
  }

  void rebuild(int i) {
    Chart& c = atlas_.charts[static_cast<std::size_t>(i)];
    c.polygon = regular_polygon(c.radius);
    for (int j : c.neighbours) {
      const Chart& other = atlas_.charts[static_cast<std::size_t>(j)];
      if ((other.z - c.z).norm() < other.radius + c.radius) cut(c, other);
    }
  }

  std::vector<Point2> regular_polygon(double radius) const {
    const int k = options_.polygon_vertices;
    const double corner = radius / std::cos(std::numbers::pi / k);
    std::vector<Point2> p;
    for (int j = 0; j < k; ++j) {
      const double angle = 2 * std::numbers::pi * j / k;
      p.emplace_back(corner * std::cos(angle), corner * std::sin(angle));
    }
    return p;
  }

  // Polygon of a new chart, clipped with every chart whose disk overlaps (and they with it).
  void add_chart(Chart c) {
    c.polygon = regular_polygon(c.radius);
    const int index = static_cast<int>(atlas_.charts.size());
    for (int j = 0; j < index; ++j) {
      Chart& other = atlas_.charts[static_cast<std::size_t>(j)];
      if ((other.z - c.z).norm() >= other.radius + c.radius) continue;
      cut(c, other);
      cut(other, c);
      c.neighbours.push_back(j);
      other.neighbours.push_back(index);
    }
    atlas_.charts.push_back(std::move(c));
  }

  // A neighbour is adjacent when two vertices of the polygon lie on its half-plane's line.
  void find_adjacent() {
    for (Chart& a : atlas_.charts) {
      a.adjacent.clear();
      for (int j : a.neighbours) {
        const Chart& b = atlas_.charts[static_cast<std::size_t>(j)];
        const Point2 s = a.tangent.transpose() * (b.z - a.z);
        const double c = (a.radius * a.radius - b.radius * b.radius + s.squaredNorm()) / 2;
        const double tolerance = 1e-9 * std::max(s.norm() * a.radius, 1e-300);
        const auto on_line =
            std::count_if(a.polygon.begin(), a.polygon.end(),
                          [&](const Point2& v) { return std::abs(s.dot(v) - c) <= tolerance; });
        if (on_line >= 2) a.adjacent.push_back(j);
      }
    }
  }

  // Henderson's half-plane of neighbour b in a's tangent coordinates.
  static void cut(Chart& a, const Chart& b) {
    const Point2 s = a.tangent.transpose() * (b.z - a.z);
    const double c = (a.radius * a.radius - b.radius * b.radius + s.squaredNorm()) / 2;
    a.polygon = clip(a.polygon, s, c);
  }

  const core::Problem& problem_;
  core::Corrector& corrector_;
  const AtlasOptions& options_;
  const std::function<bool(const core::Vector&)>& inside_;
  const std::function<bool(const core::Vector&)>& accept_;
  std::unique_ptr<ScaledProblem> scaled_;
  Atlas atlas_;
};

}  // namespace

Atlas cover_manifold(const core::Problem& problem, const core::Vector& guess,
                     core::Corrector& corrector, const AtlasOptions& options,
                     const std::function<bool(const core::Vector& x)>& inside,
                     const std::function<void(const Atlas& atlas, int chart)>& on_chart,
                     const std::function<bool(const core::Vector& x)>& accept) {
  options.validate();
  if (guess.size() != problem.num_unknowns())
    throw core::InputError("guess", fmt::format("must have {} entries (got {})",
                                                problem.num_unknowns(), guess.size()));
  if (problem.num_unknowns() < 3)
    throw core::InputError("problem", "a 2D manifold needs at least 3 unknowns");
  AtlasBuilder builder(problem, corrector, options, inside, accept);
  return builder.run(guess, on_chart);
}

}  // namespace backbone::continuation
