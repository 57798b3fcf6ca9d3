// Problems that `backbone trace` can follow register themselves here.
//
// `backbone trace SCENE --branch NAME` reads the scene's `problem` key
// (core::scene_problem_name), finds the TraceProblem of that name, parses the scene against the
// problem's keys plus the continuation keys (ds, ds_max, max_points, method, newton,
// formulation, energy_max, ...; a problem may declare any of them itself to change its
// default), and calls setup(scene, branch). setup builds the problem and the starting guess;
// trace corrects the guess, runs the continuation and writes branch.csv, orbits.csv,
// branch.png and summary.txt. For a core::PeriodicOrbitProblem trace applies the scene's
// `formulation` key after setup. setup throws core::InputError for bad scene values.
//
//   // drivers/trace_duffing.cpp
//   static const bool registered = backbone::drivers::register_trace_problem(
//       {"duffing", "conservative Duffing oscillator x'' + x + x^3 = 0", &duffing::scene_keys,
//        {"backbone"},
//        [](const core::Scene& scene, const std::string& branch) {
//          TraceSetup s; s.problem = std::make_unique<duffing::Duffing>(...);
//          s.guess = ...; s.direction = ...; return s;
//        }});
#pragma once

#include <boost/program_options.hpp>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "continuation/branch.hpp"
#include "core/problem.hpp"
#include "core/scene.hpp"
#include "core/types.hpp"

namespace backbone::drivers {

struct TraceSetup {
  // The problem whose solution curve is followed: usually a core::PeriodicOrbitProblem
  // (orbits.csv is written only for those), any core::Problem with n - m == 1 works.
  std::unique_ptr<core::Problem> problem;
  // Starting guess (layout of the problem); trace corrects it before continuing.
  core::Vector guess;
  // Initial direction hint, size num_unknowns: the first tangent t satisfies t . direction > 0.
  // Empty: increase the period (PeriodicOrbitProblem) or the last unknown.
  core::Vector direction;
  // Optional: extra outputs (figures, tables) written into the output directory after the
  // branch; called only when at least one point converged. Must write atomically
  // (core::Table::write_csv, core::render_png).
  std::function<void(const std::filesystem::path& out_dir, const continuation::Branch& branch)>
      write_extra_outputs;
  // Optional: independent check of each converged point (x in the problem's unknowns); a
  // non-empty answer rejects it and the step is retried smaller (ContinuationHooks).
  std::function<std::string(const core::Vector& x)> reject_point;
  // Optional: words appended to each progress line (e.g. "contact 0.31 T").
  std::function<std::string(const continuation::BranchPoint& point)> describe_point;
};

struct TraceProblem {
  std::string name;     // value of the scene key `problem`
  std::string summary;  // one line for `backbone trace --help`
  // The problem's scene keys with defaults (same description the simulate driver uses).
  boost::program_options::options_description (*scene_keys)();
  std::vector<std::string> branches;  // accepted --branch values; the first is the default
  std::function<TraceSetup(const core::Scene& scene, const std::string& branch)> setup;
};

// Returns false (and keeps the first) when the name is already registered.
bool register_trace_problem(TraceProblem problem);
const std::map<std::string, TraceProblem>& trace_problems();

}  // namespace backbone::drivers
