// DIR/branch.png of a traced branch: frequency against energy (log axis) when branch.csv has
// both columns, else its first two observables. Moved out of drivers/trace.cpp so that the
// drivers stay thin; needs gnuplot (a missing gnuplot skips the figure with a message).
//
//   const core::Table table = core::Table::read_csv(out / "branch.csv");
//   continuation::write_branch_figure(out, table, "contact_bar / mode1");
#pragma once

#include <filesystem>
#include <string>

#include "core/table.hpp"

namespace backbone::continuation {

void write_branch_figure(const std::filesystem::path& out, const core::Table& table,
                         const std::string& title);

}  // namespace backbone::continuation
