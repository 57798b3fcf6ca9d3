// What the contact-bar benchmark cases (bench_*.cpp) share besides their metrics: timing,
// figure reporting and the table they write and print. Internal to problems/contact_bar.
//
//   const bench::PaperMode1 m = bench::paper_mode1();   // m.episode.period = 3.1
//   const double s = bench::best_seconds([&] { solver.simulate(setup, options); });
//   bench::LabelledTable t({"method", "dt", "error"});
//   t.add_row({"tdbem_event", 1e-3, 2.5e-16});        // text or numbers, in column order
//   t.write_csv(out / "case.csv");                     // atomic, numbers with 17 digits
//   bench::print_table(t);                             // 6 significant digits on stdout
//   bench::report_plot(core::render_png(png, script), png);
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "core/plot.hpp"
#include "problems/bar/bar.hpp"
#include "problems/contact_bar/bench_metrics.hpp"

namespace backbone::contact_bar::bench {

// The exact mode 1 of the paper scene (problems/contact_bar/scenes/paper.ini): L = c = EA = 1,
// g0 = 1e-3, u0 = eps x with eps = -0.01, v0 = 0; period 3.1, contact on [1.1, 2) at 0.01 N.
struct PaperMode1 {
  bar::BarSetup setup;
  double eps = 0;
  Mode1ContactEpisode episode;
};
PaperMode1 paper_mode1();

// Wall-clock seconds of one run.
double seconds_of(const std::function<void()>& run);
// Best of up to 3 runs; a run longer than `single` seconds is not repeated.
double best_seconds(const std::function<void()>& run, double single = 0.5);

// "  wrote PNG" or "  figure skipped: why" on stdout.
void report_plot(const core::PlotResult& result, const std::filesystem::path& png);

// TEMPORARY, until core::Table has text columns (branch h2-ode-table): a table whose cells
// are text or numbers, written like core::Table (header, numbers with 17 significant digits,
// atomic). Switching is mechanical: LabelledTable -> core::Table, Cell -> its cell type.
class LabelledTable {
 public:
  // A number (any arithmetic type, stored as double) or a text.
  struct Cell {
    template <typename Number, typename = std::enable_if_t<std::is_arithmetic_v<Number>>>
    Cell(Number number) : value(static_cast<double>(number)) {}
    Cell(std::string text) : value(std::move(text)) {}
    Cell(const char* text) : value(std::string(text)) {}
    std::variant<double, std::string> value;
  };
  explicit LabelledTable(std::vector<std::string> columns) : columns_(std::move(columns)) {}
  // One cell per column (std::logic_error otherwise).
  void add_row(std::vector<Cell> row);
  const std::vector<std::string>& columns() const { return columns_; }
  std::size_t rows() const { return rows_.size(); }
  const std::vector<Cell>& row(std::size_t i) const { return rows_[i]; }
  void write_csv(const std::filesystem::path& path) const;

 private:
  std::vector<std::string> columns_;
  std::vector<std::vector<Cell>> rows_;
};

// Right-aligned columns, numbers with 6 significant digits, two spaces of indent.
void print_table(const LabelledTable& table);

}  // namespace backbone::contact_bar::bench
