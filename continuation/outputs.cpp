#include "continuation/outputs.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

#include "continuation/restart.hpp"
#include "core/errors.hpp"
#include "core/io/plot.hpp"

namespace backbone::continuation {

core::Table orbit_table(const core::PeriodicOrbitProblem& problem, const Branch& branch) {
  core::Table t({"point", "x", "u0"});
  core::Vector coordinates, values;
  for (const auto& p : branch.points) {
    problem.initial_state_samples(p.x, coordinates, values);
    for (Eigen::Index i = 0; i < values.size(); ++i)
      t.add_row({static_cast<double>(p.index), coordinates[i], values[i]});
  }
  return t;
}

std::string stability_counts(const core::Table* table) {
  if (!table || std::find(table->columns().begin(), table->columns().end(), "stable") ==
                    table->columns().end())
    return "stable_points -\nunstable_points -\nundecided_points -\n";
  long counts[3] = {0, 0, 0};  // stable, unstable, undecided
  for (double stable : table->column("stable")) ++counts[stable == 1 ? 0 : (stable == 0 ? 1 : 2)];
  return fmt::format("stable_points {}\nunstable_points {}\nundecided_points {}\n", counts[0],
                     counts[1], counts[2]);
}

std::string stability_datablocks(const core::Table& table, const std::string& x,
                                 const std::string& y, const std::string& prefix) {
  const std::vector<double> xs = table.column(x), ys = table.column(y),
                            kinds = table.column("stable");
  std::string blocks[3];  // undecided (-1), unstable (0), stable (1)
  for (std::size_t i = 0; i + 1 < xs.size() || (xs.size() == 1 && i == 0); ++i) {
    const int kind = std::clamp(static_cast<int>(kinds[i]), -1, 1) + 1;
    const std::size_t next = std::min(i + 1, xs.size() - 1);
    blocks[kind] +=
        fmt::format("{:.17g},{:.17g}\n{:.17g},{:.17g}\n\n", xs[i], ys[i], xs[next], ys[next]);
  }
  std::string text;
  const char* names[3] = {"undecided", "unstable", "stable"};
  for (int k = 0; k < 3; ++k)
    // An empty block would make gnuplot stop the plot: a point of NaN stands for none.
    // The first line is a header: render_png reads every data source's first row as one.
    text += fmt::format("${}{} << EOD\nx,y\n{}EOD\n", prefix, names[k],
                        blocks[k].empty() ? "nan,nan\n" : blocks[k]);
  return text;
}

std::string branch_plot_script(const std::filesystem::path& csv, const core::Table& table,
                               const std::string& title,
                               const std::map<std::string, std::string>& units,
                               const std::pair<std::string, std::string>& axes) {
  const auto& columns = table.columns();
  const auto column_of = [&](const std::string& name) {
    for (std::size_t i = 0; i < columns.size(); ++i)
      if (columns[i] == name) return static_cast<int>(i) + 1;
    return 0;
  };
  int x = column_of(axes.first), y = column_of(axes.second);
  const bool chosen = x > 0 && y > 0;
  if (!chosen) {
    x = column_of("energy");
    y = column_of("frequency");
  }
  const bool log_x = !chosen && x > 0 && y > 0;
  if (!chosen && !log_x) {
    x = 2;
    y = 3;
  }
  if (static_cast<int>(columns.size()) < std::max(x, y)) return {};
  const auto label = [&](int column) {
    const std::string& name = columns[column - 1];
    const auto unit = units.find(name);
    return unit == units.end() ? name : fmt::format("{} [{}]", name, unit->second);
  };
  // The header is read by `set key autotitle columnhead` (core::render_png): no `skip`, which
  // would drop the first point as well.
  const std::string frame = fmt::format(
      "set key top left\nset grid\n{}set xlabel '{}' noenhanced\n"
      "set ylabel '{}' noenhanced\nset title '{}' noenhanced\n",
      log_x ? "set logscale x\nset format x '10^{%L}'\n" : "", label(x), label(y), title);
  const int stable = column_of("stable");
  if (stable == 0)
    return frame + fmt::format("plot {} using {}:{} with linespoints pt 7 ps 0.6 title 'branch'\n",
                               core::gnuplot_quote(csv), x, y);
  return frame + stability_datablocks(table, columns[x - 1], columns[y - 1], "") +
         fmt::format(
             "plot $stable with lines lw 2 lc rgb '#1f77b4' title 'stable', "
             "$unstable with lines lw 2 dt 2 lc rgb '#d62728' title 'unstable', "
             "$undecided with lines lw 1 dt 3 lc rgb 'gray40' title 'undecided', "
             "{} using {}:{} with points pt 7 ps 0.5 lc rgb 'black' title 'points'\n",
             core::gnuplot_quote(csv), x, y);
}

void plot_branch(const std::filesystem::path& out, const core::Table& table,
                 const std::string& title, const std::map<std::string, std::string>& units,
                 const std::pair<std::string, std::string>& axes) {
  const std::string script = branch_plot_script(out / "branch.csv", table, title, units, axes);
  if (script.empty()) return;
  core::PlotResult r = core::render_png(out / "branch.png", script);
  if (!r.ok) fmt::print(stderr, "figure skipped: {}\n", r.message);
}

struct BranchWriter::File {
  std::filesystem::path path;
  std::FILE* handle = nullptr;
  File(std::filesystem::path p, bool append) : path(std::move(p)) {
    handle = std::fopen(path.c_str(), append ? "a" : "w");
    if (!handle)
      throw std::runtime_error(
          fmt::format("cannot write '{}': {}", path.string(), std::strerror(errno)));
  }
  ~File() {
    if (handle) std::fclose(handle);
  }
  // One fwrite per call, then flushed to the kernel: a killed process loses nothing written.
  void write(const std::string& text) {
    if (std::fwrite(text.data(), 1, text.size(), handle) != text.size() || std::fflush(handle) != 0)
      throw std::runtime_error(fmt::format("cannot write '{}'", path.string()));
  }
};

namespace {

std::string csv_rows(const core::Table& table, bool header) {
  std::string text;
  if (header) {
    for (std::size_t j = 0; j < table.columns().size(); ++j)
      text += (j ? "," : "") + table.columns()[j];
    text += '\n';
  }
  for (std::size_t i = 0; i < table.rows(); ++i) {
    const auto& row = table.row(i);
    for (std::size_t j = 0; j < row.size(); ++j)
      text += fmt::format("{}{:.17g}", j ? "," : "", row[j]);
    text += '\n';
  }
  return text;
}

}  // namespace

BranchWriter::BranchWriter(std::filesystem::path out, const core::PeriodicOrbitProblem* periodic,
                           bool append)
    : out_(std::move(out)), periodic_(periodic), points_(append ? 1 : 0) {
  std::filesystem::create_directories(out_);
  branch_ = std::make_unique<File>(out_ / "branch.csv", append);
  unknowns_ = std::make_unique<File>(out_ / "unknowns.csv", append);
  if (periodic_) orbits_ = std::make_unique<File>(out_ / "orbits.csv", append);
  const bool state_exists = std::filesystem::exists(out_ / "state.txt");
  state_ = std::make_unique<File>(out_ / "state.txt", append);
  if (!append || !state_exists)
    state_->write("point state (continuation/README.md, section 'Restart files')\n");
}

BranchWriter::~BranchWriter() = default;

void BranchWriter::append(const BranchPoint& point) {
  Branch one;
  one.points.push_back(point);
  const bool first = points_ == 0;
  branch_->write(csv_rows(branch_table(one), first));
  core::Table unknowns({"point", "index", "value"});
  for (Eigen::Index i = 0; i < point.x.size(); ++i)
    unknowns.add_row({static_cast<double>(point.index), static_cast<double>(i), point.x[i]});
  unknowns_->write(csv_rows(unknowns, first));
  if (periodic_) orbits_->write(csv_rows(orbit_table(*periodic_, one), first));
  if (point.floquet) {
    // Opened with the first point that has multipliers (every point of a branch has, or none).
    if (!multipliers_) {
      const bool exists = std::filesystem::exists(out_ / "multipliers.csv");
      const bool appending = points_ > 0 && exists;
      multipliers_ = std::make_unique<File>(out_ / "multipliers.csv", appending);
      multipliers_->write(csv_rows(multiplier_table(one), !appending));
    } else {
      multipliers_->write(csv_rows(multiplier_table(one), false));
    }
  }
  state_->write(
      fmt::format("{} {}\n", point.index, point.state ? format_state(*point.state) : "-"));
  ++points_;
}

namespace {

// The header and the complete lines of a CSV file (a last line without its newline is cut).
std::vector<std::string> complete_lines(const std::filesystem::path& path, const std::string& key) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw core::InputError(key, fmt::format("cannot read '{}'", path.string()));
  std::stringstream text;
  text << in.rdbuf();
  std::vector<std::string> lines;
  std::string all = text.str(), line;
  std::size_t start = 0;
  for (std::size_t end = all.find('\n'); end != std::string::npos; end = all.find('\n', start)) {
    lines.push_back(all.substr(start, end - start));
    start = end + 1;
  }
  if (lines.empty()) throw core::InputError(key, fmt::format("'{}' has no header", path.string()));
  return lines;
}

double first_cell(const std::string& line) {
  return std::strtod(line.c_str(), nullptr);
}

}  // namespace

void check_saved_files(const std::filesystem::path& dir, const std::string& key) {
  const auto fail = [&](const std::filesystem::path& file, std::size_t line,
                        const std::string& what) {
    throw core::InputError(key, fmt::format("'{}' line {}: {}; not a file of a traced branch",
                                            file.string(), line + 1, what));
  };
  const auto number = [](const std::string& cell) {
    if (cell.empty()) return false;
    char* end = nullptr;
    std::strtod(cell.c_str(), &end);
    return end == cell.c_str() + cell.size();
  };
  for (const char* name : {"branch.csv", "unknowns.csv", "orbits.csv", "multipliers.csv"}) {
    const std::filesystem::path file = dir / name;
    if (!std::filesystem::exists(file)) continue;
    const std::vector<std::string> lines = complete_lines(file, key);
    const std::string& header = lines.front();
    if (header.rfind("point,", 0) != 0) fail(file, 0, "the header does not start with 'point,'");
    const auto cells_in = [](const std::string& line) {
      return static_cast<std::size_t>(std::count(line.begin(), line.end(), ',')) + 1;
    };
    const std::size_t columns = cells_in(header);
    for (std::size_t i = 1; i < lines.size(); ++i) {
      if (cells_in(lines[i]) != columns)
        fail(file, i, fmt::format("{} cells for {} columns", cells_in(lines[i]), columns));
      std::stringstream row(lines[i]);
      for (std::string cell; std::getline(row, cell, ',');)
        if (!number(cell)) fail(file, i, fmt::format("'{}' is not a number", cell));
    }
  }
  const std::filesystem::path states = dir / "state.txt";
  if (!std::filesystem::exists(states)) return;
  const std::vector<std::string> lines = complete_lines(states, key);
  if (lines.front().rfind("point state", 0) != 0)
    fail(states, 0, "the header is not 'point state'");
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const auto space = lines[i].find(' ');
    if (space == std::string::npos || !number(lines[i].substr(0, space)) ||
        space + 1 >= lines[i].size())
      fail(states, i, "not 'POINT STATE' or 'POINT -'");
  }
}

int repair_branch_files(const std::filesystem::path& out, const std::string& key, int up_to) {
  std::vector<std::filesystem::path> files{out / "branch.csv", out / "unknowns.csv"};
  for (const char* optional : {"orbits.csv", "multipliers.csv", "state.txt"})
    if (std::filesystem::exists(out / optional)) files.push_back(out / optional);
  std::vector<std::vector<std::string>> contents;
  // The writer writes a point to branch.csv, unknowns.csv, orbits.csv, multipliers.csv, then
  // state.txt: the last
  // complete point is the smallest last point over the files, one less when a file holding
  // several rows per point has only part of that point's rows.
  double last = std::numeric_limits<double>::infinity();
  for (const auto& f : files) {
    contents.push_back(complete_lines(f, key));
    const auto& lines = contents.back();
    last = std::min(last, lines.size() > 1 ? first_cell(lines.back()) : -1.0);
  }
  const auto rows_of = [](const std::vector<std::string>& lines, double point) {
    return std::count_if(lines.begin() + 1, lines.end(),
                         [&](const std::string& l) { return first_cell(l) == point; });
  };
  // Every point has as many rows in a file as the first one (same unknowns, same samples).
  bool cut = false;
  for (std::size_t i = 1; i < contents.size() && last >= 0; ++i) {
    const auto& lines = contents[i];
    if (lines.size() > 1 && rows_of(lines, last) != rows_of(lines, first_cell(lines[1])))
      cut = true;
  }
  if (cut) last -= 1;
  last = std::min(last, static_cast<double>(up_to));
  if (!(last >= 0))
    throw core::InputError(key, fmt::format("'{}' holds no complete point", out.string()));
  for (std::size_t i = 0; i < files.size(); ++i) {
    std::string text = contents[i][0] + "\n";
    for (std::size_t j = 1; j < contents[i].size(); ++j)
      if (first_cell(contents[i][j]) <= last) text += contents[i][j] + "\n";
    core::write_text_atomically(files[i], text);
  }
  return static_cast<int>(last);
}

namespace {

// The named number columns of a CSV file; any defect is an InputError naming `key`.
std::vector<std::vector<double>> read_columns(const std::filesystem::path& path,
                                              std::initializer_list<const char*> names,
                                              const std::string& key) {
  try {
    const core::Table table = core::Table::read_csv(path);
    std::vector<std::vector<double>> columns;
    for (const char* name : names) columns.push_back(table.column(name));
    return columns;
  } catch (const core::InputError& e) {
    throw core::InputError(key, e.what());
  }
}

}  // namespace

core::Vector read_unknowns(const std::filesystem::path& path, int point, const std::string& key) {
  const auto columns = read_columns(path, {"point", "index", "value"}, key);
  const std::vector<double>&points = columns[0], &index = columns[1], &value = columns[2];
  if (points.empty())
    throw core::InputError(key, fmt::format("'{}' holds no point", path.string()));
  const double wanted = point < 0 ? points.back() : point;
  if (!(wanted >= 0 && wanted < 1e9 && wanted == std::floor(wanted)))
    throw core::InputError(key, fmt::format("'{}': point {} is not a whole number in [0, 1e9)",
                                            path.string(), wanted));
  std::map<int, double> entries;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (points[i] != wanted) continue;
    // An index must be a whole number below a million (the size of any problem here); a
    // cast of anything else would be undefined.
    if (!(index[i] >= 0 && index[i] < 1e6 && index[i] == std::floor(index[i])))
      throw core::InputError(key, fmt::format("'{}': index {} of point {} is not a whole number "
                                              "in [0, 1e6)",
                                              path.string(), index[i], wanted));
    entries[static_cast<int>(index[i])] = value[i];
  }
  if (entries.empty())
    throw core::InputError(key, fmt::format("'{}' has no point {}", path.string(), point));
  core::Vector x(static_cast<Eigen::Index>(entries.size()));
  int expected = 0;
  for (const auto& [i, v] : entries) {
    if (i != expected++)
      throw core::InputError(key, fmt::format("'{}': point {} misses unknown {}", path.string(),
                                              static_cast<int>(wanted), expected - 1));
    x[i] = v;
  }
  return x;
}

Branch whole_branch(const std::filesystem::path& dir, const core::Problem& problem,
                    const Branch& resumed, const core::FloquetOptions* floquet) {
  Branch whole;
  const int first =
      resumed.points.empty() ? std::numeric_limits<int>::max() : resumed.points.front().index;
  if (first > 0) {
    const auto columns = read_columns(dir / "unknowns.csv", {"point", "index", "value"}, "resume");
    std::map<int, std::vector<double>> saved;  // point -> values in file order (index order)
    for (std::size_t i = 0; i < columns[0].size(); ++i)
      if (columns[0][i] >= 0 && columns[0][i] <= first)
        saved[static_cast<int>(columns[0][i])].push_back(columns[2][i]);
    for (const auto& [index, values] : saved) {
      BranchPoint p;
      p.index = index;
      p.x = Eigen::Map<const core::Vector>(values.data(), static_cast<Eigen::Index>(values.size()));
      if (p.x.size() != problem.num_unknowns()) continue;
      p.observables = problem.observables(p.x);
      if (floquet) p.floquet = core::floquet_at(problem, p.x, *floquet);
      whole.points.push_back(std::move(p));
    }
  }
  for (const BranchPoint& p : resumed.points)
    if (whole.points.empty() || p.index > whole.points.back().index) whole.points.push_back(p);
  whole.branch_points = resumed.branch_points;
  whole.branch_points_from = resumed.branch_points_from;
  whole.rejected_corrections = resumed.rejected_corrections;
  whole.reason = resumed.reason;
  whole.message = resumed.message;
  return whole;
}

namespace {

// Rows of `saved` whose `column` is below `below`, then those of `fresh`, in the layout of the
// one whose columns include the other's (cells of a missing column NaN): a table whose rows are
// all unverified candidates lacks the description columns (frequency_ratio, ...), and it may be
// either. `fresh` alone when neither layout includes the other.
core::Table merge_saved_rows(const core::Table& saved, const core::Table& fresh,
                             const std::string& column, double below) {
  const auto includes = [](const core::Table& a, const core::Table& b) {
    for (const std::string& c : b.columns())
      if (std::find(a.columns().begin(), a.columns().end(), c) == a.columns().end()) return false;
    return true;
  };
  const core::Table* layout = includes(saved, fresh)   ? &saved
                              : includes(fresh, saved) ? &fresh
                                                       : nullptr;
  if (!layout) return fresh;
  core::Table merged(layout->columns());
  const auto add = [&](const core::Table& from, std::size_t i) {
    std::vector<core::Table::Cell> cells;
    for (const std::string& c : layout->columns()) {
      const auto at = std::find(from.columns().begin(), from.columns().end(), c);
      cells.push_back(at == from.columns().end()
                          ? core::Table::Cell(std::numeric_limits<double>::quiet_NaN())
                          : from.cells(i)[static_cast<std::size_t>(at - from.columns().begin())]);
    }
    merged.add_cells(std::move(cells));
  };
  const std::vector<double> key = saved.column(column);
  for (std::size_t i = 0; i < saved.rows(); ++i)
    if (key[i] < below) add(saved, i);
  for (std::size_t i = 0; i < fresh.rows(); ++i) add(fresh, i);
  return merged;
}

}  // namespace

void write_after_run(
    const std::filesystem::path& out, const core::Problem& problem, const Branch& branch,
    bool resumed, bool detect,
    const std::function<void(const std::filesystem::path&, const Branch&)>& extra) {
  if (extra) extra(out, resumed ? whole_branch(out, problem, branch, nullptr) : branch);
  if (!detect) return;
  core::Table rows = branch_point_table(branch, branch.points.front().observables);
  const std::filesystem::path saved = out / "branch_points.csv";
  if (resumed && std::filesystem::exists(saved))
    rows = merge_saved_rows(
        core::Table::read_csv(saved), rows, "after_point",
        branch.branch_points_from >= 0 ? branch.branch_points_from : branch.points.front().index);
  rows.write_csv(saved);
}

void forget_saved_states(const std::filesystem::path& out) {
  const std::filesystem::path path = out / "state.txt";
  std::ifstream in(path);
  if (!in) return;
  std::string text, line;
  for (bool header = true; std::getline(in, line); header = false) {
    if (header) {
      text += line + "\n";
      continue;
    }
    const auto space = line.find(' ');
    text += (space == std::string::npos ? line : line.substr(0, space)) + " -\n";
  }
  core::write_text_atomically(path, text);
}

}  // namespace backbone::continuation
