// detect_orbit_bifurcations on problems whose monodromy is a known function of the parameter
// lambda: F(x, lambda) = x (every lambda is a solution, the branch is the lambda axis) with
//   fold             M = diag(lambda, 0.5)        a real multiplier through +1 at lambda = 1
//   period doubling  M = diag(-lambda, 0.5)       through -1 at lambda = 1
//   torus            M = lambda R(0.7)            a complex pair leaving the circle at lambda = 1
// and a pseudo-arclength branch from lambda = 0.5 to 1.5, and the resume path: a branch whose
// points carry multipliers writes multipliers.csv and repairs it like the other files.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "continuation/methods/pseudo_arclength.hpp"
#include "continuation/orbit_bifurcations/bifurcations.hpp"
#include "continuation/outputs.hpp"
#include "core/io/table.hpp"
#include "core/stability/floquet.hpp"

namespace core = backbone::core;
namespace continuation = backbone::continuation;

namespace {

enum class Kind { fold, doubling, torus };

class Axis : public core::Problem, public core::FloquetProblem {
 public:
  explicit Axis(Kind kind) : kind_(kind) {}
  int num_unknowns() const override { return 2; }
  int num_equations() const override { return 1; }
  core::Observables observables(const core::Vector& x) const override { return {{"lambda", x[1]}}; }
  core::EvalStatus monodromy(const core::Vector& x, core::Matrix& M) const override {
    const double lambda = x[1];
    M = core::Matrix::Zero(2, 2);
    switch (kind_) {
      case Kind::fold:
        M.diagonal() << lambda, 0.5;
        break;
      case Kind::doubling:
        M.diagonal() << -lambda, 0.5;
        break;
      case Kind::torus:
        M << std::cos(0.7), -std::sin(0.7), std::sin(0.7), std::cos(0.7);
        M *= lambda;
        break;
    }
    return core::EvalStatus::ok;
  }
  core::FloquetStructure floquet_structure() const override { return {0, false}; }

 protected:
  core::EvalStatus compute_residual(const core::Vector& x, core::Vector& r) const override {
    r.resize(1);
    r[0] = x[0];
    return core::EvalStatus::ok;
  }

 private:
  Kind kind_;
};

continuation::Branch trace(const Axis& axis) {
  continuation::ContinuationOptions options;
  options.ds = 0.07;
  options.ds_max = 0.07;
  options.max_points = 100;
  options.rank_check_every = 0;
  options.bounds = {{"lambda", 0.5, 1.5}};
  core::Vector start(2), direction(2);
  start << 0.0, 0.5;
  direction << 0.0, 1.0;
  auto corrector = core::make_corrector("eigen", {});
  return continuation::pseudo_arclength(axis, start, direction, *corrector, options);
}

}  // namespace

TEST(OrbitBifurcations, EachKindIsDetectedAndLocatedAtItsCrossing) {
  for (const auto& [kind, name] :
       {std::pair{Kind::fold, "fold"}, std::pair{Kind::doubling, "period_doubling"},
        std::pair{Kind::torus, "torus"}}) {
    const Axis axis(kind);
    const continuation::Branch branch = trace(axis);
    ASSERT_GT(branch.points.size(), 10u) << branch.message;
    // Stable below lambda = 1, unstable above (no point sits on 1 with these steps).
    for (const auto& p : branch.points) {
      ASSERT_TRUE(p.floquet);
      EXPECT_EQ(p.floquet->stable, p.observable("lambda") < 1 ? 1 : 0) << name;
    }
    auto corrector = core::make_corrector("eigen", {});
    int reported = 0;
    const auto found = continuation::detect_orbit_bifurcations(
        axis, branch, *corrector, {}, [&](const continuation::OrbitBifurcation&) { ++reported; });
    ASSERT_EQ(found.size(), 1u) << name;
    EXPECT_EQ(reported, 1);
    EXPECT_EQ(found[0].type, name);
    EXPECT_TRUE(found[0].located);
    // Located to the bracket of 1e-10 of max(1, |x|) (bifurcations.hpp).
    EXPECT_NEAR(found[0].x[1], 1.0, 1e-9) << name;
    // The multipliers recomputed at the located point: one of modulus 1 there.
    EXPECT_NEAR(std::abs(found[0].floquet.multipliers[0]), 1.0, 1e-9) << name;
  }
}

TEST(OrbitBifurcations, TableNamesTheTypeAndTheMultipliers) {
  const Axis axis(Kind::doubling);
  const continuation::Branch branch = trace(axis);
  auto corrector = core::make_corrector("eigen", {});
  const auto found = continuation::detect_orbit_bifurcations(axis, branch, *corrector, {});
  const core::Table t = continuation::bifurcation_table(found, branch.points.front().observables);
  ASSERT_EQ(t.rows(), 1u);
  EXPECT_EQ(t.text_column("type")[0], "period_doubling");
  EXPECT_NEAR(t.column("lambda")[0], 1.0, 1e-9);
  EXPECT_NEAR(t.column("multiplier_0_re")[0], -1.0, 1e-9);
  EXPECT_EQ(t.column("located")[0], 1.0);
}

// multipliers.csv rows for every point, and a cut last row dropped with the point's other rows.
TEST(OrbitBifurcations, MultipliersFileIsWrittenAndRepairedWithTheBranch) {
  const std::filesystem::path out =
      std::filesystem::temp_directory_path() / "backbone_test_multipliers_file";
  std::filesystem::remove_all(out);
  const Axis axis(Kind::fold);
  const continuation::Branch branch = trace(axis);
  {
    continuation::BranchWriter writer(out, nullptr);
    for (const auto& p : branch.points) writer.append(p);
  }
  const core::Table m = core::Table::read_csv(out / "multipliers.csv");
  EXPECT_EQ(m.rows(), 2 * branch.points.size());
  // Stability flags agree between the files: a point is stable iff none of its multipliers
  // has a modulus beyond 1 + the default tolerance.
  const core::Table b = core::Table::read_csv(out / "branch.csv");
  const auto stable = b.column("stable");
  const auto point = m.column("point"), modulus = m.column("modulus");
  for (std::size_t i = 0; i < b.rows(); ++i) {
    bool outside = false;
    for (std::size_t j = 0; j < m.rows(); ++j)
      if (point[j] == static_cast<double>(i) && modulus[j] > 1 + 1e-6) outside = true;
    EXPECT_EQ(stable[i], outside ? 0.0 : 1.0) << "point " << i;
  }
  // An interruption that cut the last multiplier row: the whole last point goes.
  {
    std::string text;
    std::ifstream in(out / "multipliers.csv");
    text.assign(std::istreambuf_iterator<char>(in), {});
    text.resize(text.size() - 5);
    std::ofstream(out / "multipliers.csv", std::ios::trunc) << text;
  }
  const int last = continuation::repair_branch_files(out, "resume");
  EXPECT_EQ(last, static_cast<int>(branch.points.size()) - 2);
  EXPECT_EQ(core::Table::read_csv(out / "multipliers.csv").rows(), 2 * (branch.points.size() - 1));
  EXPECT_EQ(core::Table::read_csv(out / "branch.csv").rows(), branch.points.size() - 1);
  std::filesystem::remove_all(out);
}
