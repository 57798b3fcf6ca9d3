// The continuation keys of a scene, and one entry point that runs the method they choose.
//
// `backbone trace` reads a problem's scene keys plus these (method, predictor, newton,
// formulation, ds, ds_min, ds_max, max_points, bounds, rank checks, Newton tolerance, natural
// parameter, threads); a problem that declares one of them itself owns its default (the contact
// bar declares ds and ds_max). read_run_settings validates them all before any work (InputError
// naming the key); run_continuation dispatches to pseudo_arclength, natural or
// natural_then_arclength.
//
//   po::options_description keys = problem_keys;
//   keys.add(continuation_keys(problem_keys));
//   core::Scene scene = core::read_scene(keys, path, args, driver_keys);
//   RunSettings run = read_run_settings(scene);
//   auto corrector = core::make_corrector(run.newton, run.newton_options);
//   SwitchingBranch b = run_continuation(problem, guess, direction, run, *corrector, hooks);
#pragma once

#include <boost/program_options.hpp>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "continuation/branch_points/follow.hpp"
#include "continuation/cli/plugin.hpp"
#include "continuation/methods/switching.hpp"
#include "continuation/options.hpp"
#include "continuation/restart.hpp"
#include "core/io/scene.hpp"
#include "core/orbits/periodic_orbit.hpp"
#include "core/solvers/newton.hpp"

namespace backbone::cli {

using continuation::ContinuationHooks;
using continuation::ContinuationOptions;
using continuation::FollowRun;
using continuation::RestartPoint;
using continuation::SwitchingBranch;

// The continuation keys with defaults, minus any that problem_keys declares itself.
boost::program_options::options_description continuation_keys(
    const boost::program_options::options_description& problem_keys);

struct RunSettings {
  ContinuationOptions options;
  std::string newton = "eigen";  // corrector name (core::make_corrector)
  core::NewtonOptions newton_options;
  core::ShootingFormulation formulation = core::ShootingFormulation::half_period_velocity;
  std::string natural_parameter = "period";  // the period unknown or an observable's name
  double natural_direction = 1;              // +1 or -1
  int threads = 1;   // finite-difference Jacobian columns (core::set_default_jacobian_threads)
  FollowRun follow;  // keys follow, follow_max_points (follow.hpp); follow implies detection
};

// Throws core::InputError naming the key for any bad value.
RunSettings read_run_settings(const core::Scene& scene);

// Runs settings.options.method from guess. direction: the hint of pseudo-arclength (the first
// tangent t has t . direction > 0). For natural methods the parameter is the period unknown of
// a PeriodicOrbitProblem when natural_parameter is "period", else the named observable.
// restart (after take_up, restart.hpp): with its state the run continues from it bit for bit;
// without, guess (the saved point) is corrected again and the points numbered on from it.
SwitchingBranch run_continuation(const core::Problem& problem, const core::Vector& guess,
                                 const core::Vector& direction, const RunSettings& settings,
                                 core::Corrector& corrector, const ContinuationHooks& hooks,
                                 const RestartPoint* restart = nullptr);

// The value given for --KEY among command-line words (`--key value` or `--key=value`); empty
// when the key is not there. For the keys a command refuses or checks before it reads a scene.
std::optional<std::string> given_on_command_line(const std::vector<std::string>& words,
                                                 const std::string& key);

// The scene keys of the plugin's trace (its own and the continuation keys) that `keys` lacks:
// what `simulate` accepts in a scene.ini written by `trace` without using it.
boost::program_options::options_description trace_keys_beyond(
    const ProblemPlugin& plugin, const boost::program_options::options_description& keys);

}  // namespace backbone::cli
