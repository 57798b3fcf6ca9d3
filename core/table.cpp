#include "core/table.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "core/errors.hpp"

namespace backbone::core {

Table::Table(std::vector<std::string> columns) : columns_(std::move(columns)) {}

void Table::add_row(const std::vector<double>& row) {
  if (row.size() != columns_.size())
    throw std::logic_error(fmt::format("Table::add_row: {} values for {} columns", row.size(),
                                       columns_.size()));
  data_.push_back(row);
}

std::vector<double> Table::column(const std::string& name) const {
  for (std::size_t j = 0; j < columns_.size(); ++j) {
    if (columns_[j] != name) continue;
    std::vector<double> out;
    out.reserve(data_.size());
    for (const auto& r : data_) out.push_back(r[j]);
    return out;
  }
  throw InputError(name, "no such column in the table");
}

void write_text_atomically(const std::filesystem::path& path, const std::string& text) {
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::filesystem::path part = path;
  part += ".part";
  {
    std::ofstream out(part, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error(fmt::format("cannot write '{}'", part.string()));
    out << text;
    if (!out) throw std::runtime_error(fmt::format("error while writing '{}'", part.string()));
  }
  std::filesystem::rename(part, path);
}

void Table::write_csv(const std::filesystem::path& path) const {
  std::string text;
  for (std::size_t j = 0; j < columns_.size(); ++j) text += (j ? "," : "") + columns_[j];
  text += '\n';
  for (const auto& r : data_) {
    for (std::size_t j = 0; j < r.size(); ++j) {
      if (j) text += ',';
      text += fmt::format("{:.17g}", r[j]);
    }
    text += '\n';
  }
  write_text_atomically(path, text);
}

Table Table::read_csv(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError("csv", fmt::format("cannot read '{}'", path.string()));
  std::string line;
  if (!std::getline(in, line)) throw InputError("csv", fmt::format("'{}' is empty", path.string()));
  std::vector<std::string> columns;
  {
    std::stringstream ss(line);
    std::string name;
    while (std::getline(ss, name, ',')) columns.push_back(name);
  }
  Table t(columns);
  std::size_t line_number = 1;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.empty()) continue;
    std::vector<double> row;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) {
      // strtod, not stod: stod throws on subnormals (ERANGE on underflow) although they are
      // written by write_csv, and it accepts trailing garbage ("1x").
      if (!cell.empty() && cell.back() == '\r') cell.pop_back();
      char* end = nullptr;
      errno = 0;
      const double value = std::strtod(cell.c_str(), &end);
      const bool overflow = errno == ERANGE && std::isinf(value);
      if (cell.empty() || end != cell.c_str() + cell.size() || overflow)
        throw InputError("csv", fmt::format("{}:{}: '{}' is not a number", path.string(),
                                            line_number, cell));
      row.push_back(value);
    }
    if (row.size() != columns.size())
      throw InputError("csv", fmt::format("{}:{}: {} values for {} columns", path.string(),
                                          line_number, row.size(), columns.size()));
    t.add_row(row);
  }
  return t;
}

}  // namespace backbone::core
