// Restarting a branch from the loop state saved with one of its points (continuation/
// restart.hpp): the state's text form reads back bit for bit, and every loop continued from the
// state of point k, written and read back as state.txt would hold it, takes exactly the steps
// of the uninterrupted run. The oracle is that run itself, compared with ==: the arithmetic of
// both runs is the same, so any difference is state the restart lost (the re-corrected point,
// the re-derived tangent or step of the restart this replaced moved the branch by ~1e-14 and
// then let it diverge at a retried step).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "continuation/branch_points/branch_points.hpp"
#include "continuation/methods/natural.hpp"
#include "continuation/methods/pseudo_arclength.hpp"
#include "continuation/methods/switching.hpp"
#include "continuation/restart.hpp"
#include "core/errors.hpp"
#include "problems/algebraic/algebraic.hpp"
#include "tests/continuation/test_support.hpp"

using namespace backbone;
using continuation::Branch;
using continuation::LoopState;
using continuation_tests::vec;
namespace fs = std::filesystem;

namespace {

// An empty folder of this test's own under the system's temporary folder.
fs::path scratch(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("backbone_test_restart_" + name);
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

// x^2 + lambda = 1 with lambda in thousandths: typical scale (1, 1e-3), so the scaled unknowns
// differ from the problem's and a restart from the unknowns alone would not be exact.
class ScaledFold : public core::Problem {
 public:
  int num_unknowns() const override { return 2; }
  int num_equations() const override { return 1; }
  core::Observables observables(const core::Vector& x) const override {
    return {{"x", x[0]}, {"lambda", x[1]}};
  }
  core::Vector typical_scale() const override { return vec(1.0, 1e-3); }

 protected:
  core::EvalStatus compute_residual(const core::Vector& x, core::Vector& r) const override {
    r.resize(1);
    r[0] = x[0] * x[0] + 1e3 * x[1] - 1.0;
    return core::EvalStatus::ok;
  }
};

// The state of a point as it comes back from state.txt.
LoopState through_text(const continuation::BranchPoint& p) {
  EXPECT_TRUE(p.state) << "point " << p.index << " has no saved state";
  return continuation::parse_state(continuation::format_state(*p.state), "state", "test");
}

// Points from index `from` + 1 on of `full` and all of `rest` (which begins there) are equal,
// every unknown and the step and arclength of each point.
void expect_same_tail(const Branch& full, const Branch& rest, int from) {
  ASSERT_EQ(full.points.size(), from + 1 + rest.points.size()) << rest.message;
  for (std::size_t i = 0; i < rest.points.size(); ++i) {
    const auto& a = full.points[from + 1 + i];
    const auto& b = rest.points[i];
    EXPECT_EQ(a.index, b.index);
    EXPECT_TRUE(a.x == b.x) << "point " << a.index << ": " << (a.x - b.x).norm();
    EXPECT_EQ(a.step_size, b.step_size) << a.index;
    EXPECT_EQ(a.arclength, b.arclength) << a.index;
    EXPECT_EQ(a.newton_iterations, b.newton_iterations) << a.index;
  }
  EXPECT_EQ(full.reason, rest.reason);
}

continuation::ContinuationOptions options(int points) {
  continuation::ContinuationOptions o;
  o.ds = 0.05;
  o.ds_max = 0.3;
  o.max_points = points;
  o.rank_check_every = 0;
  o.verify = false;
  return o;
}

}  // namespace

// Awkward doubles (a third, subnormals, -0, the largest, an infinity) and vectors of every
// field come back identical.
TEST(LoopState, TextFormReadsBackBitForBit) {
  LoopState s;
  s.method = continuation::Method::natural;
  s.index = 17;
  s.arclength = 1.0 / 3.0;
  s.ds = 0.1 + 0.2;
  s.lambda = -0.0;
  s.previous_step = std::numeric_limits<double>::denorm_min();
  s.switch_index = 9;
  s.jacobian_scale = std::numeric_limits<double>::max();
  s.scale = vec(1e-300, 7.0 / 3.0);
  s.z = vec(std::nextafter(1.0, 2.0), -1e-310);
  s.tangent = vec(0.6, -0.8);
  s.jacobian_point = vec(-2.0 / 3.0, 1e300);
  s.chord_misses = 11;
  s.rejected_corrections = 6;
  s.brackets = 4;
  continuation::TestFunctionSample a;
  a.index = 16;
  a.s = 2.0 / 7.0;
  a.z = vec(1e-17, 3.0);
  a.tangent = vec(1.0, 0.0);
  a.tau.value = -std::numeric_limits<double>::infinity();
  a.tau.continued = false;
  a.tau.left = core::Vector::Constant(3, std::sqrt(2.0));
  a.tau.right = vec(std::sqrt(3.0), -std::sqrt(5.0));
  s.samples = {a, a};
  const LoopState b = continuation::parse_state(continuation::format_state(s), "state", "test");
  EXPECT_EQ(b.method, s.method);
  EXPECT_EQ(b.index, s.index);
  for (const auto& [x, y] :
       std::vector<std::pair<double, double>>{{b.arclength, s.arclength},
                                              {b.ds, s.ds},
                                              {b.previous_step, s.previous_step},
                                              {b.jacobian_scale, s.jacobian_scale}})
    EXPECT_EQ(x, y);
  EXPECT_TRUE(std::signbit(b.lambda));
  EXPECT_EQ(b.switch_index, 9);
  EXPECT_TRUE(b.scale == s.scale && b.z == s.z && b.tangent == s.tangent);
  EXPECT_EQ(b.previous.size(), 0);
  EXPECT_TRUE(b.jacobian_point == s.jacobian_point);
  EXPECT_EQ(b.chord_misses, 11);
  EXPECT_EQ(b.rejected_corrections, 6);
  EXPECT_EQ(b.brackets, 4);
  ASSERT_EQ(b.samples.size(), 2u);
  EXPECT_EQ(b.samples[1].index, 16);
  EXPECT_EQ(b.samples[1].s, a.s);
  EXPECT_EQ(b.samples[1].tau.value, a.tau.value);
  EXPECT_FALSE(b.samples[1].tau.continued);
  EXPECT_TRUE(b.samples[1].tau.left == a.tau.left && b.samples[1].tau.right == a.tau.right);
  EXPECT_TRUE(b.samples[1].z == a.z && b.samples[1].tangent == a.tangent);
}

// The smallest valid arclength state: a point, its scale, tangent and step.
static LoopState minimal_state() {
  LoopState s;
  s.z = vec(1, 2);
  s.scale = vec(1, 1);
  s.tangent = vec(1, 0);
  s.ds = 0.1;
  return s;
}

// A state written before chord corrections (no jacobian_point, no chord_misses) still reads:
// the next correction then starts with a fresh Jacobian.
TEST(LoopState, StateWithoutTheChordFieldsReads) {
  LoopState s = minimal_state();
  s.jacobian_point = vec(3, 4);
  s.chord_misses = 5;
  std::string line = continuation::format_state(s);
  for (const std::string field : {" jacobian_point=3,4", " chord_misses=5"}) {
    const auto at = line.find(field);
    ASSERT_NE(at, std::string::npos) << line;
    line.erase(at, field.size());
  }
  const LoopState b = continuation::parse_state(line, "resume", "test");
  EXPECT_EQ(b.jacobian_point.size(), 0);
  EXPECT_EQ(b.chord_misses, 0);
  EXPECT_TRUE(b.z == s.z);
}

TEST(LoopState, DefectsAreInputErrorsNamingTheKey) {
  const LoopState s = minimal_state();
  const std::string good = continuation::format_state(s);
  EXPECT_NO_THROW(continuation::parse_state(good, "resume", "test"));
  for (const std::string& bad :
       {std::string("method=arclength"), good + " z=1,x", good + " tangent=1", good + " ds=0",
        good + " samples=4", good + " junk", good + " jacobian_point=1,2,3",
        good + " rejected_corrections=-1"}) {
    try {
      continuation::parse_state(bad, "resume", "test");
      ADD_FAILURE() << bad;
    } catch (const core::InputError& e) {
      EXPECT_EQ(e.key(), "resume") << bad;
    }
  }
}

// The located candidates an interrupted run keeps (branch_points.txt) read back bit for bit,
// every field follow_attached and branch_points.csv use, the observables recomputed; the wall
// time is not kept (repeated runs write the file bit for bit).
TEST(SavedBranchPoints, TextFormReadsBackBitForBit) {
  const fs::path dir = scratch("saved_branch_points");
  continuation::SavedBranchPoints saved;
  saved.settled = 3;
  continuation::BranchPointReport r;
  r.bracket = 2;
  r.after_point = 40;
  r.x = vec(1.0 / 3.0, -1e-310);
  r.arclength = 2.0 / 7.0;
  r.test_value = -0.0;
  r.sign_change = true;
  r.location_steps = 6;
  r.jacobian_evaluations = 12345678901;
  r.residual_evaluations = 7;
  r.nullity = 3;
  r.attached_dimension = 2;
  r.candidates = 2;
  r.probed = 2;
  r.verified_dimension = 3;
  r.tangent_angle = std::numeric_limits<double>::quiet_NaN();
  r.seconds = 0.125;
  r.attached_points = {vec(0.5, 1e300), vec(std::sqrt(2.0), 0.0)};
  r.attached_point = r.attached_points[1];
  r.attached_description = {{"frequency_ratio", 7.0 / 3.0}, {"resonance_order", 8}};
  continuation::BranchPointReport unverified;
  unverified.bracket = 0;
  unverified.x = vec(0.25, 0.75);
  saved.reports = {unverified, r};
  saved.write(dir);
  const ScaledFold problem;
  const continuation::SavedBranchPoints b =
      continuation::read_saved_branch_points(dir, problem, "resume");
  EXPECT_EQ(b.settled, 3);
  ASSERT_EQ(b.reports.size(), 2u);
  const continuation::BranchPointReport& c = b.reports[1];
  EXPECT_EQ(c.bracket, 2);
  EXPECT_EQ(c.after_point, 40);
  EXPECT_TRUE(c.x == r.x && c.attached_point == r.attached_point);
  ASSERT_EQ(c.attached_points.size(), 2u);
  EXPECT_TRUE(c.attached_points[0] == r.attached_points[0] &&
              c.attached_points[1] == r.attached_points[1]);
  EXPECT_EQ(c.arclength, r.arclength);
  EXPECT_TRUE(std::signbit(c.test_value));
  EXPECT_TRUE(c.sign_change);
  EXPECT_EQ(c.location_steps, 6);
  EXPECT_EQ(c.jacobian_evaluations, 12345678901);
  EXPECT_EQ(c.residual_evaluations, 7);
  EXPECT_EQ(c.nullity, 3);
  EXPECT_EQ(c.attached_dimension, 2);
  EXPECT_EQ(c.candidates, 2);
  EXPECT_EQ(c.probed, 2);
  EXPECT_EQ(c.verified_dimension, 3);
  EXPECT_TRUE(std::isnan(c.tangent_angle));
  EXPECT_EQ(c.seconds, 0);  // wall time is not kept
  EXPECT_EQ(c.attached_description, r.attached_description);
  EXPECT_EQ(c.observables, problem.observables(r.x));
  EXPECT_EQ(b.reports[0].attached_points.size(), 0u);
  EXPECT_EQ(b.reports[0].attached_point.size(), 0);
}

// A resume takes up the last point whose state had made no more brackets than the saved list
// settled, and keeps the candidates bracketed before it: here 3 are settled, point 5 had made
// 4 (one still being located when the run stopped), point 4 had made 3. Point 3 has no state
// (`3 -`), which the search passes over. States that do not count brackets, or no saved list:
// nothing to take up (the rows of branch_points.csv are merged instead).
TEST(SavedBranchPoints, ResumeStartsWhereEveryBracketWasSettled) {
  const fs::path dir = scratch("branch_point_resume");
  const ScaledFold problem;
  const auto state = [](int index, int brackets) {
    LoopState s = minimal_state();
    s.index = index;
    s.brackets = brackets;
    return fmt::format("{} {}\n", index, continuation::format_state(s));
  };
  const auto write = [&](const std::string& text) {
    std::ofstream(dir / "state.txt") << "point state\n" << text;
  };
  write(state(0, 0) + state(1, 1) + state(2, 2) + "3 -\n" + state(4, 3) + state(5, 4));
  EXPECT_FALSE(continuation::branch_point_resume(dir, 5, problem, "resume"));
  continuation::SavedBranchPoints saved;
  saved.settled = 3;
  for (int bracket : {0, 2}) {
    continuation::BranchPointReport r;
    r.bracket = bracket;
    r.x = vec(bracket, 1);
    saved.reports.push_back(r);
  }
  saved.write(dir);
  auto r = continuation::branch_point_resume(dir, 5, problem, "resume");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->point, 4);
  EXPECT_EQ(r->saved.settled, 3);
  EXPECT_EQ(r->saved.reports.size(), 2u);
  // Point 2 had made 2 brackets: the candidate of bracket 2 is located again from there.
  saved.settled = 2;
  saved.reports.pop_back();
  saved.write(dir);
  r = continuation::branch_point_resume(dir, 5, problem, "resume");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->point, 2);
  EXPECT_EQ(r->saved.reports.size(), 1u);
  // A candidate written before the count that settles its bracket counts as settled.
  saved.settled = 0;
  saved.write(dir);
  r = continuation::branch_point_resume(dir, 5, problem, "resume");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->point, 1);
  write(state(0, 0) + "1 " +
        continuation::format_state(minimal_state())
            .replace(continuation::format_state(minimal_state()).find(" brackets=-1"), 12, "") +
        "\n");
  EXPECT_FALSE(continuation::branch_point_resume(dir, 1, problem, "resume"));
  // A state of a loop without a detector (brackets=-1) ends the search too.
  write(state(0, 0) + state(1, -1));
  EXPECT_FALSE(continuation::branch_point_resume(dir, 1, problem, "resume"));
  std::ofstream(dir / "branch_points.txt") << "not a list\n";
  try {
    continuation::branch_point_resume(dir, 1, problem, "resume");
    ADD_FAILURE() << "a list that is no list was read";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.key(), "resume");
  }
}

// Pseudo-arclength round the fold of x^2 + 1000 lambda = 1 (tangent and secant predictors,
// the step growing and shrinking), continued from the states of points 0, 7 and 20.
TEST(PseudoArclength, ContinuesFromASavedStateBitForBit) {
  ScaledFold fold;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  for (const auto predictor : {continuation::Predictor::tangent, continuation::Predictor::secant}) {
    auto opt = options(40);
    opt.predictor = predictor;
    const Branch full =
        continuation::pseudo_arclength(fold, vec(-1.5, -1.25e-3), vec(1, 0), *newton, opt);
    ASSERT_EQ(full.points.size(), 40u) << full.message;
    ASSERT_GT(full.points.back().x[0], 0.5);  // round the fold at x = 0
    for (int k : {0, 7, 20}) {
      const LoopState state = through_text(full.points[k]);
      const Branch rest = continuation::pseudo_arclength(fold, state, false, *newton, opt);
      expect_same_tail(full, rest, k);
      // record_from: the saved point comes first, as it was (not corrected again).
      const Branch with = continuation::pseudo_arclength(fold, state, true, *newton, opt);
      ASSERT_FALSE(with.points.empty());
      EXPECT_TRUE(with.points.front().x == full.points[k].x);
      EXPECT_EQ(with.points.front().index, k);
    }
  }
}

// Natural continuation in lambda, and the paper's strategy continued from a state of its
// natural part (before the switch) and of its arclength part (after it).
TEST(NaturalThenArclength, ContinuesFromSavedStatesOfBothParts) {
  ScaledFold fold;
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  auto opt = options(50);
  opt.ds_min = 1e-4;
  const auto lambda = continuation::NaturalParameter::of_unknown(1, "lambda");
  const Branch natural =
      continuation::natural(fold, vec(-1.5, -1.25e-3), lambda, *newton, options(20));
  ASSERT_EQ(natural.points.size(), 20u) << natural.message;
  expect_same_tail(natural,
                   continuation::natural(fold, through_text(natural.points[6]), false, lambda,
                                         *newton, options(20)),
                   6);
  const auto full =
      continuation::natural_then_arclength(fold, vec(-1.5, -1.25e-3), lambda, *newton, opt);
  ASSERT_GT(full.switch_index, 3) << full.branch.message;
  ASSERT_LT(full.switch_index + 5, 50);
  for (int k : {full.switch_index - 2, full.switch_index - 1, full.switch_index + 3}) {
    const LoopState state = through_text(full.branch.points[k]);
    const auto rest =
        continuation::natural_then_arclength(fold, state, false, lambda, *newton, opt);
    EXPECT_EQ(rest.switch_index, full.switch_index) << k;
    expect_same_tail(full.branch, rest.branch, k);
  }
}

// A state is taken up only by a run in the same scaled units: another typical scale, another
// size or another loop is refused, named.
TEST(LoopState, MismatchIsNamed) {
  ScaledFold fold;
  algebraic::FoldCurve unit_fold;  // typical scale 1
  auto newton = core::make_corrector("eigen", core::NewtonOptions{});
  const auto opt = options(5);
  const Branch b =
      continuation::pseudo_arclength(fold, vec(-1.5, -1.25e-3), vec(1, 0), *newton, opt);
  const LoopState state = *b.points.back().state;
  EXPECT_TRUE(continuation::state_mismatch(state, fold, opt).empty());
  EXPECT_NE(continuation::state_mismatch(state, unit_fold, opt).find("scaled units"),
            std::string::npos);
  auto natural = opt;
  natural.method = continuation::Method::natural;
  EXPECT_NE(continuation::state_mismatch(state, fold, natural).find("arclength loop"),
            std::string::npos);
  EXPECT_THROW(continuation::pseudo_arclength(unit_fold, state, false, *newton, opt),
               core::InputError);
}
