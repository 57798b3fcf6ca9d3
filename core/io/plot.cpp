#include "core/io/plot.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>

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

namespace {

// gnuplot SCRIPT with its stderr into LOG; its exit status (-1: it could not be started, 128 +
// the signal that ended it). Spawned directly, in a process group of its own, rather than by
// std::system, which ignores SIGINT in the caller while the child runs: a Ctrl-C during a figure
// reaches the run's own handlers (continuation/cli/stop_signals.hpp), which stop the run after
// it, and not gnuplot, whose own SIGINT handler was seen to hang it (a figure takes a fraction
// of a second).
int run_gnuplot(const std::filesystem::path& script, const std::filesystem::path& log) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, log.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attributes, 0);
  const std::string program = "gnuplot", path = script.string();
  char* argv[] = {const_cast<char*>(program.c_str()), const_cast<char*>(path.c_str()), nullptr};
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, "gnuplot", &actions, &attributes, argv, environ);
  posix_spawnattr_destroy(&attributes);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) return -1;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return -1;
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

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
  std::filesystem::path log = png;
  log += ".log";
  const int rc = run_gnuplot(script, log);
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
    return {false, rc < 0 ? fmt::format("gnuplot could not be run for {}", png.string())
                          : fmt::format("gnuplot failed (exit {}) for {}{}", rc, png.string(),
                                        complaint.empty() ? "" : ": " + complaint)};
  }
  std::filesystem::rename(part, png);
  std::filesystem::remove(script, ec);
  std::filesystem::remove(log, ec);
  return {true, ""};
}

}  // namespace backbone::core
