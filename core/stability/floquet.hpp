// Floquet multipliers of a periodic orbit: the eigenvalues of its monodromy matrix M, the
// derivative of the period map of the full state (core/README.md, section 'Stability').
//
// A problem that can build M implements FloquetProblem beside its residual; the continuation
// then stores the multipliers with every point (branch.csv's stable, unstable_multipliers,
// max_multiplier_modulus; multipliers.csv). analyse_monodromy separates the multipliers that
// the orbit's kind puts at +1 whatever its stability (FloquetStructure) from the others and
// decides stability from the others alone:
//   - forced (non-autonomous) orbits: none is trivial;
//   - autonomous orbits: one, the time shift;
//   - conservative autonomous orbits: two, time shift and energy (a Jordan block, so that an
//     error e in M moves them by about sqrt(e): trivial_tolerance is a square root's width).
// Conservative problems (symplectic M) report the structure checks |det M - 1| and the pairing
// error max_i min_j |mu_i mu_j - 1| (multipliers come as mu, 1/mu).
//
//   core::Matrix M; problem.monodromy(x, M);
//   core::Floquet f = core::analyse_monodromy(M, problem.floquet_structure(), {});
//   if (f.stable == 0) fmt::print("{} multipliers outside the unit circle\n", f.unstable);
#pragma once

#include <complex>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/problem.hpp"
#include "core/types.hpp"

namespace backbone::core {

struct FloquetStructure {
  int trivial = 0;            // multipliers at +1 by construction (0, 1 or 2)
  bool conservative = false;  // M symplectic: det M = 1, multipliers in pairs mu, 1/mu
  // false: M comes from a representation whose isolated multipliers are not known to converge
  // (the contact bar's projected full state): the per-point counts stand, but the sign changes
  // of the test functions between points are not taken for bifurcations.
  bool bifurcations_detectable = true;
};

struct FloquetOptions {
  // A multiplier is outside the unit circle when |mu| > 1 + tolerance. The default sits well
  // above the monodromy's error on the problems here (1e-10 from CVODE at rtol 1e-13, measured
  // as |det M - r^2| on the impact oscillator) and far below any growth that matters within a
  // few hundred periods.
  double tolerance = 1e-6;
  // The trivial multipliers must lie within this distance of +1; when they do not, M is not
  // accurate enough to tell them from the others and the point's stability is undecided (-1).
  // A simple trivial multiplier moves by about the error of M, the conservative pair (a Jordan
  // block) by its square root: 1e-4 leaves room for an error of 1e-8 in M.
  double trivial_tolerance = 1e-4;
  void validate() const;  // InputError("floquet_tolerance" / "floquet_trivial_tolerance", ...)
};

// Where the non-trivial multipliers outside the unit circle lie: a change of one count between
// two points of a branch is a bifurcation of the orbit (fold: real positive; period doubling:
// real negative; torus or Krein collision: complex).
struct OutsideCounts {
  int real_positive = 0, real_negative = 0, complex = 0;
  bool operator==(const OutsideCounts&) const = default;
};

struct Floquet {
  std::vector<std::complex<double>> multipliers;  // all of them, by decreasing modulus
  std::vector<bool> trivial;                      // per multiplier: counted as trivial
  // 1 stable (every non-trivial |mu| <= 1 + tolerance), 0 unstable, -1 undecided (M could not
  // be built or its eigenvalues not computed, or the trivial multipliers are not within
  // trivial_tolerance of +1).
  int stable = -1;
  int unstable = 0;             // non-trivial multipliers with |mu| > 1 + tolerance
  double max_modulus = 0;       // largest |mu| among the non-trivial ones (NaN: none, or no M)
  double trivial_distance = 0;  // largest |mu - 1| among the trivial ones (0: none)
  double determinant = 0;       // det M
  double pairing_error = 0;     // conservative problems: max_i min_j |mu_i mu_j - 1|, else NaN
  OutsideCounts outside;        // where the unstable ones lie
  // Test functions whose sign changes where a real multiplier crosses -1 (period doubling) or
  // +1 (fold), over the non-trivial multipliers: prod (mu + 1) and prod (mu - 1), each factor
  // normalised by max(1, |mu|) so that a product stays of order one.
  double period_doubling_test = 0, fold_test = 0;
  // The largest modulus of a complex non-trivial multiplier, less 1 (NaN: none is complex): its
  // sign changes where a pair leaves the circle off the real axis (a torus). A conservative pair
  // that collides on the circle and leaves it (Krein) goes from 0 to positive instead.
  double torus_test = 0;
};

// Eigenvalues of M with the trivial ones identified (the structure's count, nearest to +1) and
// the stability decided (see Floquet). A matrix with a NaN gives stable = -1 and NaN moduli.
Floquet analyse_monodromy(const Matrix& M, const FloquetStructure& structure,
                          const FloquetOptions& options);
// The result for a point whose monodromy could not be built: stable = -1, NaN numbers.
Floquet undecided_floquet(int size);

// Optional interface of a problem whose solutions are periodic orbits with a monodromy matrix.
class FloquetProblem {
 public:
  virtual ~FloquetProblem() = default;
  // M at the orbit x (the problem's unknowns, x a solution): the derivative of the period map
  // of the full state (positions and velocities of a mechanical system), n x n.
  virtual EvalStatus monodromy(const Vector& x, Matrix& M) const = 0;
  virtual FloquetStructure floquet_structure() const = 0;
  // Names of observables that fall to 0 where the orbit grazes a switching surface (an event
  // with zero normal velocity), for the grazing detection (continuation/README.md, 'Stability
  // and bifurcations of orbits'). Default: none.
  virtual std::vector<std::string> grazing_observables() const { return {}; }
  // A problem whose solutions are the grazing orbits where that observable vanishes, with the
  // same unknowns (x near one: the branch's last point), or nullptr (the default).
  virtual std::unique_ptr<Problem> grazing_problem(const std::string& observable,
                                                   const Vector& x) const {
    return nullptr;
  }
  // The same system with orbits of twice the period, for the switch at a period doubling
  // (continuation/orbit_bifurcations/doubling.hpp), or nullptr (the default: no switch).
  virtual std::unique_ptr<Problem> doubled_problem() const { return nullptr; }
  // An orbit x of this problem as an orbit of doubled_problem() (its unknowns).
  virtual Vector doubled_unknowns(const Vector& x) const { return x; }
};

// The multipliers of the orbit x of `problem` when it is a FloquetProblem (nullopt otherwise);
// undecided (undecided_floquet(0)) when its monodromy cannot be built at x.
std::optional<Floquet> floquet_at(const Problem& problem, const Vector& x,
                                  const FloquetOptions& options);

}  // namespace backbone::core
