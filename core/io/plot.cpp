#include "core/io/plot.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <cstdlib>

#include "core/io/table.hpp"

namespace backbone::core {

std::string gnuplot_quote(const std::filesystem::path& p) {
  std::string out = "'";
  for (char ch : p.string()) {
    if (ch == '\'')
      out += "''";
    else
      out += ch;
  }
  return out + "'";
}

PlotResult render_png(const std::filesystem::path& png, const std::string& gnuplot_commands,
                      PlotSize size) {
  std::filesystem::path part = png;
  part += ".part.png";
  std::filesystem::path script = png;
  script += ".gp";
  if (png.has_parent_path()) std::filesystem::create_directories(png.parent_path());
  const std::string text = fmt::format(
      "set terminal pngcairo size {},{} enhanced font 'DejaVu Sans,11'\n"
      "set output {}\nset datafile separator ','\nset key autotitle columnhead\n"
      "{}\nunset output\n",
      size.width, size.height, gnuplot_quote(part), gnuplot_commands);
  write_text_atomically(script, text);
  const std::string command =
      fmt::format("gnuplot {} 2>{}.log", gnuplot_quote(script), gnuplot_quote(png.string()));
  const int rc = std::system(command.c_str());
  std::filesystem::path log = png;
  log += ".log";
  std::error_code ec;
  if (rc != 0 || !std::filesystem::exists(part)) {
    // Nothing is left behind: the message carries gnuplot's error line.
    std::string complaint;
    if (std::FILE* f = std::fopen(log.c_str(), "r")) {
      char line[512];
      while (std::fgets(line, sizeof line, f))
        if (std::string(line).find_first_not_of(" \t\n^") != std::string::npos) complaint = line;
      std::fclose(f);
    }
    while (!complaint.empty() && (complaint.back() == '\n' || complaint.back() == ' '))
      complaint.pop_back();
    for (const auto& p : {part, script, log}) std::filesystem::remove(p, ec);
    return {false, fmt::format("gnuplot failed (exit {}) for {}{}", rc, png.string(),
                               complaint.empty() ? "" : ": " + complaint)};
  }
  std::filesystem::rename(part, png);
  std::filesystem::remove(script, ec);
  std::filesystem::remove(log, ec);
  return {true, ""};
}

}  // namespace backbone::core
