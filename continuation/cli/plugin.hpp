// A problem plugged into the `backbone` CLI: what `trace`, `simulate`, `bench`, `figures` and
// `reproduce` need to know of it, in one value that the problem's own folder builds.
//
// Each problems/<name>/ that the CLI can run defines, in its own sources,
//     void backbone::<name>::register_plugin(backbone::cli::PluginRegistry&);
// The build finds every problem folder whose sources define it and generates the one
// register_all() list the CLI calls at start (drivers/CMakeLists.txt): a problem that defines
// the function is always registered, and a listed problem whose function is missing is a link
// error, never a silent miss. The CLI then only parses, dispatches and reports: the problem's
// setup builds the core::Problem and its guess, its hooks check points and write its extra
// outputs, and its jobs (benchmarks, figures) are library functions of the problem.
//
//   // problems/pendulum/plugin.cpp
//   void backbone::pendulum::register_plugin(cli::PluginRegistry& registry) {
//     cli::ProblemPlugin p;
//     p.name = "pendulum"; p.summary = "conservative pendulum q'' = -sin q";
//     p.scene_keys = &pendulum::scene_keys; p.branches = {"backbone"};
//     p.setup = [](const core::Scene& scene, const std::string& branch) {
//       cli::TraceSetup s; s.problem = std::make_unique<Pendulum>();
//       s.guess = ...; s.direction = ...; return s;
//     };
//     registry.add(std::move(p));
//   }
#pragma once

#include <boost/program_options.hpp>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "continuation/branch.hpp"
#include "continuation/options.hpp"
#include "core/io/scene.hpp"
#include "core/problem.hpp"
#include "core/solvers/newton.hpp"
#include "core/types.hpp"

namespace backbone::cli {

using continuation::Branch;
using continuation::BranchPoint;
using continuation::ContinuationOptions;

// What `trace` follows: built by ProblemPlugin::setup from the scene and the branch name.
struct TraceSetup {
  // The problem whose solution curve is followed: usually a core::PeriodicOrbitProblem
  // (orbits.csv is written only for those); any core::Problem with n - m == 1 works.
  std::unique_ptr<core::Problem> problem;
  // Starting guess (layout of the problem); trace corrects it before continuing.
  core::Vector guess;
  // Initial direction hint, size num_unknowns: the first tangent t satisfies t . direction > 0.
  // Empty: increase the period (PeriodicOrbitProblem) or the last unknown.
  core::Vector direction;
  // Optional: extra outputs (figures, tables) written into the output directory after the
  // branch; called only when at least one point converged. Must write atomically
  // (core::Table::write_csv, core::render_png).
  std::function<void(const std::filesystem::path& out_dir, const Branch& branch)>
      write_extra_outputs;
  // Optional: independent check of each converged point (x in the problem's unknowns); a
  // non-empty answer rejects it and the step is retried smaller (ContinuationHooks).
  std::function<std::string(const core::Vector& x)> reject_point;
  // Optional: words appended to each progress line (e.g. "closed-form rel err 1e-14").
  std::function<std::string(const BranchPoint& point)> describe_point;
  // Optional: the branch's own continuation and corrector settings, applied by `trace` to the
  // options read from the scene before the run (a setup keeps a value the user gave: the
  // scene's values()[key].defaulted() tells a default from a given key).
  std::function<void(ContinuationOptions& options, core::NewtonOptions& newton)> branch_options;
  // Optional: describes a verified branch point (ContinuationHooks::describe_branch_point).
  std::function<core::Observables(const core::Vector& on_branch, const core::Vector& attached)>
      describe_branch_point;
  // Optional: checks of the scene that apply to a trace but not to `inspect`, which builds the
  // same setup (e.g. a key that leaves the traced curve undefined); throws core::InputError.
  std::function<void()> check_for_trace;
  // Optional: the dimension of the solution set the extra outputs cover (an atlas of a 2D
  // manifold), when it is not the curve the sizes make the branch: the header and summary.txt
  // state it, and the traced branch, only the corrected start the covering grows from, gets no
  // branch.png. 0: the dimension the sizes give.
  int covered_dimension = 0;
  // Applies branch_options (when set) to the settings a run read from its scene and checks
  // them: what every runner of a trace (trace, the benchmarks) does before making its corrector.
  void apply_branch_options(ContinuationOptions& options, core::NewtonOptions& newton) const;
};

// A named job of a problem that writes into a folder: a benchmark case (`backbone bench
// --case NAME`) or a set of figures (`backbone figures`). Returns an exit code (0 ok, 1
// numerical failure); throws core::InputError for bad input.
struct ProblemJob {
  std::string name;
  std::string summary;  // one line for --help
  std::function<int(const std::filesystem::path& out)> run;
};

// One step of the main job (`backbone reproduce`): a subcommand with its arguments, where
// the word "{out}" (alone or inside a word) stands for the output folder.
struct ReproduceStep {
  std::string name;
  std::string command;
  std::vector<std::string> arguments;
};

struct ProblemPlugin {
  std::string name;     // value of the scene key `problem`
  std::string summary;  // one line for --help

  // `trace`: the problem's scene keys with defaults (a problem may declare a continuation key
  // itself to change its default), its branches (the first is the default) and the setup.
  std::function<boost::program_options::options_description()> scene_keys;
  std::vector<std::string> branches;
  // Families of branch names beyond the list (optional): a test of a name, and how the
  // messages and --help name the family ("modeJ for every J >= 1").
  std::function<bool(const std::string& name)> branch_family;
  std::string branch_family_text;
  std::function<TraceSetup(const core::Scene& scene, const std::string& branch)> setup;

  // `simulate` (optional): the scene and driver keys of a time simulation, and the run, which
  // validates everything before it creates `out` (bad input writes nothing).
  std::function<boost::program_options::options_description()> simulate_keys;
  std::function<int(const core::Scene& scene, const std::filesystem::path& out)> simulate;

  // Units of the observables (branch.csv columns) for axis labels and docs: {"energy", "J"}.
  std::map<std::string, std::string> units;
  // The observables branch.png draws (x, y); empty: frequency against energy when both exist.
  std::pair<std::string, std::string> branch_axes;

  std::vector<ProblemJob> bench_cases;
  std::vector<ProblemJob> figures;  // run(out): reads the traced branches in out, draws
  std::vector<ReproduceStep> reproduce;

  bool can_trace() const { return static_cast<bool>(setup); }
  // A name in branches or in the family.
  bool has_branch(const std::string& name) const;
  // The branches for messages: the list, then the family's text.
  std::string branch_list() const;
  bool can_simulate() const { return static_cast<bool>(simulate); }
};

class PluginRegistry {
 public:
  // Throws std::logic_error when the name is empty or already registered (a build mistake).
  void add(ProblemPlugin plugin);
  // nullptr when no plugin has that name.
  const ProblemPlugin* find(const std::string& name) const;
  // In registration order.
  const std::vector<ProblemPlugin>& all() const { return plugins_; }
  // "contact_bar, duffing" (for messages), only those for which `has` holds when given.
  std::string names(const std::function<bool(const ProblemPlugin&)>& has = {}) const;

 private:
  std::vector<ProblemPlugin> plugins_;
};

}  // namespace backbone::cli
