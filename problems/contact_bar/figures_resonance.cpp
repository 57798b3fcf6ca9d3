#include "problems/contact_bar/figures_resonance.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <string>

#include "core/plot.hpp"
#include "core/table.hpp"

namespace backbone::contact_bar {

namespace fs = std::filesystem;

int draw_attached_branches(const fs::path& out) {
  const fs::path mode1 = out / "mode1";
  if (!fs::exists(mode1 / "branch.csv")) {
    fmt::print("[figures] attached_branches skipped: no {}\n", (mode1 / "branch.csv").string());
    return 0;
  }
  std::vector<fs::path> attached;
  for (const auto& entry : fs::directory_iterator(mode1))
    if (entry.path().filename().string().rfind("branch_point_", 0) == 0 &&
        fs::exists(entry.path() / "branch.csv"))
      attached.push_back(entry.path());
  std::sort(attached.begin(), attached.end());
  if (attached.empty()) {
    fmt::print("[figures] attached_branches skipped: no followed branch in {} (trace --follow)\n",
               mode1.string());
    return 0;
  }
  std::string plot =
      "set title 'Mode 1 and the branches attached at its branch points (internal resonances)'\n"
      "set xlabel 'frequency {/Symbol w} [rad/s]'\nset ylabel 'energy E [J]'\n"
      "set logscale y\nset format y '10^{%L}'\nset grid\nset key outside right\n";
  plot += fmt::format(
      "plot {} using 'frequency':'energy' with linespoints pt 7 ps 0.5 lw 2 lc rgb 'blue' "
      "title 'mode 1'",
      core::gnuplot_quote(mode1 / "branch.csv"));
  if (fs::exists(mode1 / "branch_points.csv"))
    plot += fmt::format(
        ", {} using 'frequency':(column('verified') == 1 ? "
        "column('energy') : NaN) with points pt 6 ps 2 lc rgb 'black' title 'verified branch "
        "points'",
        core::gnuplot_quote(mode1 / "branch_points.csv"));
  for (const fs::path& dir : attached)
    plot += fmt::format(
        ", {} using 'frequency':'energy' with linespoints pt 5 ps 0.5 title "
        "'attached at branch point {}'",
        core::gnuplot_quote(dir / "branch.csv"),
        dir.filename().string().substr(13));  // "branch_point_K" -> K
  const fs::path png = out / "attached_branches.png";
  const core::PlotResult r = core::render_png(png, plot + "\n", {1200, 700});
  if (r.ok)
    fmt::print("[figures] wrote {}\n", png.string());
  else
    fmt::print(stderr, "[figures] {}\n", r.message);
  return 0;
}

std::vector<continuation::ProblemJob> resonance_figure_jobs() {
  return {{"attached_branches",
           "attached_branches.png: mode 1 with its followed attached branches (Fig. 4 d)",
           draw_attached_branches}};
}

}  // namespace backbone::contact_bar
