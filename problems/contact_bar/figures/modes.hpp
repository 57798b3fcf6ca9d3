// The paper's figures of the contact-bar modes, drawn from the outputs of `backbone trace`
// (branch.csv, orbits.csv, closed_form_check.csv of OUT/mode1 and OUT/mode2), each with the CSV
// behind it beside it in OUT. Closed forms, asymptotes and the mode-2 node come from
// ContactFamily (family.hpp).
//   backbones            backbones.png (Fig. 4): frequency-energy backbones, log energy axis,
//                        the linear modes and the asymptotes 2 pi c / (3L) (mode 1) and
//                        8 pi c / (5L) (mode 2) as vertical lines, closed forms of both modes
//   backbones_all        backbones_all.png: Fig. 4 widened to modes 1 to 5 (closed forms from
//                        grazing, OUT/modeJ's points), the subharmonic band of mode 2 and the
//                        families attached to mode 1 (OUT/mode1_resonances/branch_point_K) as
//                        vertical segments
//   mode1_contact        mode1_contact.png (Fig. 5): contacting-end displacement and contact
//                        force over one period of a mode-1 orbit (TD-BEM and the exact oracle)
//   spacetime            mode1_spacetime.png, mode2_spacetime.png (Figs. 6, 7) and
//                        mode3_spacetime.png: u(x, t) over one period (TD-BEM); mode 2 marks
//                        its node, where u0 changes sign
//                        and, with OUT/subharmonic, the subharmonic backbone omega2 / 2 as a
//                        band where its verified dimension is 2
//   subharmonic_continuum  subharmonic_continuum.png (Fig. 8): u(L, t) over T = 2 T2 of the
//                        members of OUT/subharmonic_continuum, coloured by shape, with the two
//                        grazing limits located by NLopt (grazing_limits.hpp) drawn thick
//   subharmonic_spacetime  subharmonic_spacetime.png (Fig. 9): u(x, t) over 2 T2 of the
//                        grazing limit shape 1 (the continuum's first member, TD-BEM)
//   closed_form_summary  closed_form_summary.csv: one row per traced contact-bar branch found
//                        in OUT/*/: points, energy range, worst closed-form frequency error and
//                        exact-oracle return errors, point seconds
//
//   for (const cli::ProblemJob& job : contact_bar::figure_jobs())
//     status = std::max(status, job.run("results"));   // after trace --out results/mode1 ...
//   FigureInputs in; in.energy = 1e-3;                   // draw the orbits nearest 1e-3 J
//   contact_bar::draw_spacetime("results", in);
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "continuation/cli/plugin.hpp"
#include "problems/bar/bar.hpp"

namespace backbone::contact_bar {

struct FigureInputs {
  // The scene the branches were traced with (material, gap; dt and elements of the redrawn
  // orbits), relative to the working directory.
  std::filesystem::path scene = "problems/contact_bar/scenes/paper.ini";
  // Orbits drawn: the traced orbit whose energy is closest (in log) to this [J]; 0: the
  // middle of each branch's energy range.
  double energy = 0;
};

// The jobs above; run(out) reads OUT/mode1 and OUT/mode2 and writes into OUT. backbones
// returns 1 when neither branch exists; the others skip (with a line) what is missing.
std::vector<cli::ProblemJob> figure_jobs(const FigureInputs& inputs = {});

int draw_backbones(const std::filesystem::path& out, const FigureInputs& inputs);
int draw_all_backbones(const std::filesystem::path& out, const FigureInputs& inputs);
int draw_mode1_contact(const std::filesystem::path& out, const FigureInputs& inputs);
int draw_spacetime(const std::filesystem::path& out, const FigureInputs& inputs);
int draw_subharmonic_continuum(const std::filesystem::path& out, const FigureInputs& inputs);
int draw_subharmonic_spacetime(const std::filesystem::path& out, const FigureInputs& inputs);
int write_closed_form_summary(const std::filesystem::path& out);

// One orbit of a traced branch: its period, energy and initial displacement (orbits.csv with
// the fixed end u0(0) = 0 put back).
struct TracedOrbit {
  double period = 0;
  double energy = 0;
  bar::PiecewiseLinear u0;
};
// The orbit of the trace output `branch_dir` whose energy is closest (in log) to
// target_energy (<= 0: the geometric middle of the branch's energy range); knots beyond
// `length` are clipped to it. Empty when branch.csv or orbits.csv is missing or holds no orbit.
std::optional<TracedOrbit> load_traced_orbit(const std::filesystem::path& branch_dir,
                                             double target_energy, double length);
// The same for point `point` of the branch (>= 0), or as above when point < 0.
std::optional<TracedOrbit> load_traced_orbit_point(const std::filesystem::path& branch_dir,
                                                   int point, double target_energy, double length);

// The followed families a trace wrote into dir (--follow): its branch_point_K/ folders that hold
// a branch.csv, sorted; empty when dir does not exist.
std::vector<std::filesystem::path> followed_branches(const std::filesystem::path& dir);

// The value of `key` in a trace's resolved scene.ini ("key = value", a default written as
// "# key = value  (default)"); empty when absent.
std::string scene_value(const std::filesystem::path& scene, const std::string& key);

// Renders plot (gnuplot text) into png at size and says so on stdout, or the renderer's
// message on stderr (a missing gnuplot leaves the CSV files as the result).
void render_figure(const std::filesystem::path& png, const std::string& plot, int width,
                   int height);

}  // namespace backbone::contact_bar
