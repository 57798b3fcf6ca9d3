#include "problems/contact_bar/figures/stability.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <string>

#include "core/io/plot.hpp"
#include "core/io/scene.hpp"
#include "core/io/table.hpp"
#include "problems/contact_bar/figures/modes.hpp"
#include "problems/contact_bar/orbits/family.hpp"
#include "problems/contact_bar/orbits/monodromy.hpp"
#include "problems/contact_bar/solver/scene.hpp"

namespace backbone::contact_bar {

namespace fs = std::filesystem;

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double smallest(const std::vector<double>& v) {
  double m = std::nan("");
  for (double x : v)
    if (!std::isnan(x) && !(x >= m)) m = x;
  return m;
}

double largest(const std::vector<double>& v) {
  double m = std::nan("");
  for (double x : v)
    if (!std::isnan(x) && !(x <= m)) m = x;
  return m;
}

}  // namespace

namespace {

// A run's own name: its folder, or <trace>/<branch_point_K> for a family it followed.
std::string run_name(const fs::path& run, fs::path& scene_dir) {
  const bool followed = run.filename().string().rfind("branch_point_", 0) == 0;
  scene_dir = followed ? run.parent_path() : run;
  return followed ? scene_dir.filename().string() + "/" + run.filename().string()
                  : run.filename().string();
}

double number_or_nan(const std::string& text) {
  return text.empty() ? std::nan("") : std::stod(text);
}

// The frequency-energy figure of the fronts' runs: every point coloured by the Jordan defect
// of its K (0: every multiplier on the circle with its eigenvectors; 1, 2: linear growth along
// as many chains), an unstable point circled, one with a multiplier off the circle on a kink of
// the period map (the TD-BEM's one-sided K apart by over 1e-3: one side's K, which decides
// nothing; the perturbed orbits of fronts.csv's growth_* do) in a square.
void plot_stability_backbones(const fs::path& folder, const std::vector<fs::path>& runs) {
  std::string curves;
  for (const fs::path& run : runs) {
    if (!fs::exists(run / "fronts.csv")) continue;
    fs::path scene_dir;
    const std::string name = run_name(run, scene_dir);
    // One run per branch: the trace's own settings at 20, 40 or 70 intervals (and what it
    // followed), not its refinements or its exact-solver twin.
    const std::string trace = name.substr(0, name.find('/'));
    if (!trace.ends_with("_N20") && !trace.ends_with("_N40") && !trace.ends_with("_N70")) continue;
    const std::string fronts = core::gnuplot_quote(run / "fronts.csv");
    const std::string branch = core::gnuplot_quote(run / "branch.csv");
    curves += fmt::format(
        "{}{} using 'energy':(2*pi/column('period')):(column('jordan_defect')+1) with "
        "linespoints lc variable pt 7 ps 0.6 notitle",
        curves.empty() ? "plot " : ", ", fronts);
    const core::Table table = core::Table::read_csv(run / "fronts.csv");
    const auto& columns = table.columns();
    if (std::find(columns.begin(), columns.end(), "tdbem_kink") == columns.end()) {
      curves += fmt::format(
          ", {} using 'energy':(column('stable')==0 ? column('frequency') : NaN) with points pt 6 "
          "ps 2 lc 'black' notitle",
          branch);
    } else {
      const double tolerance =
          number_or_nan(scene_value(scene_dir / "scene.ini", "floquet_tolerance"));
      for (const auto& [test, style] :
           {std::pair{"<=", "pt 6 ps 2 lc 'black'"}, std::pair{">", "pt 4 ps 1.6 lc 'gray40'"}})
        curves += fmt::format(
            ", {} using 'energy':(column('max_modulus_minus_one') > {:.17g} && "
            "column('tdbem_kink') {} 1e-3 ? 2*pi/column('period') : NaN) with points {} notitle",
            fronts, std::isfinite(tolerance) ? tolerance : 1e-4, test, style);
    }
    // The first point of each run named, but the families attached to mode 1 (on top of it).
    if (name.find("resonances") == std::string::npos)
      curves += fmt::format(
          ", {} every ::0::0 using 'energy':(2*pi/column('period')):('{}') with labels right "
          "offset -1,0 font ',9' noenhanced notitle",
          fronts, name.substr(0, name.find("_N")));
  }
  if (curves.empty()) return;
  curves +=
      ", NaN with points pt 7 lc 1 title 'Jordan defect 0 (neutral)', NaN with points pt 7 lc 2 "
      "title 'defect 1 (linear growth)', NaN with points pt 7 lc 3 title 'defect 2', NaN with "
      "points pt 6 ps 2 lc 'black' title 'unstable (|mu| > 1 + tol)', NaN with points pt 4 ps 1.6 "
      "lc 'gray40' title 'the same on a kink (one-sided K)'";
  const core::PlotResult r = core::render_png(
      folder / "stability_backbones.png",
      "set datafile separator ','\nset key noenhanced\nset grid\nset logscale x\nset format x "
      "'%.0e'\nset xrange [1e-7:2e-2]\nset xlabel 'energy [J]'\nset ylabel 'frequency "
      "[rad/s]'\nset key outside right\n"
      "set title 'K of the fronts: colour, its Jordan defect; circle, unstable; square, on a "
      "kink'\n" +
          curves + "\n");
  if (!r.ok) fmt::print("[figures] stability_backbones.png skipped: {}\n", r.message);
}

// The multipliers in the complex plane: the fronts' K of modes 1 to 3 and the subharmonic
// backbone (every point), against the projected grid's at 160 intervals on mode 2.
void plot_multipliers(const fs::path& folder) {
  std::string curves = "plot cos(t), sin(t) with lines lc 'grey' title 'unit circle'";
  const std::vector<std::pair<std::string, std::string>> runs{
      {"grid_mode2_N160", "projected grid, mode 2, N = 160"},
      {"mode1_N40", "fronts, mode 1"},
      {"mode2_N40", "fronts, mode 2"},
      {"mode3_N40", "fronts, mode 3"},
      {"subharmonic_N20", "fronts, subharmonic backbone"}};
  bool any = false;
  for (const auto& [run, title] : runs) {
    const fs::path csv = folder / run / "multipliers.csv";
    if (!fs::exists(csv)) continue;
    any = true;
    curves += fmt::format(", {} using 're':'im' with points pt {} ps {} title '{}'",
                          core::gnuplot_quote(csv), run.starts_with("grid") ? 7 : 6,
                          run.starts_with("grid") ? "0.3" : "2", title);
  }
  if (!any) return;
  const core::PlotResult r = core::render_png(
      folder / "multipliers.png",
      "set datafile separator ','\nset key noenhanced\nset parametric\nset trange [0:2*pi]\nset "
      "size ratio -1\nset grid\nset xlabel 'Re mu'\nset ylabel 'Im mu'\nset key outside right\n"
      "set title 'Floquet multipliers of every point: the fronts (exact, at roots of unity) and "
      "the projected grid'\n" +
          curves + "\n");
  if (!r.ok) fmt::print("[figures] multipliers.png skipped: {}\n", r.message);
}

}  // namespace

// What a run's numbers say (orbits/README.md, 'Stability'): the fronts' K decides; the
// projected grid's counts are its own and no verdict on the bar.
// kinks: points where the TD-BEM's one-sided differences of K disagree (a grazing within the
// step): the map has no derivative there, and K is one side's, so a multiplier off the circle
// there (unstable_on_kinks of the unstable points) decides nothing.
std::string stability_verdict(const std::string& representation, int unstable,
                              int unstable_on_kinks, int undecided, double defect_min,
                              double defect_max, double kinks, const KinkGrowth& growth) {
  if (representation == "grid") return "projected grid: no verdict (see the fronts' runs)";
  std::string text;
  if (unstable > unstable_on_kinks)
    text = fmt::format("unstable at {} {}", unstable - unstable_on_kinks,
                       unstable - unstable_on_kinks == 1 ? "point" : "points");
  else if (unstable > 0 && growth.power <= 1.5)
    text = fmt::format(
        "no multiplier off the unit circle off the kinks; at {} {} on a kink one side's K has "
        "one (|mu| up to {:.3g}), but a perturbed orbit there grows like k^{:.2f}, at most "
        "{:.3g}-fold over {:g} periods: no excited |mu| above {:.4g}",
        unstable, unstable == 1 ? "point" : "points", growth.modulus, growth.power, growth.largest,
        growth.periods, std::pow(growth.largest, 1 / growth.periods));
  else if (unstable > 0)
    text = fmt::format(
        "no multiplier off the unit circle off the kinks; at {} {} on a kink one side's K has "
        "one{}: not resolved there",
        unstable, unstable == 1 ? "point" : "points",
        std::isnan(growth.power)
            ? std::string()
            : fmt::format(" and a perturbed orbit grows like k^{:.2f}", growth.power));
  else if (defect_max > 0)
    text = fmt::format(
        "no multiplier off the unit circle; Jordan defect {}{}: perturbations along it grow "
        "linearly in the number of periods",
        defect_min == defect_max ? "" : fmt::format("{:g} to ", defect_min), defect_max);
  else
    text = "neutral: every multiplier on the unit circle, with its eigenvectors";
  if (undecided > 0) text += fmt::format(" ({} points undecided)", undecided);
  if (kinks > 0)
    text += fmt::format(" ({:g} {} on a kink of the period map, a grazing: one-sided there)", kinks,
                        kinks == 1 ? "point" : "points");
  return text;
}

int write_stability_summary(const fs::path& out) {
  const fs::path folder = out / "stability";
  std::vector<fs::path> runs;
  if (fs::exists(folder))
    for (const auto& entry : fs::directory_iterator(folder)) {
      if (fs::exists(entry.path() / "branch.csv") && fs::exists(entry.path() / "multipliers.csv"))
        runs.push_back(entry.path());
      // The families a run followed (--follow), with their own multipliers.
      if (entry.is_directory())
        for (const fs::path& followed : followed_branches(entry.path()))
          if (fs::exists(followed / "multipliers.csv")) runs.push_back(followed);
    }
  if (runs.empty()) {
    fmt::print("[figures] stability_summary skipped: no trace with --stability true in {}\n",
               folder.string());
    return 0;
  }
  std::sort(runs.begin(), runs.end());
  core::Table summary({"run",
                       "branch",
                       "representation",
                       "elements",
                       "steps_per_period",
                       "courant",
                       "points",
                       "unstable_points",
                       "undecided_points",
                       "max_modulus_worst",
                       "max_modulus_median",
                       "trivial_distance_worst",
                       "determinant_error_worst",
                       "fronts_min",
                       "fronts_max",
                       "jordan_defect_min",
                       "jordan_defect_max",
                       "structure_error_worst",
                       "return_error_worst",
                       "real_negative_modulus_worst",
                       "complex_modulus_worst",
                       "tdbem_points",
                       "tdbem_kink_points",
                       "tdbem_k_difference_worst",
                       "tdbem_multiplier_difference_worst",
                       "growth_largest_worst",
                       "growth_power_worst",
                       "verdict"});
  std::string curves;
  for (const fs::path& run : runs) {
    const core::Table branch = core::Table::read_csv(run / "branch.csv");
    const core::Table multipliers = core::Table::read_csv(run / "multipliers.csv");
    const std::vector<double> stable = branch.column("stable"), point = branch.column("point");
    int unstable = 0, undecided = 0, unstable_on_kinks = 0;
    for (double s : stable) {
      unstable += s == 0 ? 1 : 0;
      undecided += s < 0 ? 1 : 0;
    }
    const std::vector<double> re = multipliers.column("re"), im = multipliers.column("im"),
                              modulus = multipliers.column("modulus"),
                              trivial = multipliers.column("trivial");
    std::vector<double> negative, complex;
    for (std::size_t i = 0; i < re.size(); ++i) {
      if (trivial[i] != 0) continue;
      if (im[i] == 0 && re[i] < 0) negative.push_back(modulus[i]);
      if (im[i] != 0) complex.push_back(modulus[i]);
    }
    std::vector<double> determinant_error;
    for (double d : branch.column("monodromy_determinant"))
      determinant_error.push_back(std::abs(d - 1));
    fs::path scene_dir;
    const std::string name = run_name(run, scene_dir);
    const fs::path scene = scene_dir / "scene.ini";
    std::string representation = scene_value(scene, "stability_representation");
    if (representation.empty()) representation = "fronts";
    // The fronts' own checks (fronts.csv): sizes, Jordan defects, structure and return errors.
    const double nan = std::nan("");
    double fronts_min = nan, fronts_max = nan, defect_min = nan, defect_max = nan, structure = nan,
           returned = nan;
    // K by the TD-BEM's own march against it (--stability_tdbem_check): how many points have it,
    // how many sit on a kink of the map (one-sided differences apart by over 1e-3; 1e-5 at most
    // elsewhere in the main job), and the worst differences off the kinks.
    double tdbem_points = nan, tdbem_kinks = nan, tdbem_k = nan, tdbem_mu = nan;
    // The perturbed orbits' check (--stability_growth_periods): worst over the run, and the
    // kink growth at the unstable points on a kink.
    double growth_worst = nan, power_worst = nan;
    KinkGrowth kink_growth;
    bool growth_failed = false;  // a point on a kink whose check failed: no conclusion there
    const std::vector<double> modulus_at = branch.column("max_multiplier_modulus");
    if (fs::exists(run / "fronts.csv")) {
      const core::Table f = core::Table::read_csv(run / "fronts.csv");
      fronts_min = smallest(f.column("fronts"));
      fronts_max = largest(f.column("fronts"));
      defect_min = smallest(f.column("jordan_defect"));
      defect_max = largest(f.column("jordan_defect"));
      structure = std::max({largest(f.column("time_shift_error")), largest(f.column("value_leak")),
                            largest(f.column("isometry_error"))});
      returned = largest(f.column("return_error"));
      const auto& names = f.columns();
      const bool growth = std::find(names.begin(), names.end(), "growth_power") != names.end();
      if (growth) {
        growth_worst = largest(f.column("growth_largest"));
        power_worst = largest(f.column("growth_power"));
        kink_growth.periods = number_or_nan(scene_value(scene, "stability_growth_periods"));
      }
      if (std::find(names.begin(), names.end(), "tdbem_ok") != names.end()) {
        tdbem_points = 0;
        tdbem_kinks = 0;
        const std::vector<double> ok = f.column("tdbem_ok"), kink = f.column("tdbem_kink"),
                                  at = f.column("point"), dk = f.column("tdbem_k_difference"),
                                  dmu = f.column("tdbem_multiplier_difference");
        std::vector<double> smooth_k, smooth_mu;
        for (std::size_t i = 0; i < ok.size(); ++i) {
          tdbem_points += ok[i];
          if (kink[i] > 1e-3) {
            tdbem_kinks += 1;
            for (std::size_t j = 0; j < point.size(); ++j) {
              if (point[j] != at[i] || stable[j] != 0) continue;
              ++unstable_on_kinks;
              kink_growth.modulus = std::fmax(kink_growth.modulus, modulus_at[j]);
              if (!growth) continue;
              const double g = f.column("growth_largest")[i], q = f.column("growth_power")[i];
              growth_failed = growth_failed || std::isnan(g) || std::isnan(q);
              kink_growth.largest = std::fmax(kink_growth.largest, g);
              kink_growth.power = std::fmax(kink_growth.power, q);
            }
            continue;
          }
          smooth_k.push_back(dk[i]);
          smooth_mu.push_back(dmu[i]);
        }
        tdbem_k = largest(smooth_k);
        tdbem_mu = largest(smooth_mu);
      }
    }
    const std::string bare = name.starts_with("grid_") ? name.substr(5) : name;
    summary.add_cells(
        {name,
         bare.substr(0, bare.find('_')),
         representation,
         number_or_nan(scene_value(scene, "shooting_elements")),
         number_or_nan(scene_value(scene, "steps_per_period")),
         representation == "grid" ? number_or_nan(scene_value(scene, "stability_courant")) : nan,
         double(stable.size()),
         double(unstable),
         double(undecided),
         largest(branch.column("max_multiplier_modulus")),
         median(branch.column("max_multiplier_modulus")),
         largest(branch.column("trivial_multiplier_distance")),
         largest(determinant_error),
         fronts_min,
         fronts_max,
         defect_min,
         defect_max,
         structure,
         returned,
         largest(negative),
         largest(complex),
         tdbem_points,
         tdbem_kinks,
         tdbem_k,
         tdbem_mu,
         growth_worst,
         power_worst,
         stability_verdict(representation, unstable, unstable_on_kinks, undecided, defect_min,
                           defect_max, tdbem_kinks, growth_failed ? KinkGrowth{} : kink_growth)});
    if (representation == "grid")
      curves += fmt::format(
          "{}{} using 'energy':'max_multiplier_modulus' with linespoints title '{}'",
          curves.empty() ? "plot " : ", ", core::gnuplot_quote(run / "branch.csv"), name);
  }
  summary.write_csv(folder / "summary.csv");
  fmt::print("[figures] wrote {}\n{}", (folder / "summary.csv").string(), summary.aligned(4));
  if (!curves.empty()) {
    const core::PlotResult r = core::render_png(
        folder / "max_modulus.png",
        "set datafile separator ','\nset key autotitle columnhead noenhanced\nset grid\nset "
        "logscale x\nset format x '%.0e'\n"
        "set xlabel 'energy [J]'\nset ylabel 'largest non-trivial |mu|'\nset key outside right\n"
        "set title 'Bar modes, projected grid: the largest Floquet multiplier by run'\n" +
            curves + "\n");
    if (!r.ok) fmt::print("[figures] max_modulus.png skipped: {}\n", r.message);
  }
  plot_stability_backbones(folder, runs);
  plot_multipliers(folder);
  return 0;
}

int write_perturbation_growth(const fs::path& out) {
  // The paper scene's bar (problems/contact_bar/scenes/paper.ini).
  const core::Scene scene = core::read_scene(
      scene_keys(), core::shipped_path("problems/contact_bar/scenes/paper.ini").string(), {},
      boost::program_options::options_description());
  bar::BarSetup setup = setup_from_scene(scene);
  core::Table table(
      {"mode", "energy", "period", "periods", "largest", "at_500", "last", "modulus_bound"});
  constexpr int periods = 1000;
  for (int mode : {1, 2, 3}) {
    const ContactFamily family(setup.material, setup.right.gap, mode);
    for (double factor : {2.0, 20.0, 200.0}) {
      const double energy = factor * family.grazing_energy();
      setup.u0 = family.u0(energy);
      const PerturbationGrowth g =
          perturbation_growth(setup, family.period(energy), periods, 1e-6, 40, 7);
      double at_half = 0;
      for (const auto& [k, d] : g.history)
        if (k <= periods / 2) at_half = std::max(at_half, d);
      table.add_row({double(mode), energy, family.period(energy), double(periods),
                     g.ok ? g.largest : std::nan(""), at_half, g.last,
                     std::pow(g.largest, 1.0 / periods)});
    }
  }
  fs::create_directories(out / "stability");
  table.write_csv(out / "stability" / "perturbation_growth.csv");
  fmt::print("[figures] wrote {}\n{}", (out / "stability" / "perturbation_growth.csv").string(),
             table.aligned(4));
  return 0;
}

std::vector<cli::ProblemJob> stability_figure_jobs() {
  return {{"stability_summary",
           "stability/summary.csv, stability_backbones.png, multipliers.png and max_modulus.png "
           "from the traces in OUT/stability",
           write_stability_summary},
          {"perturbation_growth",
           "stability/perturbation_growth.csv: random perturbations of modes 1 to 3 over 1000 "
           "periods by the exact solver",
           write_perturbation_growth}};
}

}  // namespace backbone::contact_bar
