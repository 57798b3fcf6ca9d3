#include "core/io/table.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "core/errors.hpp"

namespace backbone::core {

namespace {

std::string number_text(double value, int significant_digits = 17) {
  return fmt::format("{:.{}g}", value, significant_digits);
}

// True when the whole of s is one double for strtod (nan and inf included). overflow: the number
// is finite in the text but out of a double's range. strtod, not stod: stod throws on subnormals
// (ERANGE on underflow) although write_csv writes them, and it accepts trailing garbage ("1x").
bool parses_as_number(const std::string& s, double& value, bool& overflow) {
  if (s.empty()) return false;
  char* end = nullptr;
  errno = 0;
  value = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size()) return false;
  overflow = errno == ERANGE && std::isinf(value);
  return true;
}

bool has_csv_special(const std::string& s) {
  return s.empty() || s.find_first_of(",\"\n\r") != std::string::npos;
}

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + '"';
}

// A text cell as write_csv spells it: quoted when read_csv would otherwise not give it back.
std::string text_cell(const std::string& s) {
  double value = 0;
  bool overflow = false;
  return has_csv_special(s) || parses_as_number(s, value, overflow) ? quoted(s) : s;
}

std::string cell_text(const Table::Cell& cell, int significant_digits) {
  if (const double* value = std::get_if<double>(&cell))
    return number_text(*value, significant_digits);
  return std::get<std::string>(cell);
}

// One CSV field as read: its text and whether it was quoted.
struct Field {
  std::string text;
  bool quoted = false;
};
struct Record {
  std::vector<Field> fields;
  std::size_t line = 0;  // line where the record starts, for messages
};

// RFC 4180 records: fields separated by commas, quoted fields may hold commas, doubled quotes
// and line breaks; CRLF line ends are accepted; empty lines are skipped.
std::vector<Record> parse_records(const std::string& text, const std::string& source) {
  std::vector<Record> records;
  Record record;
  Field field;
  std::size_t line = 1;
  record.line = line;
  bool in_quotes = false, after_closing_quote = false, empty_record = true;
  const auto error = [&](const std::string& what) {
    return InputError("csv", fmt::format("{}:{}: {}", source, line, what));
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_quotes) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
        field.text += '"';
        ++i;
      } else if (c == '"') {
        in_quotes = false;
        after_closing_quote = true;
      } else {
        if (c == '\n') ++line;
        field.text += c;
      }
      continue;
    }
    if (c == '\r' && (i + 1 == text.size() || text[i + 1] == '\n')) continue;
    if (c == ',' || c == '\n') {
      const bool end_of_record = c == '\n';
      if (!(end_of_record && empty_record && field.text.empty() && !field.quoted))
        record.fields.push_back(std::move(field));
      field = Field{};
      after_closing_quote = false;
      if (end_of_record) {
        if (!record.fields.empty()) records.push_back(std::move(record));
        record = Record{};
        record.line = ++line;
        empty_record = true;
      } else {
        empty_record = false;
      }
      continue;
    }
    if (after_closing_quote) throw error("text after the closing quote of a cell");
    if (c == '"') {
      if (!field.text.empty())
        throw error(fmt::format("quote inside the unquoted cell '{}'", field.text));
      field.quoted = in_quotes = true;
    } else {
      field.text += c;
    }
    empty_record = false;
  }
  if (in_quotes)
    throw InputError("csv", fmt::format("{}:{}: unterminated quote", source, record.line));
  if (!empty_record) {
    record.fields.push_back(std::move(field));
    records.push_back(std::move(record));
  }
  return records;
}

}  // namespace

Table::Table(std::vector<std::string> columns) : columns_(std::move(columns)) {}

void Table::add_row(const std::vector<double>& row) {
  add_cells(std::vector<Cell>(row.begin(), row.end()));
}

void Table::add_row(const std::string& label, const std::vector<double>& values) {
  std::vector<Cell> cells;
  cells.reserve(values.size() + 1);
  cells.emplace_back(label);
  cells.insert(cells.end(), values.begin(), values.end());
  add_cells(std::move(cells));
}

void Table::add_cells(std::vector<Cell> cells) {
  if (cells.size() != columns_.size())
    throw std::logic_error(
        fmt::format("Table::add_cells: {} cells for {} columns", cells.size(), columns_.size()));
  rows_.push_back(std::move(cells));
}

std::size_t Table::column_index(const std::string& name) const {
  const auto it = std::find(columns_.begin(), columns_.end(), name);
  if (it == columns_.end()) throw InputError(name, "no such column in the table");
  return static_cast<std::size_t>(it - columns_.begin());
}

std::vector<double> Table::column(const std::string& name) const {
  const std::size_t j = column_index(name);
  std::vector<double> out;
  out.reserve(rows_.size());
  for (std::size_t i = 0; i < rows_.size(); ++i) {
    const double* value = std::get_if<double>(&rows_[i][j]);
    if (!value)
      throw InputError(name, fmt::format("holds text ('{}' in row {}), not numbers",
                                         std::get<std::string>(rows_[i][j]), i));
    out.push_back(*value);
  }
  return out;
}

std::vector<std::string> Table::text_column(const std::string& name) const {
  const std::size_t j = column_index(name);
  std::vector<std::string> out;
  out.reserve(rows_.size());
  for (const auto& r : rows_) out.push_back(cell_text(r[j], 17));
  return out;
}

std::vector<double> Table::row(std::size_t i) const {
  std::vector<double> out;
  out.reserve(columns_.size());
  for (std::size_t j = 0; j < columns_.size(); ++j) {
    const double* value = std::get_if<double>(&rows_.at(i)[j]);
    if (!value)
      throw InputError(columns_[j], fmt::format("holds text ('{}' in row {}), not a number",
                                                std::get<std::string>(rows_[i][j]), i));
    out.push_back(*value);
  }
  return out;
}

std::string Table::csv() const {
  std::string text;
  for (std::size_t j = 0; j < columns_.size(); ++j) {
    if (j) text += ',';
    text += has_csv_special(columns_[j]) ? quoted(columns_[j]) : columns_[j];
  }
  text += '\n';
  for (const auto& r : rows_) {
    for (std::size_t j = 0; j < r.size(); ++j) {
      if (j) text += ',';
      if (const double* value = std::get_if<double>(&r[j]))
        text += number_text(*value);
      else
        text += text_cell(std::get<std::string>(r[j]));
    }
    text += '\n';
  }
  return text;
}

std::string Table::aligned(int significant_digits) const {
  std::vector<std::vector<std::string>> lines{columns_};
  for (const auto& r : rows_) {
    std::vector<std::string> line;
    line.reserve(r.size());
    for (const Cell& cell : r) line.push_back(cell_text(cell, significant_digits));
    lines.push_back(std::move(line));
  }
  std::vector<std::size_t> width(columns_.size(), 0);
  for (const auto& line : lines)
    for (std::size_t j = 0; j < line.size(); ++j) width[j] = std::max(width[j], line[j].size());
  std::string text;
  for (const auto& line : lines) {
    for (std::size_t j = 0; j < line.size(); ++j)
      text += fmt::format("  {:>{}}", line[j], width[j]);
    text += '\n';
  }
  return text;
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
  write_text_atomically(path, csv());
}

Table Table::read_csv(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("csv", fmt::format("cannot read '{}'", path.string()));
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string source = path.string();
  const std::vector<Record> records = parse_records(text, source);
  if (records.empty()) throw InputError("csv", fmt::format("'{}' is empty", source));
  std::vector<std::string> columns;
  for (const Field& f : records.front().fields) columns.push_back(f.text);
  Table t(columns);
  for (std::size_t k = 1; k < records.size(); ++k) {
    const Record& record = records[k];
    if (record.fields.size() != columns.size())
      throw InputError("csv", fmt::format("{}:{}: {} values for {} columns", source, record.line,
                                          record.fields.size(), columns.size()));
    std::vector<Cell> cells;
    cells.reserve(columns.size());
    for (const Field& f : record.fields) {
      double value = 0;
      bool overflow = false;
      if (f.quoted || !parses_as_number(f.text, value, overflow)) {
        cells.emplace_back(f.text);
        continue;
      }
      if (overflow)
        throw InputError(
            "csv", fmt::format("{}:{}: '{}' overflows a double", source, record.line, f.text));
      cells.emplace_back(value);
    }
    t.add_cells(std::move(cells));
  }
  return t;
}

}  // namespace backbone::core
