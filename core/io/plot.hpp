// PNG figures through gnuplot (pngcairo), written atomically.
//
// The caller writes the gnuplot commands that draw the figure (data usually comes from CSV
// files it has just written); render_png sets the terminal and output, runs gnuplot, and
// renames the PNG into place only when gnuplot succeeded. A missing gnuplot is reported as a
// value, not an exception: figures are a by-product, the CSV data is the result.
//
//   PlotResult r = render_png("results/mode1.png",
//       "set xlabel 'E [J]'\nplot 'results/branch.csv' using 4:3 with lines title 'mode 1'",
//       {1000, 700});
//   if (!r.ok) fmt::print(stderr, "figure skipped: {}\n", r.message);
#pragma once

#include <filesystem>
#include <string>

namespace backbone::core {

struct PlotSize {
  int width = 1000;
  int height = 700;
};

struct PlotResult {
  bool ok = false;
  std::string message;
};

PlotResult render_png(const std::filesystem::path& png, const std::string& gnuplot_commands,
                      PlotSize size = {});

// Quotes a path for use inside a gnuplot script ('...' with quotes escaped).
std::string gnuplot_quote(const std::filesystem::path& p);

}  // namespace backbone::core
