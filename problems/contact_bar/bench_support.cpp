#include "problems/contact_bar/bench_support.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "core/table.hpp"

namespace backbone::contact_bar::bench {

PaperMode1 paper_mode1() {
  PaperMode1 m;
  m.eps = -0.01;
  const double gap = 1e-3;
  m.setup.left = {bar::EndType::fixed, 0};
  m.setup.right = {bar::EndType::contact, gap};
  m.setup.u0 = bar::PiecewiseLinear({0.0, 1.0}, {0.0, m.eps});
  const bar::Material& material = m.setup.material;
  // Potential energy of u0 = eps x at rest: EA L eps^2 / 2.
  const double energy = m.eps * m.eps / 2 * material.axial_stiffness() * material.length;
  m.episode = mode1_contact_episode(material, gap, energy);
  return m;
}

double seconds_of(const std::function<void()>& run) {
  const auto start = std::chrono::steady_clock::now();
  run();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double best_seconds(const std::function<void()>& run, double single) {
  double best = seconds_of(run);
  for (int k = 1; k < 3 && best < single; ++k) best = std::min(best, seconds_of(run));
  return best;
}

void report_plot(const core::PlotResult& result, const std::filesystem::path& png) {
  if (result.ok)
    fmt::print("  wrote {}\n", png.string());
  else
    fmt::print("  figure skipped: {}\n", result.message);
}

namespace {

std::string csv_text(const LabelledTable::Cell& cell) {
  if (const auto* text = std::get_if<std::string>(&cell.value)) return *text;
  return fmt::format("{:.17g}", std::get<double>(cell.value));
}

std::string screen_text(const LabelledTable::Cell& cell) {
  if (const auto* text = std::get_if<std::string>(&cell.value)) return *text;
  return fmt::format("{:.6g}", std::get<double>(cell.value));
}

}  // namespace

void LabelledTable::add_row(std::vector<Cell> row) {
  if (row.size() != columns_.size())
    throw std::logic_error(fmt::format("LabelledTable::add_row: {} cells for {} columns",
                                       row.size(), columns_.size()));
  rows_.push_back(std::move(row));
}

void LabelledTable::write_csv(const std::filesystem::path& path) const {
  std::string text;
  for (std::size_t j = 0; j < columns_.size(); ++j) text += (j ? "," : "") + columns_[j];
  text += '\n';
  for (const auto& r : rows_) {
    for (std::size_t j = 0; j < r.size(); ++j) {
      if (j) text += ',';
      text += csv_text(r[j]);
    }
    text += '\n';
  }
  core::write_text_atomically(path, text);
}

void print_table(const LabelledTable& table) {
  const auto& columns = table.columns();
  std::vector<std::size_t> width(columns.size());
  for (std::size_t c = 0; c < columns.size(); ++c) width[c] = columns[c].size();
  for (std::size_t i = 0; i < table.rows(); ++i)
    for (std::size_t c = 0; c < columns.size(); ++c)
      width[c] = std::max(width[c], screen_text(table.row(i)[c]).size());
  std::string line;
  for (std::size_t c = 0; c < columns.size(); ++c)
    line += fmt::format("{:>{}}  ", columns[c], width[c]);
  fmt::print("  {}\n", line);
  for (std::size_t i = 0; i < table.rows(); ++i) {
    line.clear();
    for (std::size_t c = 0; c < columns.size(); ++c)
      line += fmt::format("{:>{}}  ", screen_text(table.row(i)[c]), width[c]);
    fmt::print("  {}\n", line);
  }
}

}  // namespace backbone::contact_bar::bench
