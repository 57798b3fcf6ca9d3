#include "continuation/branch_figure.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "core/plot.hpp"

namespace backbone::continuation {

void write_branch_figure(const std::filesystem::path& out, const core::Table& table,
                         const std::string& title) {
  const auto& columns = table.columns();
  const auto column_of = [&](const std::string& name) {
    for (std::size_t i = 0; i < columns.size(); ++i)
      if (columns[i] == name) return static_cast<int>(i) + 1;
    return 0;
  };
  int x = column_of("energy"), y = column_of("frequency");
  bool log_x = x > 0 && y > 0;
  if (!log_x) {
    x = 2;
    y = 3;
  }
  if (static_cast<int>(columns.size()) < std::max(x, y)) return;
  const std::string script = fmt::format(
      "set datafile separator ','\nset key top left\nset grid\n{}"
      "set xlabel '{}'\nset ylabel '{}'\nset title '{}' noenhanced\n"
      "plot {} using {}:{} skip 1 with linespoints pt 7 ps 0.6 title 'branch'\n",
      log_x ? "set logscale x\nset format x '10^{%L}'\n" : "", columns[x - 1],
      columns[y - 1] + (columns[y - 1] == "frequency" ? " [rad/time]" : ""), title,
      core::gnuplot_quote(out / "branch.csv"), x, y);
  core::PlotResult r = core::render_png(out / "branch.png", script);
  if (!r.ok) fmt::print(stderr, "figure skipped: {}\n", r.message);
}

}  // namespace backbone::continuation
