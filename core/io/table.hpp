// A table of named columns whose cells are numbers or texts, written as CSV with a header,
// atomically.
//
// Every tabular output of backbone (history.csv, branch.csv, orbits.csv, benchmark tables) is
// a Table. write_csv writes to a temporary file beside the target and renames it, so a run
// that fails or is interrupted never leaves a half-written file. Numbers are written with 17
// significant digits (round-trip exact): outputs are reproducible bit for bit. Text cells are
// written as they are, or quoted RFC 4180 style ("a ""b""") when they hold a comma, a quote, a
// line break, nothing at all, or would read back as a number ("1e-3"); read_csv turns quoted
// cells into texts and unquoted cells into numbers when they parse fully as doubles (nan and inf
// included), into texts otherwise. So write_csv then read_csv gives back the same cells, and a
// numeric table's CSV is plain numbers, as before texts existed.
//
//   Table t({"method", "dt", "error"});
//   t.add_row("tdbem", {1e-3, 2.5e-7});                  // a text label, then numbers
//   t.add_cells({std::string("fem"), 1e-3, 4.1e-5});     // any mix of cells
//   t.write_csv("out/errors.csv");
//   Table back = Table::read_csv("out/errors.csv");
//   std::vector<double> e = back.column("error");        // numbers
//   std::vector<std::string> m = back.text_column("method");
//   fmt::print("{}", back.aligned());                    // screen rendering, 6 digits
#pragma once

#include <filesystem>
#include <string>
#include <variant>
#include <vector>

namespace backbone::core {

class Table {
 public:
  using Cell = std::variant<double, std::string>;

  Table() = default;
  explicit Table(std::vector<std::string> columns);

  // Each row's size must equal the number of columns (std::logic_error otherwise: a bug).
  void add_row(const std::vector<double>& row);
  void add_row(const std::string& label, const std::vector<double>& values);  // label first
  void add_cells(std::vector<Cell> cells);

  std::size_t rows() const { return rows_.size(); }
  const std::vector<std::string>& columns() const { return columns_; }
  // Numbers of a column. InputError if the column is absent or one of its cells is a text.
  std::vector<double> column(const std::string& name) const;
  // Cells of a column as texts: text cells as they are, numbers as write_csv spells them.
  // InputError if the column is absent.
  std::vector<std::string> text_column(const std::string& name) const;
  // Row i as numbers; InputError if one of its cells is a text.
  std::vector<double> row(std::size_t i) const;
  const std::vector<Cell>& cells(std::size_t i) const { return rows_[i]; }

  // The CSV text write_csv writes (header line, then one line per row).
  std::string csv() const;
  // Right-aligned columns for a screen: numbers with significant_digits digits, two spaces
  // before each line and between columns, one line per row after the header.
  std::string aligned(int significant_digits = 6) const;

  // Atomic: writes path + ".part" then renames. Creates parent directories.
  void write_csv(const std::filesystem::path& path) const;
  // InputError ("csv") when the file is unreadable or empty, a row has the wrong number of
  // cells, a quote is unterminated or a number overflows a double.
  static Table read_csv(const std::filesystem::path& path);

 private:
  std::size_t column_index(const std::string& name) const;  // InputError if absent

  std::vector<std::string> columns_;
  std::vector<std::vector<Cell>> rows_;
};

// Writes text to a file atomically (same rule as Table::write_csv).
void write_text_atomically(const std::filesystem::path& path, const std::string& text);

}  // namespace backbone::core
