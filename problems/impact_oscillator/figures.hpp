// The impact oscillator's figures and summary, drawn from the outputs of `backbone trace` in
// OUT/impact_oscillator/ (the main job's steps: the period-1 branch from sigma = 0 up to grazing
// and down to -0.2, with the period-2 branch switched onto at its period doubling, for r = 0.8
// into dissipative_up/ and dissipative_down/, for r = 1 into elastic_up/ and elastic_down/):
//   impact_diagram      bifurcation_diagram.png: impact velocity against the wall position,
//                       stable solid, unstable dashed, the period-2 branch beside period 1,
//                       every located bifurcation marked; one panel per restitution
//   impact_multipliers  multipliers.png: the multipliers in the complex plane with the unit
//                       circle, at sigma = 0, at the period doubling, at sigma = -0.2 and at
//                       the period-2 branch's first point
//   impact_summary      summary.csv: per restitution the acceptance numbers against the closed
//                       form (README.md, 'What the main job measures')
//
//   for (const cli::ProblemJob& job : impact_oscillator::figure_jobs()) job.run("results");
#pragma once

#include <vector>

#include "continuation/cli/plugin.hpp"

namespace backbone::impact_oscillator {

std::vector<cli::ProblemJob> figure_jobs();

}  // namespace backbone::impact_oscillator
