// A table of named double columns, written as CSV with a header, atomically.
//
// Every numeric output of backbone (history.csv, branch.csv, orbits.csv, benchmark tables) is
// a Table. write_csv writes to a temporary file beside the target and renames it, so a run
// that fails or is interrupted never leaves a half-written file. Numbers are written with 17
// significant digits (round-trip exact): outputs are reproducible bit for bit.
//
//   Table t({"t", "u_contact"});
//   t.add_row({0.0, 1e-3});
//   t.write_csv("out/history.csv");
//   Table back = Table::read_csv("out/history.csv");  double u = back.column("u_contact")[0];
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace backbone::core {

class Table {
 public:
  Table() = default;
  explicit Table(std::vector<std::string> columns);

  void add_row(const std::vector<double>& row);  // size must equal the number of columns
  std::size_t rows() const { return data_.size(); }
  const std::vector<std::string>& columns() const { return columns_; }
  std::vector<double> column(const std::string& name) const;  // throws InputError if absent
  const std::vector<double>& row(std::size_t i) const { return data_[i]; }

  // Atomic: writes path + ".part" then renames. Creates parent directories.
  void write_csv(const std::filesystem::path& path) const;
  static Table read_csv(const std::filesystem::path& path);  // throws InputError

 private:
  std::vector<std::string> columns_;
  std::vector<std::vector<double>> data_;
};

// Writes text to a file atomically (same rule as Table::write_csv).
void write_text_atomically(const std::filesystem::path& path, const std::string& text);

}  // namespace backbone::core
