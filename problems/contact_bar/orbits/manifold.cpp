#include "problems/contact_bar/orbits/manifold.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <string>

#include "continuation/scaled_problem.hpp"
#include "core/errors.hpp"
#include "core/io/plot.hpp"
#include "problems/contact_bar/orbits/family.hpp"
#include "problems/exact_bar/exact_bar_solver.hpp"

namespace backbone::contact_bar {

namespace po = boost::program_options;

po::options_description manifold_keys() {
  po::options_description keys("subharmonic_manifold (an atlas of the 2D manifold)");
  keys.add_options()  //
      ("chart_radius", po::value<double>()->default_value(0.3),
       "subharmonic_manifold: chart radius in the scaled unknowns (continuation/README.md, "
       "section 'Covering a 2D manifold')")  //
      ("shape_margin", po::value<double>()->default_value(1e-3),
       "subharmonic_manifold: the atlas stops at shape_margin and 1 - shape_margin (the grazing "
       "limits are shape 0 and 1, nonsmooth ends of the manifold)")  //
      ("max_charts", po::value<long>()->default_value(3000), "subharmonic_manifold: chart cap");
  return keys;
}

double manifold_seed_energy(const core::Scene& scene) {
  const double e1 = scene.positive("energy_min"), e2 = scene.positive("energy_max");
  if (!(e1 < e2))
    throw core::InputError("energy_max",
                           fmt::format("must be > energy_min (got {} <= {})", e2, e1));
  return std::sqrt(e1 * e2);
}

namespace {

double observable(const core::Observables& o, const std::string& name) {
  for (const auto& [key, value] : o)
    if (key == name) return value;
  return std::nan("");
}

}  // namespace

namespace {

// Sutherland-Hodgman with one half-plane n . q <= c (a convex clip of any simple polygon).
std::vector<PlanePoint> clip(const std::vector<PlanePoint>& polygon, const PlanePoint& n,
                             double c) {
  std::vector<PlanePoint> out;
  const std::size_t k = polygon.size();
  for (std::size_t i = 0; i < k; ++i) {
    const PlanePoint& a = polygon[i];
    const PlanePoint& b = polygon[(i + 1) % k];
    const double da = n.dot(a) - c, db = n.dot(b) - c;
    if (da <= 0) out.push_back(a);
    if ((da < 0 && db > 0) || (da > 0 && db < 0)) out.push_back(a + (b - a) * (da / (da - db)));
  }
  return out;
}

}  // namespace

std::vector<std::vector<PlanePoint>> plane_cells(
    const std::vector<PlanePoint>& centres, const std::vector<std::vector<PlanePoint>>& polygons) {
  std::vector<std::vector<PlanePoint>> cells;
  for (std::size_t i = 0; i < centres.size(); ++i) {
    std::vector<PlanePoint> cell = polygons[i];
    for (const auto& [n, c] : {std::pair{PlanePoint(-1, 0), 0.0}, std::pair{PlanePoint(1, 0), 1.0},
                               std::pair{PlanePoint(0, -1), 0.0}, std::pair{PlanePoint(0, 1), 1.0}})
      cell = clip(cell, n, c);
    for (std::size_t j = 0; j < centres.size() && !cell.empty(); ++j) {
      if (j == i) continue;
      const PlanePoint d = centres[j] - centres[i];
      cell = clip(cell, d, (centres[j].squaredNorm() - centres[i].squaredNorm()) / 2);
    }
    cells.push_back(std::move(cell));
  }
  return cells;
}

namespace {

// The figure's cells in (shape, energy): the Voronoi cells of the chart centres in the plane of
// shape and normalised log energy, clipped to the bounds (plane_cells with the box as every
// polygon). The charts' own polygons live in their tangent planes of the scaled unknowns; mapped
// to this plane they neither tile it nor stay disjoint, so the figure tiles its own plane.
std::vector<std::vector<std::array<double, 2>>> figure_cells(const continuation::Atlas& atlas,
                                                             double energy_min, double energy_max) {
  const double log_min = std::log(energy_min), log_range = std::log(energy_max) - log_min;
  std::vector<PlanePoint> centres;
  for (const continuation::Chart& c : atlas.charts)
    centres.emplace_back(observable(c.observables, "shape"),
                         (std::log(observable(c.observables, "energy")) - log_min) / log_range);
  const std::vector<PlanePoint> box{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const std::vector<std::vector<PlanePoint>> boxes(centres.size(), box);
  std::vector<std::vector<std::array<double, 2>>> cells;
  for (const std::vector<PlanePoint>& cell : plane_cells(centres, boxes)) {
    cells.emplace_back();
    for (const PlanePoint& q : cell)
      cells.back().push_back({q[0], std::exp(log_min + q[1] * log_range)});
  }
  return cells;
}

}  // namespace

ManifoldRun cover_subharmonic_manifold(const ContactBarOrbitProblem& problem,
                                       const core::Vector& seed,
                                       const continuation::AtlasOptions& options, double energy_min,
                                       double energy_max, double shape_margin,
                                       const core::NewtonOptions& newton, double return_tolerance) {
  // F alone: the periodicity residual whose solutions form the 2D manifold.
  const ContactBarOrbitProblem f = problem.without_path_rows();
  auto inside = [&](const core::Vector& x) {
    const core::Observables o = f.observables(x);
    const double e = observable(o, "energy"), shape = observable(o, "shape");
    return e >= energy_min && e <= energy_max && shape >= shape_margin && shape <= 1 - shape_margin;
  };
  auto corrector = core::make_corrector("eigen", newton);  // F plus 2 rows: least squares
  const exact_bar::ExactBarSolver oracle;
  // The exact-oracle return on 1000 intervals, as the continuum's reject_point (plugin.cpp):
  // near shape 1/2 (mode 2 itself) the projected residual has spurious roots, which it refuses.
  auto accept = [&](const core::Vector& x) {
    return !(return_tolerance > 0) || return_error(f, x, oracle, 1000).worst() <= return_tolerance;
  };
  ManifoldRun run;
  run.mode = problem.options().subharmonic_mode;
  run.atlas = continuation::cover_manifold(f, seed, *corrector, options, inside, {}, accept);
  const bar::BarSetup& setup = problem.setup_template();
  const ContactFamily mode2(setup.material, setup.right.gap, problem.options().subharmonic_mode);
  run.energy_low = 1e300;
  run.energy_high = 0;
  for (const continuation::Chart& c : run.atlas.charts) {
    const double e = observable(c.observables, "energy");
    run.energy_low = std::min(run.energy_low, e);
    run.energy_high = std::max(run.energy_high, e);
    run.period_errors.push_back(observable(c.observables, "period") / (2 * mode2.period(e)) - 1);
    run.return_errors.push_back(return_error(f, c.x, oracle, 1000).worst());
    run.worst_period = std::max(run.worst_period, std::abs(run.period_errors.back()));
    run.worst_return = std::max(run.worst_return, run.return_errors.back());
  }
  // No holes: closed-form members (subharmonic_guess: exact in the two-knot chart) at random
  // (log E, shape) inside the bounds, each against the chart disk nearest in units of its radius.
  const continuation::ScaledProblem scaled(f);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> log_energy(std::log(energy_min), std::log(energy_max)),
      shape(shape_margin, 1 - shape_margin);
  for (int k = 0; k < 2000 && !run.atlas.charts.empty(); ++k) {
    const core::Vector z =
        scaled.to_scaled(f.subharmonic_guess(std::exp(log_energy(rng)), shape(rng)));
    double nearest = 1e300;
    for (const continuation::Chart& c : run.atlas.charts)
      nearest = std::min(nearest, (z - c.z).norm() / c.radius);
    run.largest_gap = std::max(run.largest_gap, nearest);
  }
  run.cells = figure_cells(run.atlas, energy_min, energy_max);
  return run;
}

core::Table manifold_table(const ManifoldRun& run) {
  core::Table t({"point", "chart", "energy", "period", "shape", "neighbours", "adjacent", "radius",
                 "on_boundary", "residual", "return_error", "period_error"});
  for (std::size_t i = 0; i < run.atlas.charts.size(); ++i) {
    const continuation::Chart& c = run.atlas.charts[i];
    auto joined = [](const std::vector<int>& indices) {
      std::string text;
      for (int j : indices) {
        if (!text.empty()) text += ';';
        text += std::to_string(j);
      }
      return text;
    };
    const std::string neighbours = joined(c.neighbours), adjacent = joined(c.adjacent);
    const double e = observable(c.observables, "energy");
    const double period = observable(c.observables, "period");
    t.add_cells({static_cast<double>(i), static_cast<double>(i), e, period,
                 observable(c.observables, "shape"), neighbours, adjacent, c.radius,
                 c.on_boundary ? 1.0 : 0.0, c.residual, run.return_errors[i],
                 run.period_errors[i]});
  }
  return t;
}

namespace {

// Energy (log axis) vs shape: each chart's cell (its polygon, cut so that neighbours do not
// overlap), chart centres, boundary charts highlighted.
void write_manifold_figure(const std::filesystem::path& out, const ManifoldRun& run,
                           double energy_min, double energy_max) {
  std::string edges = "$edges << EOD\n", charts = "$charts << EOD\n", rim = "$rim << EOD\n";
  const auto& cs = run.atlas.charts;
  auto shape = [](const continuation::Chart& c) { return observable(c.observables, "shape"); };
  auto energy = [](const continuation::Chart& c) { return observable(c.observables, "energy"); };
  for (std::size_t i = 0; i < cs.size(); ++i) {
    (cs[i].on_boundary ? rim : charts) +=
        fmt::format("{:.9g} {:.9g}\n", shape(cs[i]), energy(cs[i]));
    const auto& cell = run.cells[i];
    if (cell.empty()) continue;
    for (const auto& q : cell) edges += fmt::format("{:.9g} {:.9g}\n", q[0], q[1]);
    edges += fmt::format("{:.9g} {:.9g}\n\n", cell.front()[0], cell.front()[1]);
  }
  const std::string script =
      edges + "EOD\n" + charts + "EOD\n" + rim + "EOD\n" +
      fmt::format(
          "set datafile separator whitespace\nset key noautotitle\nset logscale y\nset format y "
          "'10^{{%L}}'\nset xlabel 'shape (first contact phase / "
          "total contact time)'\nset ylabel 'energy [J]'\nset xrange [-0.02:1.02]\n"
          "set yrange [{:g}:{:g}]\nset key below horizontal maxcols 3 samplen 2\nset bmargin 6\n"
          "set title 'subharmonic orbits near {{/Symbol w}}_{}/2: atlas of {} charts{} (period 2 "
          "T_{} at every point)'\n"
          "set arrow from 0,graph 0 to 0,graph 1 nohead dt 2 lc rgb 'gray40'\n"
          "set arrow from 1,graph 0 to 1,graph 1 nohead dt 2 lc rgb 'gray40'\n"
          "plot $edges using 1:2 with lines lc rgb '#8fa8cc' lw 1 title 'chart cells', "
          "$charts using 1:2 with points pt 7 ps 0.6 lc rgb '#1f4e9a' title 'chart centres', "
          "$rim using 1:2 with points pt 7 ps 0.7 lc rgb '#c0392b' title 'on the boundary (bounds, "
          "refused corrections)'\n",
          energy_min / 1.15, energy_max * 1.15, run.mode, cs.size(),
          run.atlas.complete ? "" : " (incomplete)", run.mode);
  const core::PlotResult r = core::render_png(out / "manifold.png", script, {1100, 800});
  if (!r.ok) fmt::print(stderr, "manifold.png skipped: {}\n", r.message);
}

}  // namespace

void add_manifold_outputs(const core::Scene& scene, cli::TraceSetup& setup,
                          const ContactBarOrbitProblem& problem) {
  const double e1 = scene.positive("energy_min"), e2 = scene.positive("energy_max");
  manifold_seed_energy(scene);  // validates the range
  continuation::AtlasOptions options;
  options.radius = scene.positive("chart_radius");
  options.radius_min = options.radius / 64;
  options.max_charts = static_cast<int>(scene.integer("max_charts", 1));
  options.validate();
  const double margin = scene.positive("shape_margin");
  if (!(margin < 0.5)) throw core::InputError("shape_margin", "must be < 0.5");
  core::NewtonOptions newton;
  newton.residual_tolerance = scene.positive("newton_tolerance");
  auto continuum_options = setup.branch_options;
  setup.branch_options = [continuum_options](continuation::ContinuationOptions& o,
                                             core::NewtonOptions& n) {
    if (continuum_options) continuum_options(o, n);
    o.max_points = 1;  // the seed only: the manifold is the atlas's
    o.bounds.clear();
  };
  const ContactBarOrbitProblem* p = &problem;
  const double return_tolerance = scene.non_negative("return_tolerance");
  setup.write_extra_outputs = [p, options, e1, e2, margin, newton, return_tolerance](
                                  const std::filesystem::path& out, const continuation::Branch& b) {
    const ManifoldRun run = cover_subharmonic_manifold(*p, b.points.front().x, options, e1, e2,
                                                       margin, newton, return_tolerance);
    manifold_table(run).write_csv(out / "manifold.csv");
    write_manifold_figure(out, run, e1, e2);
    const continuation::Atlas& a = run.atlas;
    fmt::print(
        "manifold: {} charts ({} on the boundary), energy {:.3e} .. {:.3e} J, {} corrections ({} "
        "failed: {} not converged, {} too far or turned, {} rejected by the exact return; {} "
        "outside the bounds; {} directions closed by failure), {:.1f} s; worst exact return "
        "{:.1e}, worst period vs 2 T_{} {:.1e}; largest gap {:.2f} chart radii (2000 closed-form "
        "members); {}\n",
        a.charts.size(),
        std::count_if(a.charts.begin(), a.charts.end(),
                      [](const continuation::Chart& c) { return c.on_boundary; }),
        run.energy_low, run.energy_high, a.corrections, a.failed_corrections, a.not_converged,
        a.too_far, a.rejected, a.outside, a.closed_by_failure, a.seconds, run.worst_return,
        run.mode, run.worst_period, run.largest_gap, run.atlas.message);
  };
}

}  // namespace backbone::contact_bar
