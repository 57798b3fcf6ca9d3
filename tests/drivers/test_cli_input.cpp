// `backbone trace` and `backbone inspect` on input that names something the run cannot honour:
// each is refused before any work (exit 2, one line naming the key, nothing written), or, when
// it can only be known after the run, fails the run (exit 1) instead of passing in silence.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <climits>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <memory>
#include <sstream>

#include "core/io/output_folder.hpp"
#include "core/io/table.hpp"
#include "tests/drivers/cli_run.hpp"

namespace {

namespace fs = std::filesystem;

const std::string scene =
    std::string(BACKBONE_SOURCE_DIR) + "/problems/contact_bar/scenes/paper.ini";
// A short mode-1 branch: 20 intervals, a few points up to E = 2e-5 J (a tenth of a second).
const std::string small = scene + " --branch mode1 --shooting_elements 20 --energy_max 2e-5";

// Runs the binary and returns its standard output (exit code in `code`).
std::string stdout_of(const std::string& arguments, int& code) {
  const std::string command =
      std::string(BACKBONE_BINARY_DIR) + "/bin/backbone " + arguments + " 2> /dev/null";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  std::string text;
  std::array<char, 4096> buffer{};
  while (pipe && fgets(buffer.data(), buffer.size(), pipe.get())) text += buffer.data();
  const int status = pclose(pipe.release());
  code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return text;
}

// Writes `bytes` as a scene file in the test's scratch folder.
fs::path scene_file(const std::string& name, const std::string& bytes) {
  const fs::path path = cli::scratch("cli_input", name);
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

TEST(TraceInput, BoundOnAnObservableTheProblemDoesNotHaveIsBadInput) {
  cli::expect_bad_input("trace", small + " --bound nosuch:0:1", "bound", "trace_input");
}

TEST(TraceInput, DirectionWithoutAStartIsBadInput) {
  cli::expect_bad_input("trace", small + " --direction -1", "direction", "trace_input");
}

TEST(TraceInput, ProblemCannotBeChangedOnTheCommandLine) {
  cli::expect_bad_input("trace", small + " --problem duffing", "problem", "trace_input");
}

TEST(TraceInput, StartingFromTheOutputFolderIsRefusedAndKeepsItsPoints) {
  const fs::path out = cli::scratch("trace_input", "branch");
  ASSERT_EQ(cli::run("trace", small, out).code, 0);
  const std::size_t rows = backbone::core::Table::read_csv(out / "branch.csv").rows();
  ASSERT_GT(rows, 4u);
  const cli::Run again = cli::run("trace", small + " --start " + (out / "orbits.csv:3").string(),
                                  out, out.string() + ".again.stderr");
  EXPECT_EQ(again.code, 2) << again.err;
  EXPECT_NE(again.err.find("out"), std::string::npos) << again.err;
  EXPECT_EQ(backbone::core::Table::read_csv(out / "branch.csv").rows(), rows);
}

TEST(TraceInput, SecondWriterIntoAFolderIsRefusedBeforeItWrites) {
  const fs::path out = cli::scratch("trace_input", "locked");
  const backbone::core::FolderLock first("out", out);  // the first writer, in this process
  const cli::Run r = cli::run("trace", small, out);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("another run is writing"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_empty(out));
}

TEST(TraceInput, FollowingARowTheRunDidNotLocateFailsTheRun) {
  // 40 intervals up to 3e-5 J locate two candidates (results/mode1_resonances at the main job's
  // settings): row 99 does not exist.
  const fs::path out = cli::scratch("trace_input", "follow");
  const cli::Run r = cli::run("trace",
                              scene +
                                  " --branch mode1 --shooting_elements 40 --energy_max 3e-5 "
                                  "--detect_branch_points true --follow 99",
                              out);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("--follow 99"), std::string::npos) << r.err;
}

TEST(TraceInput, TheDefaultBranchIsAnnounced) {
  const fs::path out = cli::scratch("trace_input", "default");
  int code = -1;
  const std::string text = stdout_of(
      "trace " + scene + " --shooting_elements 20 --energy_max 2e-5 --out " + out.string(), code);
  EXPECT_EQ(code, 0);
  EXPECT_NE(text.find("branch mode1: the first of contact_bar's branches"), std::string::npos)
      << text;
  const std::string chosen = stdout_of("trace " + small + " --out " + out.string() + "2", code);
  EXPECT_EQ(chosen.find("the first of"), std::string::npos) << chosen;
}

TEST(TraceInput, AStartOutsideItsBoundsIsBadInputNamingTheBoundsKey) {
  // The paper scene's mode 1 starts at 5.5e-7 J: a bound below it would end the branch at once.
  for (const char* energy_max : {"-1", "0", "1e-7"})
    cli::expect_bad_input("trace", scene + " --branch mode1 --energy_max " + energy_max,
                          "energy_max", "trace_input_bounds");
  cli::expect_bad_input("trace", scene + " --branch mode1 --energy_min 1 --energy_max 0.5",
                        "energy_min", "trace_input_bounds");
  cli::expect_bad_input("trace", scene + " --branch mode1 --bound energy:0:1e-9", "bound",
                        "trace_input_bounds");
  // A start far out (end amplitude 1e6 g0, 5e5 J) lies above energy_max at its default 1e-2:
  // the key that bounds it is named though the user did not give it (20 intervals keep a
  // regressed check short).
  cli::expect_bad_input("trace",
                        scene + " --branch mode1 --start_offset 1e6 --shooting_elements 20",
                        "energy_max", "trace_input_bounds");
}

TEST(TraceInput, MessagesNameTheKeyTheUserGave) {
  cli::expect_bad_input("trace", scene + " --branch mode1 --shooting_elements 1",
                        "shooting_elements:", "trace_input_keys");
  cli::expect_bad_input("trace", small + " --left_end contact", "left_end:", "trace_input_keys");
  cli::expect_bad_input("trace", small + " --gap 0", "gap:", "trace_input_keys");
  cli::expect_bad_input("trace", small + " --right_end free", "right_end:", "trace_input_keys");
}

TEST(TraceInput, AStepLongerThanTheBarsTravelTimeIsBadInput) {
  // T = 3.95 L/c at the start: 2 steps give dt = 1.98 L/c > L/c.
  cli::expect_bad_input("trace", small + " --steps_per_period 2", "steps_per_period",
                        "trace_input_dt");
}

TEST(TraceInput, TheWrittenSceneRerunsAsASimulation) {
  // u0 and dt of the paper scene are for L = 1: on a 0.3 m bar they are refused up front, and
  // with keys that fit, the scene.ini the trace writes is a valid simulation scene.
  const std::string short_bar =
      scene +
      " --branch mode1 --shooting_elements 20 --length 0.3 --youngs_modulus 7e4 "
      "--density 2.7 --gap 1e-5";
  cli::expect_bad_input("trace", short_bar, "u0", "trace_input_rerun");
  const fs::path out = cli::scratch("trace_input", "short_bar");
  ASSERT_EQ(cli::run("trace",
                     short_bar + " --u0 '0:0 0.3:-3e-5' --period 0.0055 --dt 1e-5 "
                                 "--energy_max 2e-5",
                     out)
                .code,
            0);
  const cli::Run simulated =
      cli::run("simulate", (out / "scene.ini").string(), cli::scratch("trace_input", "sim"));
  EXPECT_EQ(simulated.code, 0) << simulated.err;
}

TEST(TraceInput, AGridWhoseJacobianDoesNotFitIsRefusedUpFront) {
  // 20000 intervals: a 40000 x 20001 dense Jacobian, 6.4 GB a copy, nine copies.
  cli::expect_bad_input("trace", scene + " --branch mode1 --shooting_elements 20000",
                        "shooting_elements", "trace_input_memory");
  // The bound is the key max_memory when given: 800 intervals need about 0.09 GB.
  cli::expect_bad_input("trace",
                        scene + " --branch mode1 --shooting_elements 800 --max_memory 0.01",
                        "max_memory 0.01", "trace_input_memory");
  cli::expect_bad_input("trace", small + " --max_memory -1", "max_memory", "trace_input_memory");
}

TEST(SimulateInput, AHistoryTooLargeToHoldIsRefusedUpFront) {
  // 50000 probes x 311 rows (3.1 s at dt = 0.01) x 100005 columns: 3e7 values, above a tenth of
  // max_steps (1e8).
  std::string probes = "probes =";
  for (int i = 0; i < 50000; ++i) (probes += ' ') += std::to_string(i / 50000.0);
  std::ifstream paper(scene);
  std::stringstream text;
  text << paper.rdbuf() << "\n" << probes << "\n";
  const fs::path many = scene_file("many_probes.ini", text.str());
  cli::expect_bad_input("simulate", many.string(), "probes", "simulate_input_history");
}

TEST(TraceInput, ResumeWithAnotherRunsStatesKeepsNoneOfThem) {
  // The same five points traced twice, by the arclength and by the natural loop; the folder of
  // the first then holds the second's state.txt, whose states do not fit an arclength resume.
  const fs::path mine = cli::scratch("trace_input", "mine");
  const fs::path other = cli::scratch("trace_input", "other");
  ASSERT_EQ(cli::run("trace", small + " --max_points 5", mine).code, 0);
  ASSERT_EQ(cli::run("trace", small + " --max_points 5 --method natural", other).code, 0);
  fs::copy_file(other / "state.txt", mine / "state.txt", fs::copy_options::overwrite_existing);
  const fs::path err = mine.string() + ".resume.stderr";
  const std::string command = std::string(BACKBONE_BINARY_DIR) + "/bin/backbone trace --resume " +
                              mine.string() + " --max_points 8 > /dev/null 2> " + err.string();
  ASSERT_EQ(std::system(command.c_str()), 0);
  std::ifstream log(err);
  const std::string message((std::istreambuf_iterator<char>(log)), {});
  EXPECT_NE(message.find("do not fit this run"), std::string::npos) << message;
  std::ifstream states(mine / "state.txt");
  std::string line;
  std::getline(states, line);  // header
  int saved = 0, own = 0;
  while (std::getline(states, line)) {
    const bool none = line.substr(line.find(' ') + 1) == "-";
    const int point = std::stoi(line.substr(0, line.find(' ')));
    if (point <= 4) saved += none ? 1 : 0;
    if (point > 4) own += line.find("method=arclength") != std::string::npos ? 1 : 0;
  }
  EXPECT_EQ(saved, 5);  // the five saved points keep no state of the natural run
  EXPECT_EQ(own, 3);    // the resumed points carry this run's arclength states
}

TEST(TraceOutputs, ARerunWritesEveryFileBitForBit) {
  // No output of a trace holds a wall time (they are on the progress lines and in the bench), so
  // the main job rerun leaves results/ as it was outside results/bench.
  const fs::path first = cli::scratch("trace_outputs", "first");
  const fs::path second = cli::scratch("trace_outputs", "second");
  const std::string run = small + " --detect_branch_points true";
  ASSERT_EQ(cli::run("trace", run, first).code, 0);
  ASSERT_EQ(cli::run("trace", run, second).code, 0);
  int files = 0;
  for (const auto& entry : fs::directory_iterator(first)) {
    const auto read = [](const fs::path& p) {
      std::ifstream in(p, std::ios::binary);
      return std::string((std::istreambuf_iterator<char>(in)), {});
    };
    const fs::path other = second / entry.path().filename();
    ASSERT_TRUE(fs::exists(other)) << other;
    EXPECT_EQ(read(entry.path()), read(other)) << entry.path().filename();
    ++files;
  }
  EXPECT_GE(files, 8);  // branch, orbits, unknowns, state, summary, scene, closed form, figure
}

TEST(CommandLineInput, StrayWordsAreRefusedByEveryCommand) {
  // Each of these ran its whole job (every benchmark, the whole main job) with the word ignored.
  for (const std::string command : {"bench extra --case siconos_bar", "figures extra",
                                    "reproduce extra --only mode1_orbit", "version extra"}) {
    const fs::path out = cli::scratch("cli_input", "stray");
    const cli::Run r = cli::run(command, "", out);
    EXPECT_EQ(r.code, 2) << command << "\n" << r.err;
    EXPECT_NE(r.err.find("extra"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out)) << command;
  }
}

TEST(CommandLineInput, AValueThatDoesNotParseIsNamedWithTheRuleItBreaks) {
  cli::expect_bad_input("trace", small + " --length one", "length: 'one' is not a number",
                        "cli_input_rule");
  cli::expect_bad_input("trace", scene + " --branch mode1 --shooting_elements 20.5",
                        "shooting_elements: '20.5' is not a whole number", "cli_input_rule");
  cli::expect_bad_input("bench", "--case siconos_bar --threads 100000",
                        "threads: must be in 1..256 (got 100000)", "cli_input_rule");
}

TEST(CommandLineInput, CombinationsTheMethodCannotDoAreRefused) {
  cli::expect_bad_input("trace", small + " --method natural --follow all", "follow",
                        "cli_input_combinations");
  cli::expect_bad_input("trace", small + " --method natural --detect_branch_points true",
                        "detect_branch_points", "cli_input_combinations");
  cli::expect_bad_input("trace", small + " --method natural --natural_parameter nosuch",
                        "natural_parameter", "cli_input_combinations");
  cli::expect_bad_input("trace", small + " --bound energy:2:1", "bound", "cli_input_combinations");
}

TEST(CommandLineInput, ResumeTakesNoStartAndNeedsItsSummary) {
  const fs::path dir = cli::scratch("cli_input", "resumed");
  ASSERT_EQ(cli::run("trace", small + " --max_points 4", dir).code, 0);
  int code = -1;
  stdout_of("trace --resume " + dir.string() + " --start " + (dir / "orbits.csv:2").string(), code);
  EXPECT_EQ(code, 2);
  fs::remove(dir / "summary.txt");
  stdout_of("trace --resume " + dir.string(), code);
  EXPECT_EQ(code, 2);
  stdout_of("", code);  // no command at all
  EXPECT_EQ(code, 2);
}

TEST(TraceInput, ADamagedSavedFolderIsRefusedBeforeAnythingIsRepaired) {
  const fs::path dir = cli::scratch("trace_input", "damaged");
  ASSERT_EQ(cli::run("trace", small + " --max_points 5", dir).code, 0);
  const auto read = [](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), {});
  };
  const std::string branch = read(dir / "branch.csv");
  std::ofstream(dir / "state.txt") << "hello\nworld 1 2 3\n";  // not a state file
  int code = -1;
  stdout_of("trace --resume " + dir.string() + " --max_points 8", code);
  EXPECT_EQ(code, 2);
  EXPECT_EQ(read(dir / "branch.csv"), branch);  // nothing cut, nothing appended
  const fs::path out = cli::scratch("trace_input", "from_damaged");
  const cli::Run start = cli::run("trace", small + " --start " + dir.string() + ":3", out);
  EXPECT_EQ(start.code, 2) << start.err;
  EXPECT_NE(start.err.find("start:"), std::string::npos) << start.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(TraceInput, AShapeOutsideItsRangeIsBadInput) {
  for (const char* shape : {"-0.5", "0", "1.5"})
    cli::expect_bad_input("trace", scene + " --branch subharmonic --shape " + std::string(shape),
                          "shape", "trace_input_shape");
}

TEST(TraceInput, ADuffingPeriodGuessFarAboveTheLinearPeriodIsBadInput) {
  // 1e12 s had CVODE integrate until it gave up, with three lines of its errors and exit 1.
  cli::expect_bad_input(
      "trace",
      std::string(BACKBONE_SOURCE_DIR) + "/problems/duffing/scenes/duffing.ini --period_guess 1e12",
      "period_guess", "trace_input_duffing");
}

TEST(TraceInput, ASimulationStepThatCrossesTheBarIsBadInputForTraceToo) {
  // The scene.ini a trace writes must simulate: dt = 5 s > L/c = 1 s would not.
  cli::expect_bad_input("trace", small + " --dt 5", "dt", "trace_input_dt_sim");
}

TEST(SimulateInput, ADamagedOrbitFileIsNamedByTheOrbitKey) {
  const fs::path traced = cli::scratch("cli_input", "traced_for_orbit");
  ASSERT_EQ(cli::run("trace", small + " --max_points 4", traced).code, 0);
  std::ofstream(traced / "orbits.csv") << "point,x,u0\n0,zero,nan\n";
  cli::expect_bad_input("simulate", scene + " --orbit " + (traced / "orbits.csv:0").string(),
                        "orbit:", "simulate_input_orbit");
}

TEST(TraceOutputs, TheSubharmonicTraceSaysWhichDimensionItsBranchFileHolds) {
  // The point lines give the traced curve's dimension (F plus the shape row: 1); branch.csv's
  // dimension column holds F alone's (dimension_check), and the run says so with its counts.
  const fs::path out = cli::scratch("trace_outputs", "subharmonic");
  int code = -1;
  const std::string text = stdout_of(
      "trace " + scene + " --branch subharmonic --max_points 5 --out " + out.string(), code);
  ASSERT_EQ(code, 0);
  const auto dimension = backbone::core::Table::read_csv(out / "branch.csv").column("dimension");
  const auto twos = std::count(dimension.begin(), dimension.end(), 2.0);
  EXPECT_NE(text.find("dimension of the periodicity residual F alone (branch.csv's dimension "
                      "column; the point lines give the traced curve's): 2 at " +
                      std::to_string(twos) + " points"),
            std::string::npos)
      << text;
}

TEST(TraceOutputs, TheManifoldTraceStatesTheDimensionItCovers) {
  // The atlas covers a 2D manifold from one corrected start: the header says 2, summary.txt
  // too, and no one-point branch.png is drawn (manifold.png is the figure).
  const fs::path out = cli::scratch("trace_outputs", "manifold");
  int code = -1;
  std::string arguments = "trace " + scene;
  arguments += " --branch subharmonic_manifold --energy_min 1e-5 --energy_max 2e-5 --out ";
  arguments += out.string();
  const std::string text = stdout_of(arguments, code);
  ASSERT_EQ(code, 0) << text;
  EXPECT_NE(text.find("expected manifold dimension 2"), std::string::npos) << text;
  std::ifstream summary(out / "summary.txt");
  const std::string lines((std::istreambuf_iterator<char>(summary)),
                          std::istreambuf_iterator<char>());
  EXPECT_NE(lines.find("expected_dimension 2"), std::string::npos) << lines;
  EXPECT_FALSE(fs::exists(out / "branch.png"));
  EXPECT_TRUE(fs::exists(out / "manifold.png"));
}

TEST(FiguresInput, AFolderWithNoTracedBranchIsBadInput) {
  const fs::path empty = cli::scratch("cli_input", "empty_results");
  fs::create_directories(empty);
  const cli::Run r = cli::run("figures", "", empty);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("out:"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_empty(empty));
}

TEST(OutputFolderInput, AFolderThatCannotBeCreatedIsBadInputForEveryCommand) {
  // /proc takes no new folders; bench and reproduce checked nothing before their first case.
  const fs::path proc = "/proc/backbone_test";
  for (const std::string command : {"bench --case tdbem_scaling", "reproduce --only mode1"}) {
    const cli::Run r = cli::run(command, "", proc, cli::scratch("cli_input", "err"));
    EXPECT_EQ(r.code, 2) << command << "\n" << r.err;
    EXPECT_NE(r.err.find("out: cannot create"), std::string::npos) << r.err;
  }
}

TEST(OutputFolderInput, NamesAndPathsBeyondTheSystemsLimitsAreBadInput) {
  const fs::path parent = cli::scratch("cli_input", "long");
  const std::string long_name(NAME_MAX + 1, 'a');  // one character over the limit of a name
  const cli::Run name =
      cli::run("trace", small, parent / long_name, parent.string() + ".name.stderr");
  EXPECT_EQ(name.code, 2) << name.err;
  EXPECT_NE(name.err.find("longer than the system's limit"), std::string::npos) << name.err;
  fs::path deep = parent;  // PATH_MAX reached by names each within NAME_MAX
  while (deep.string().size() < PATH_MAX) deep /= std::string(200, 'b');
  const cli::Run path = cli::run("simulate", scene, deep, parent.string() + ".path.stderr");
  EXPECT_EQ(path.code, 2) << path.err;
  EXPECT_NE(path.err.find("characters long"), std::string::npos) << path.err;
  EXPECT_FALSE(fs::exists(parent / std::string(200, 'b')));
}

TEST(FiguresInput, AFolderWithoutTracedBranchesIsBadInput) {
  const fs::path missing = cli::scratch("cli_input", "no_such_folder");
  const cli::Run r = cli::run("figures", "", missing);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("out:"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(missing));
}

TEST(SceneFileInput, WhatIsNotASceneIsRefusedBeforeItIsRead) {
  const fs::path fifo = cli::scratch("cli_input", "fifo");
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);  // reading it would block forever
  const std::string paper_keys = "problem = contact_bar\n";
  for (const std::string& path :
       {std::string("/dev/zero"), fifo.string(),
        scene_file("large.ini", paper_keys + std::string(2 << 20, '#')).string(),
        scene_file("nul.ini", paper_keys + std::string("gap = 1e-3\0\n", 12)).string(),
        scene_file("utf16.ini", std::string("\xff\xfep\0r\0o\0", 8)).string(),
        scene_file("section.ini", "[bar]\n" + paper_keys).string()})
    cli::expect_bad_input("trace", path + " --branch mode1", "scene", "cli_input_scene");
}

TEST(SceneFileInput, TheSceneFileComesFirst) {
  const fs::path out = cli::scratch("cli_input", "order");
  const cli::Run r = cli::run("trace", "--branch mode1 " + scene, out);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("the scene file comes first"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(EveryCommand, AnswersHelpWithItsUsage) {
  for (const char* command :
       {"trace", "simulate", "inspect", "bench", "figures", "reproduce", "version"}) {
    int code = -1;
    const std::string text = stdout_of(std::string(command) + " --help", code);
    EXPECT_EQ(code, 0) << command;
    EXPECT_NE(text.find("usage: backbone " + std::string(command)), std::string::npos)
        << command << ":\n"
        << text;
  }
}

TEST(InspectInput, HelpIsAnswered) {
  int code = -1;
  EXPECT_NE(stdout_of("inspect --help", code).find("usage: backbone inspect"), std::string::npos);
  EXPECT_EQ(code, 0);
  EXPECT_NE(stdout_of("inspect " + scene + " --help", code).find("usage"), std::string::npos);
  EXPECT_EQ(code, 0);
}

}  // namespace
