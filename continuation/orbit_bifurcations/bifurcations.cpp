#include "continuation/orbit_bifurcations/bifurcations.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>

#include "core/solvers/bordered_system.hpp"

namespace backbone::continuation {

namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();
// The bracket is small enough when its length in the unknowns is below this share of the
// orbit's size: the multipliers carry errors of about 1e-10 (CVODE at rtol 1e-12..1e-13), so the
// test functions' signs are noise closer to the root than that.
constexpr double bracket_tolerance = 1e-10;
constexpr int max_location_steps = 80;
constexpr double grazing_fraction = 0.5;

enum class Kind { fold, period_doubling, torus };

const char* name_of(Kind k) {
  switch (k) {
    case Kind::fold:
      return "fold";
    case Kind::period_doubling:
      return "period_doubling";
    case Kind::torus:
      return "torus";
  }
  return "?";
}

double test_of(Kind k, const core::Floquet& f) {
  switch (k) {
    case Kind::fold:
      return f.fold_test;
    case Kind::period_doubling:
      return f.period_doubling_test;
    case Kind::torus:
      return f.torus_test;
  }
  return nan;
}

int count_of(Kind k, const core::OutsideCounts& c) {
  return k == Kind::fold ? c.real_positive
                         : (k == Kind::period_doubling ? c.real_negative : c.complex);
}

// The orbit on the hyperplane through a + s (b - a) normal to b - a, with its multipliers.
struct Sample {
  bool ok = false;
  double s = 0;
  core::Vector x;
  core::Floquet floquet;
};

class Locator {
 public:
  Locator(const core::Problem& problem, core::Corrector& corrector,
          const core::FloquetOptions& options, const core::Vector& a, const core::Vector& b)
      : problem_(problem), corrector_(corrector), options_(options), a_(a), d_(b - a) {}

  Sample at(double s, const core::Vector& guess) {
    ++steps;
    Sample out;
    out.s = s;
    out.x = guess;
    const core::Vector through = a_ + s * d_;
    core::BorderedSystem system(problem_, {core::BorderRow::hyperplane(d_, through)});
    if (!corrector_.solve(system, out.x).converged()) return out;
    const auto f = core::floquet_at(problem_, out.x, options_);
    if (!f || f->stable < 0) return out;
    out.floquet = *f;
    out.ok = true;
    return out;
  }
  int steps = 0;

 private:
  const core::Problem& problem_;
  core::Corrector& corrector_;
  const core::FloquetOptions& options_;
  core::Vector a_, d_;
};

OrbitBifurcation locate(const core::Problem& problem, core::Corrector& corrector,
                        const core::FloquetOptions& options, const BranchPoint& pa,
                        const BranchPoint& pb, Kind kind) {
  Locator locator(problem, corrector, options, pa.x, pb.x);
  const double chord = (pb.x - pa.x).norm(), scale = std::max(1.0, pa.x.norm());
  Sample lo{true, 0.0, pa.x, *pa.floquet}, hi{true, 1.0, pb.x, *pb.floquet};
  const int count_lo = count_of(kind, lo.floquet.outside);
  double f_lo = test_of(kind, lo.floquet), f_hi = test_of(kind, hi.floquet);
  const bool signed_test = f_lo * f_hi < 0;
  enum class End { none, lower, upper } replaced = End::none;  // Illinois: which end moved last
  Sample best = hi;
  bool located = false;
  while (locator.steps < max_location_steps) {
    if ((hi.s - lo.s) * chord <= bracket_tolerance * scale) {
      located = true;
      break;
    }
    double s = 0.5 * (lo.s + hi.s);
    if (signed_test) {
      s = (lo.s * f_hi - hi.s * f_lo) / (f_hi - f_lo);
      if (!(s > lo.s && s < hi.s)) s = 0.5 * (lo.s + hi.s);
    }
    const core::Vector guess = lo.x + (s - lo.s) / (hi.s - lo.s) * (hi.x - lo.x);
    Sample m = locator.at(s, guess);
    if (!m.ok) break;
    best = m;
    const double f_m = test_of(kind, m.floquet);
    if (signed_test && f_m == 0) {
      located = true;
      break;
    }
    const bool with_lo =
        signed_test ? (f_m * f_lo > 0) : (count_of(kind, m.floquet.outside) == count_lo);
    // An end kept twice in a row has its test value halved (Illinois), so that regula falsi
    // does not creep up from one side.
    if (with_lo) {
      lo = m;
      f_lo = f_m;
      if (replaced == End::lower) f_hi *= 0.5;
      replaced = End::lower;
    } else {
      hi = m;
      f_hi = f_m;
      if (replaced == End::upper) f_lo *= 0.5;
      replaced = End::upper;
    }
  }
  OrbitBifurcation b;
  b.type = name_of(kind);
  b.after_point = pa.index;
  b.located = located;
  b.x = best.x;
  b.observables = problem.observables(best.x);
  b.floquet = best.floquet;
  b.test_value = test_of(kind, best.floquet);
  b.location_steps = locator.steps;
  return b;
}

std::optional<OrbitBifurcation> locate_grazing(const core::Problem& problem,
                                               core::Corrector& corrector,
                                               const core::FloquetProblem& orbit,
                                               const Branch& branch, const std::string& name) {
  const auto& points = branch.points;
  // A branch that ended on its point budget did not stop at the grazing.
  if (points.size() < 2 || branch.reason == StopReason::max_points) return std::nullopt;
  double largest = 0, smallest = std::numeric_limits<double>::infinity();
  for (const BranchPoint& p : points) {
    const double g = p.observable(name);
    if (std::isfinite(g)) {
      largest = std::max(largest, g);
      smallest = std::min(smallest, g);
    }
  }
  const BranchPoint& last = points.back();
  const double g_end = last.observable(name);
  const double g_before = points[points.size() - 2].observable(name);
  if (!(g_end > 0 && g_end <= smallest && g_end < grazing_fraction * largest && g_end < g_before))
    return std::nullopt;
  const auto grazing = orbit.grazing_problem(name, last.x);
  if (!grazing) return std::nullopt;
  OrbitBifurcation b;
  b.type = "grazing";
  b.after_point = last.index;
  b.x = last.x;
  b.location_steps = 1;
  // A correction that stalls within 1e-8 has reached the noise of the shots near grazing.
  const core::NewtonSummary summary = corrector.solve(*grazing, b.x);
  b.located =
      summary.converged() || (summary.status == core::NewtonStatus::stalled &&
                              summary.final_residual() >= 0 && summary.final_residual() <= 1e-8);
  b.observables = grazing->observables(b.x);
  b.floquet = last.floquet ? *last.floquet : core::undecided_floquet(0);
  b.test_value = 0;
  return b;
}

}  // namespace

std::vector<OrbitBifurcation> detect_orbit_bifurcations(
    const core::Problem& problem, const Branch& branch, core::Corrector& corrector,
    const core::FloquetOptions& floquet,
    const std::function<void(const OrbitBifurcation&)>& on_found) {
  std::vector<OrbitBifurcation> found;
  const auto report = [&](OrbitBifurcation b) {
    found.push_back(std::move(b));
    if (on_found) on_found(found.back());
  };
  const auto& points = branch.points;
  for (std::size_t i = 0; i + 1 < points.size(); ++i) {
    const BranchPoint &pa = points[i], &pb = points[i + 1];
    if (!pa.floquet || !pb.floquet || pa.floquet->stable < 0 || pb.floquet->stable < 0) continue;
    for (Kind kind : {Kind::fold, Kind::period_doubling, Kind::torus})
      if (count_of(kind, pa.floquet->outside) != count_of(kind, pb.floquet->outside))
        report(locate(problem, corrector, floquet, pa, pb, kind));
  }
  // Every grazing observable falling at the end is tried; those whose grazing orbit is corrected
  // are reported (a branch that ends at one grazing may see another observable fall too).
  if (const auto* orbit = dynamic_cast<const core::FloquetProblem*>(&problem)) {
    std::vector<std::string> unlocated;
    bool any = false;
    for (const std::string& name : orbit->grazing_observables())
      if (auto b = locate_grazing(problem, corrector, *orbit, branch, name)) {
        if (b->located) {
          report(std::move(*b));
          any = true;
        } else {
          unlocated.push_back(name);
        }
      }
    if (!any)
      for (const std::string& name : unlocated)
        fmt::print(stderr,
                   "backbone: {} falls towards 0 at the end of the branch, but no grazing "
                   "orbit was corrected from its last point\n",
                   name);
  }
  return found;
}

core::Table bifurcation_table(const std::vector<OrbitBifurcation>& found,
                              const core::Observables& template_point) {
  std::vector<std::string> names;
  const auto add = [&](const std::string& n) {
    if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
  };
  for (const auto& [key, value] : template_point) add(key);
  std::size_t multipliers = 0;
  for (const OrbitBifurcation& b : found) {
    for (const auto& [key, value] : b.observables) add(key);
    multipliers = std::max(multipliers, b.floquet.multipliers.size());
  }
  std::vector<std::string> columns{"type"};
  columns.insert(columns.end(), names.begin(), names.end());
  columns.insert(columns.end(), {"stable", "max_multiplier_modulus"});
  for (std::size_t k = 0; k < multipliers; ++k) {
    columns.push_back(fmt::format("multiplier_{}_re", k));
    columns.push_back(fmt::format("multiplier_{}_im", k));
  }
  columns.insert(columns.end(), {"located", "after_point", "test_value", "location_steps"});
  core::Table table(columns);
  for (const OrbitBifurcation& b : found) {
    std::vector<double> row;
    for (const std::string& n : names) row.push_back(core::observable_value(b.observables, n));
    row.push_back(b.floquet.stable);
    row.push_back(b.floquet.max_modulus);
    for (std::size_t k = 0; k < multipliers; ++k) {
      const bool has = k < b.floquet.multipliers.size();
      row.push_back(has ? b.floquet.multipliers[k].real() : nan);
      row.push_back(has ? b.floquet.multipliers[k].imag() : nan);
    }
    row.insert(row.end(), {b.located ? 1.0 : 0.0, static_cast<double>(b.after_point), b.test_value,
                           static_cast<double>(b.location_steps)});
    table.add_row(b.type, row);
  }
  return table;
}

std::string bifurcation_line(const OrbitBifurcation& b) {
  std::string line =
      fmt::format("{}{} after point {}:", b.type, b.located ? "" : " (not located)", b.after_point);
  for (const auto& [key, value] : b.observables) line += fmt::format(" {} {:.12g}", key, value);
  // The largest few (they come by decreasing modulus): a discretised continuum (the contact
  // bar's) has hundreds, which bifurcations.csv's point and multipliers.csv hold.
  constexpr std::size_t shown = 8;
  const auto& all = b.floquet.multipliers;
  line += "  multipliers";
  for (std::size_t i = 0; i < std::min(all.size(), shown); ++i) {
    const auto& mu = all[i];
    line += mu.imag() == 0 ? fmt::format(" {:.9g}", mu.real())
                           : fmt::format(" {:.9g}{:+.9g}i", mu.real(), mu.imag());
  }
  if (all.size() > shown) line += fmt::format(" (and {} smaller)", all.size() - shown);
  return line;
}

}  // namespace backbone::continuation
