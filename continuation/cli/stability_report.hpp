// What `trace` says of the stability of a traced branch whose points carry multipliers
// (continuation/README.md, 'Stability and bifurcations of orbits'): a summary line (stable,
// unstable and undecided points, the worst distance of the trivial multipliers from +1 and, for
// a conservative problem, the structure checks |det M - 1| and the pairing error), then the
// bifurcations of the branch, one line each as it is located, written to bifurcations.csv.
//
//   const auto found = report_stability(problem, whole, options.floquet, *corrector, out);
#pragma once

#include <filesystem>
#include <vector>

#include "continuation/branch.hpp"
#include "continuation/orbit_bifurcations/bifurcations.hpp"
#include "core/problem.hpp"
#include "core/solvers/newton.hpp"
#include "core/stability/floquet.hpp"

namespace backbone::cli {

// Nothing (an empty list, no file) when the branch's points carry no multipliers.
std::vector<continuation::OrbitBifurcation> report_stability(const core::Problem& problem,
                                                             const continuation::Branch& whole,
                                                             const core::FloquetOptions& floquet,
                                                             core::Corrector& corrector,
                                                             const std::filesystem::path& out);

}  // namespace backbone::cli
