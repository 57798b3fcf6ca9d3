#include "continuation/cli/stability_report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace backbone::cli {

std::vector<continuation::OrbitBifurcation> report_stability(const core::Problem& problem,
                                                             const continuation::Branch& whole,
                                                             const core::FloquetOptions& floquet,
                                                             core::Corrector& corrector,
                                                             const std::filesystem::path& out) {
  if (whole.points.empty() || !whole.points.front().floquet) return {};
  int counts[3] = {0, 0, 0};  // undecided, unstable, stable
  double trivial = 0, determinant = 0, pairing = 0;
  const auto* orbit = dynamic_cast<const core::FloquetProblem*>(&problem);
  const bool conservative = orbit && orbit->floquet_structure().conservative;
  for (const continuation::BranchPoint& p : whole.points) {
    const core::Floquet& f = *p.floquet;
    counts[f.stable + 1] += 1;
    if (std::isfinite(f.trivial_distance)) trivial = std::max(trivial, f.trivial_distance);
    if (conservative && std::isfinite(f.determinant)) {
      determinant = std::max(determinant, std::abs(f.determinant - 1));
      pairing = std::max(pairing, f.pairing_error);
    }
  }
  fmt::print(
      "stability: {} stable, {} unstable, {} undecided points (|mu| > 1 + {:g} counts as "
      "unstable; multipliers.csv)\n",
      counts[2], counts[1], counts[0], floquet.tolerance);
  if (orbit && orbit->floquet_structure().trivial > 0)
    fmt::print("  trivial multipliers ({} at +1): worst |mu - 1| = {:.2e} (tolerance {:g})\n",
               orbit->floquet_structure().trivial, trivial, floquet.trivial_tolerance);
  if (conservative)
    fmt::print(
        "  conservative structure: worst |det M - 1| = {:.2e}, worst pairing "
        "min_j |mu_i mu_j - 1| = {:.2e}\n",
        determinant, pairing);
  std::fflush(stdout);
  if (orbit && !orbit->floquet_structure().bifurcations_detectable) {
    continuation::bifurcation_table({}, whole.points.front().observables)
        .write_csv(out / "bifurcations.csv");
    fmt::print(
        "bifurcations of the orbits: not detected ({} multipliers come from a projected "
        "representation; see its README, 'Stability')\n",
        problem.name());
    return {};
  }
  const auto found = continuation::detect_orbit_bifurcations(
      problem, whole, corrector, floquet, [](const continuation::OrbitBifurcation& b) {
        fmt::print("  bifurcation {}\n", continuation::bifurcation_line(b));
        std::fflush(stdout);
      });
  continuation::bifurcation_table(found, whole.points.front().observables)
      .write_csv(out / "bifurcations.csv");
  fmt::print("bifurcations of the orbits: {} (bifurcations.csv)\n", found.size());
  return found;
}

}  // namespace backbone::cli
