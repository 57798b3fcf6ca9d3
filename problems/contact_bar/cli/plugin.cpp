// The contact bar in the `backbone` CLI (continuation/cli/plugin.hpp): its trace branches and
// simulation (trace.hpp), its benchmarks (bench/), its figures (figures/) and its steps of the
// main job, `backbone reproduce`.
#include "continuation/cli/plugin.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "problems/contact_bar/bench/cases.hpp"
#include "problems/contact_bar/bench/peers.hpp"
#include "problems/contact_bar/cli/trace.hpp"
#include "problems/contact_bar/figures/clearance.hpp"
#include "problems/contact_bar/figures/modes.hpp"
#include "problems/contact_bar/figures/resonance.hpp"
#include "problems/contact_bar/figures/stability.hpp"

namespace backbone::contact_bar {

namespace {

// The stability study (problems/contact_bar/orbits/README.md, section 'Stability'), into
// {out}/stability/<name>:
//   - the fronts' multipliers (the default representation; K also by the TD-BEM's own march
//     where the TD-BEM traces the orbits) of modes 1, 2 and 3 at 40, 80 and
//     160 intervals, at 40 with the shooting's time step halved and with the orbits traced by
//     the exact solver, of the subharmonic backbone
//     (20 to 160 intervals, and 20 with the time step halved) and its continuum at 1e-3 J (20 to
//     80), of the families attached to mode 1 at 40, 80 and 160 intervals (T = 3.6, 3.5, 3.25,
//     3.2 and more), at 70 and 140 and at 70 with the time step halved (T = 3.6, 3.5, 24/7, 3.2
//     and 22/7 L/c), the families at 40 again with their perturbed orbits over 3000 periods,
//     and of the clearance modes 1 and 2;
//   - the projected grid's (grid_<name>), modes 1 and 2 at 40 and 80, at 40 with c dt / dx
//     halved and by the exact solver, and mode 2 at 160, for the comparison.
std::vector<cli::ReproduceStep> stability_steps(const std::string& scenes) {
  std::vector<cli::ReproduceStep> steps;
  // Every run of the fronts traced by the TD-BEM also computes K by the TD-BEM's own march.
  auto add = [&](const std::string& name, const std::string& scene, std::vector<std::string> args) {
    auto has = [&](const std::string& key, const std::string& value) {
      for (std::size_t i = 0; i + 1 < args.size(); ++i)
        if (args[i] == key && args[i + 1] == value) return true;
      return false;
    };
    const bool tdbem_fronts =
        !has("--stability_representation", "grid") && !has("--shooting_solver", "exact");
    args.insert(args.begin(), scenes + scene);
    if (tdbem_fronts)
      for (const char* word : {"--stability_tdbem_check", "true"}) args.push_back(word);
    for (const char* word : {"--stability", "true", "--threads", "2", "--out"})
      args.push_back(word);
    args.push_back("{out}/stability/" + name);
    steps.push_back({"stability_" + name, "trace", std::move(args)});
  };
  for (const char* mode : {"mode1", "mode2", "mode3"}) {
    for (const char* n : {"40", "80", "160"})
      add(fmt::format("{}_N{}", mode, n), "paper.ini",
          {"--branch", mode, "--shooting_elements", n});
    add(fmt::format("{}_N40_dt_half", mode), "paper.ini",
        {"--branch", mode, "--shooting_elements", "40", "--steps_per_period", "80"});
    add(fmt::format("{}_N40_exact", mode), "paper.ini",
        {"--branch", mode, "--shooting_elements", "40", "--shooting_solver", "exact"});
  }
  for (const char* n : {"20", "40", "80", "160"})
    add(fmt::format("subharmonic_N{}", n), "paper.ini",
        {"--branch", "subharmonic", "--shooting_elements", n});
  add("subharmonic_N20_dt_half", "paper.ini",
      {"--branch", "subharmonic", "--shooting_elements", "20", "--steps_per_period", "80"});
  for (const char* n : {"20", "40", "80"})
    add(fmt::format("subharmonic_continuum_N{}", n), "paper.ini",
        {"--branch", "subharmonic_continuum", "--energy", "1e-3", "--shooting_elements", n});
  // Every family the grid finds attached to mode 1 up to 3e-5 J, followed with its multipliers
  // (the steps of mode1_resonance_twelve: 0.05 of the amplitude); at 140 and 160 intervals 8
  // points of each (the seven families' rank reports there take minutes per 30 points).
  for (const auto& [run, n, per_period, points] :
       {std::array<std::string, 4>{"N40", "40", "40", "30"},
        {"N80", "80", "40", "30"},
        {"N160", "160", "40", "8"},
        {"N70", "70", "40", "30"},
        {"N140", "140", "40", "8"},
        {"N70_dt_half", "70", "80", "30"}})
    add("mode1_resonances_" + run, "paper.ini",
        {"--branch", "mode1", "--shooting_elements", n, "--steps_per_period", per_period,
         "--detect_branch_points", "true", "--ds", "0.05", "--ds_max", "0.05", "--energy_max",
         "3e-5", "--follow", "all", "--follow_max_points", points});
  // The perturbed orbits over 3 times the periods, on the families with grazing ends at 40
  // intervals: a drift that stays linear (3 times the growth) is no slow exponential one.
  add("mode1_resonances_N40_growth_3000", "paper.ini",
      {"--branch",
       "mode1",
       "--shooting_elements",
       "40",
       "--steps_per_period",
       "40",
       "--detect_branch_points",
       "true",
       "--ds",
       "0.05",
       "--ds_max",
       "0.05",
       "--energy_max",
       "3e-5",
       "--follow",
       "all",
       "--follow_max_points",
       "30",
       "--stability_growth_periods",
       "3000"});
  for (const char* mode : {"mode1", "mode2"})
    add(fmt::format("clearance_{}", mode), "clearance.ini", {"--branch", mode});
  // The projected grid, its tolerances at the size of its projection's error.
  const std::vector<std::string> grid{"--stability_representation",  "grid",
                                      "--floquet_tolerance",         "1e-2",
                                      "--floquet_trivial_tolerance", "1e-2"};
  auto add_grid = [&](const std::string& branch, const std::string& run,
                      std::vector<std::string> extra) {
    std::vector<std::string> args{"--branch", branch};
    args.insert(args.end(), extra.begin(), extra.end());
    args.insert(args.end(), grid.begin(), grid.end());
    add("grid_" + branch + "_" + run, "paper.ini", std::move(args));
  };
  for (const char* branch : {"mode1", "mode2"}) {
    add_grid(branch, "N40", {"--shooting_elements", "40"});
    add_grid(branch, "N80", {"--shooting_elements", "80"});
    add_grid(branch, "N40_dt_half",
             {"--shooting_elements", "40", "--stability_courant", "0.015625"});
    add_grid(branch, "N40_exact", {"--shooting_elements", "40", "--shooting_solver", "exact"});
  }
  add_grid("mode2", "N160", {"--shooting_elements", "160"});
  return steps;
}

// A family attached to mode 2 or 3 on the grid the law picks (orbits/README.md, 'Attached
// families: the law', Mode J): the knots' reference nodes on the kinks at the branch point, so
// that the mapped grid is uniform there; detected on steps of 0.05 g0 and followed.
cli::ReproduceStep law_step(const std::string& name, const std::string& branch,
                            const std::string& elements, const std::string& knot_nodes,
                            const std::string& energy_max) {
  return {name,
          "trace",
          {"problems/contact_bar/scenes/paper.ini",
           "--branch",
           branch,
           "--shooting_elements",
           elements,
           "--knot_nodes",
           knot_nodes,
           "--detect_branch_points",
           "true",
           "--amplitude_units",
           "false",
           "--ds",
           "0.05",
           "--ds_max",
           "0.05",
           "--energy_max",
           energy_max,
           "--follow",
           "all",
           "--out",
           "{out}/" + name}};
}

// Mode J of the clearance scene with the back wall at gap_back.
cli::ReproduceStep clearance_step(const std::string& name, const std::string& branch,
                                  const std::string& gap_back) {
  return {name,
          "trace",
          {"problems/contact_bar/scenes/clearance.ini", "--branch", branch, "--gap_back", gap_back,
           "--out", "{out}/" + name}};
}

// 10^4 periods of a clearance orbit (strain 0.01, orbits/README.md 'Modes in a clearance') by
// TD-BEM with dt = 0.0073, no multiple of L/c: every contact instant is a fresh root.
cli::ReproduceStep drift_step(const std::string& name, const std::string& gap_back,
                              const std::string& u0, const std::string& period) {
  return {name,
          "simulate",
          {"problems/contact_bar/scenes/clearance.ini", "--gap_back", gap_back, "--u0", u0,
           "--period", period, "--periods", "10000", "--dt", "0.0073", "--out", "{out}/" + name}};
}

}  // namespace

void register_plugin(cli::PluginRegistry& registry) {
  cli::ProblemPlugin p = trace_plugin();
  p.bench_cases = bench_cases();
  for (cli::ProblemJob& job : peer_bench_cases()) p.bench_cases.push_back(std::move(job));
  p.figures = figure_jobs();
  for (cli::ProblemJob& job : resonance_figure_jobs()) p.figures.push_back(std::move(job));
  for (cli::ProblemJob& job : stability_figure_jobs()) p.figures.push_back(std::move(job));
  for (cli::ProblemJob& job : clearance_figure_jobs()) p.figures.push_back(std::move(job));
  const std::string scenes = "problems/contact_bar/scenes/";
  p.reproduce = {
      {"bouncing_bar",
       "simulate",
       {scenes + "bouncing_bar.ini", "--compare", "--periods", "2", "--out", "{out}/bouncing_bar"}},
      {"mode1_orbit",
       "simulate",
       {scenes + "paper.ini", "--compare", "--periods", "1", "--out", "{out}/mode1_orbit"}},
      {"mode1", "trace", {scenes + "paper.ini", "--branch", "mode1", "--out", "{out}/mode1"}},
      {"mode2", "trace", {scenes + "paper.ini", "--branch", "mode2", "--out", "{out}/mode2"}},
      {"mode3", "trace", {scenes + "paper.ini", "--branch", "mode3", "--out", "{out}/mode3"}},
      {"mode4", "trace", {scenes + "paper.ini", "--branch", "mode4", "--out", "{out}/mode4"}},
      {"mode5", "trace", {scenes + "paper.ini", "--branch", "mode5", "--out", "{out}/mode5"}},
      {"mode8", "trace", {scenes + "paper.ini", "--branch", "mode8", "--out", "{out}/mode8"}},
      {"mode3_other_bar",
       "trace",
       {scenes + "paper.ini", "--branch", "mode3", "--length", "2", "--youngs_modulus", "4",
        "--gap", "5e-3", "--u0", "0:0 2:-1e-2", "--period", "1", "--dt", "1e-3", "--energy_max",
        "1", "--out", "{out}/mode3_other_bar"}},
      {"mode1_resonances",
       "trace",
       {scenes + "paper.ini", "--branch", "mode1", "--shooting_elements", "40", "--energy_max",
        "3e-5", "--follow", "all", "--follow_max_points", "100", "--out",
        "{out}/mode1_resonances"}},
      // The law of the attached periods against detection on fine steps (mode1_law.csv by the
      // figures step): every family the 40-interval grid holds up to 1e-3 J. Steps of 0.1 % of
      // the amplitude: the test function's dips next to grazing are narrower than 0.005 g0.
      {"mode1_law",
       "trace",
       {scenes + "paper.ini", "--branch", "mode1", "--shooting_elements", "40",
        "--detect_branch_points", "true", "--ds", "0.001", "--ds_max", "0.001", "--max_points",
        "8000", "--energy_max", "1e-3", "--out", "{out}/mode1_law"}},
      // The family of resonance order 12 attached at T = 24/7 L/c (the paper's "about 12
      // times", figures/README.md): 70 intervals resolve it (7 divides 140), and steps of 0.05
      // sample the test function finely enough to locate it (the third candidate).
      {"mode1_resonance_twelve",
       "trace",
       {scenes + "paper.ini", "--branch", "mode1", "--shooting_elements", "70",
        "--detect_branch_points", "true", "--ds", "0.05", "--ds_max", "0.05", "--energy_max",
        "3e-5", "--follow", "3", "--out", "{out}/mode1_resonance_twelve"}},
      law_step("mode2_resonances", "mode2", "35", "10", "4e-5"),
      law_step("mode2_resonances_14_11", "mode2", "77", "21", "1e-4"),
      law_step("mode3_resonances", "mode3", "46", "10 26", "4e-4"),
      {"subharmonic",
       "trace",
       {scenes + "paper.ini", "--branch", "subharmonic", "--out", "{out}/subharmonic"}},
      // The continuum at two energies, from the grazing limit shape 1 to shape_end (about one
      // second each; problems/contact_bar/orbits/README.md, section 'Subharmonic continuum').
      {"subharmonic_continuum",
       "trace",
       {scenes + "paper.ini", "--branch", "subharmonic_continuum", "--energy", "1.25e-5", "--out",
        "{out}/subharmonic_continuum"}},
      {"subharmonic_continuum_1e-3",
       "trace",
       {scenes + "paper.ini", "--branch", "subharmonic_continuum", "--energy", "1e-3", "--out",
        "{out}/subharmonic_continuum_1e-3"}},
      // The continuum of mode 4 over two periods (problems/contact_bar/orbits/README.md,
      // 'Subharmonic continuum of mode J'): its backbone at N and 2N, and the members at one
      // energy (strain 9 g0 / L) from limit to limit.
      {"subharmonic4",
       "trace",
       {scenes + "paper.ini", "--branch", "subharmonic4", "--out", "{out}/subharmonic4"}},
      {"subharmonic4_N40",
       "trace",
       {scenes + "paper.ini", "--branch", "subharmonic4", "--shooting_elements", "40", "--out",
        "{out}/subharmonic4_N40"}},
      {"subharmonic_continuum4",
       "trace",
       {scenes + "paper.ini", "--branch", "subharmonic_continuum4", "--out",
        "{out}/subharmonic_continuum4"}},
      // The end in a clearance (problems/contact_bar/orbits/README.md, 'Modes in a
      // clearance'): modes 1 and 2 with the back wall as far as the front one, and three times
      // as far; then 10^4 periods of one orbit of each by TD-BEM, off the L/c lattice
      // (dt = 0.0073), for the energy drift (figures: clearance_energy_drift.csv).
      clearance_step("clearance_mode1", "mode1", "1e-3"),
      clearance_step("clearance_mode2", "mode2", "1e-3"),
      clearance_step("clearance_asym_mode1", "mode1", "3e-3"),
      clearance_step("clearance_asym_mode2", "mode2", "3e-3"),
      drift_step("clearance_drift_mode1", "1e-3", "0:0 0.55:0.0055 1:0.001", "2.2"),
      drift_step("clearance_drift_mode2", "1e-3", "0:0 0.275:-0.00275 0.825:0.00275 1:0.001",
                 "1.1"),
      drift_step("clearance_drift_asym_mode1", "3e-3", "0:0 0.55:0.0055 1:0.001", "2.4"),
      drift_step("clearance_drift_asym_mode2", "3e-3", "0:0 0.325:-0.00325 0.875:0.00225 1:0.001",
                 "1.2"),
      // Other scenes, the bar changed (and u0, period and dt with it, so that each scene.ini
      // simulates too): the closed forms must hold there as well.
      {"mode1_short_bar",
       "trace",
       {scenes + "paper.ini", "--branch", "mode1", "--length", "0.3", "--youngs_modulus", "7e4",
        "--density", "2.7", "--gap", "1e-5", "--u0", "0:0 0.3:-3e-5", "--period", "0.0055", "--dt",
        "1e-5", "--out", "{out}/mode1_short_bar"}},
      {"mode2_steel_bar",
       "trace",
       {scenes + "paper.ini",
        "--branch",
        "mode2",
        "--length",
        "2.5",
        "--youngs_modulus",
        "2.1e11",
        "--density",
        "7850",
        "--area",
        "3e-4",
        "--gap",
        "1e-4",
        "--energy_max",
        "1e3",
        "--u0",
        "0:0 2.5:-3e-4",
        "--period",
        "6.5e-4",
        "--dt",
        "1e-6",
        "--out",
        "{out}/mode2_steel_bar"}},
      {"figures", "figures", {"--out", "{out}"}},
      {"bench", "bench", {"--problem", "contact_bar", "--out", "{out}/bench"}},
  };
  // The stability study after the paper scene's branches, before the other bars.
  const auto other_bars =
      std::find_if(p.reproduce.begin(), p.reproduce.end(),
                   [](const cli::ReproduceStep& r) { return r.name == "mode1_short_bar"; });
  const std::vector<cli::ReproduceStep> study = stability_steps(scenes);
  p.reproduce.insert(other_bars, study.begin(), study.end());
  registry.add(std::move(p));
}

}  // namespace backbone::contact_bar
