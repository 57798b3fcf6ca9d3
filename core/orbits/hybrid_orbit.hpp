// Periodic orbits of a hybrid system, forced or autonomous, by shooting with events and resets.
//
// The system (core/README.md, section 'Hybrid and forced orbits'):
//     y' = f(t, y; p),  y in R^n, p the named parameters;
//     events h_k(t, y; p) = 0, k < num_events(), crossed in event_direction(k), each followed by
//     a reset y+ = g_k(y-; p) (an impact law, a switch of regime), as many per period as occur.
// The orbit's period is either set by the forcing, T = forcing_periods() * forcing_period(p)
// (forced: non-autonomous, no phase condition), or an unknown (autonomous, forcing_period 0,
// one phase condition). Continuation runs in one free parameter (set_free_parameter), the
// others stay at their values. Unknown layout:
//     forced      x = [ y0 (n) | p_free ]             n equations  y(T) - y0
//     autonomous  x = [ y0 (n) | T | p_free ]         n + 1: y(T) - y0, phase(y0; p)
// The shooting starts at t = 0 with y0 and integrates to T with CVODE's root finding
// (cvode_integrator.hpp). The Jacobian is analytic: the variational equations Phi' = f_y Phi and
// psi' = f_y psi + f_p (psi = dy/dp_free) are integrated with the orbit, and at each event the
// saltation matrix
//     S = G + (f+ - G f-) n^T / D,   G = dg/dy, n = dh/dy, D = dh/dt + n^T f-,
// maps Phi and psi across it (psi also gains g_p + (f+ - G f-) h_p / D). The monodromy matrix
// is Phi(T) (FloquetProblem): an impact x = sigma with v+ = -r v- has det S = r^2.
//
// No event is lost: CVODE finds an event by a sign change of h_k over a step or a value of 0 at
// a step's end, so a crossing back and forth within one step would pass unseen. Each event
// therefore has a companion root function, dh_k/dt along the flow, whose zero in the opposite
// direction is the extremum of h_k between two such crossings. At that extremum h_k must still be
// on the near side of its surface; when it is not, the segment is integrated again from its start
// with steps shorter than the time to the extremum. A tangent event (grazing, D = 0) has no
// saltation matrix: the orbit is refused there (EvalStatus::failed) and the continuation stops
// before it; event_speed (the smallest D/|n| of the orbit, the normal speed at its events) falls
// to 0 on the way, which is what the grazing detection follows (grazing_observables()).
//
// Derivatives a subclass does not give are central differences (step cbrt(eps) max(|z|, 1)).
//
//   class ImpactOscillator : public core::HybridOrbitProblem {
//    public:
//     ImpactOscillator() : HybridOrbitProblem(2, {"frequency", "restitution", "wall"}) {}
//     void field(double t, const double* y, const core::Vector& p, double* dy) const override {
//       dy[0] = y[1]; dy[1] = -y[0] + std::cos(p[0] * t);
//     }
//     double forcing_period(const core::Vector& p) const override { return 2 * pi / p[0]; }
//     int num_events() const override { return 1; }
//     double event(int, double, const double* y, const core::Vector& p) const override {
//       return y[0] - p[2];
//     }
//     void reset(int, const double* y, const core::Vector& p, double* out) const override {
//       out[0] = y[0]; out[1] = -p[1] * y[1];
//     }
//   };
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/problem.hpp"
#include "core/stability/floquet.hpp"

namespace backbone::core {

struct HybridOrbitOptions {
  double relative_tolerance = 1e-12;  // CVODE rtol (absolute tolerances scale with the orbit)
  long max_steps = 1000000;           // CVODE steps per segment
  int max_events = 1000;              // events per period; more is refused (chattering)
  void validate() const;              // InputError("rtol" / "max_steps" / "max_events", ...)
};

// One event of a shot orbit.
struct HybridEvent {
  int which = 0;     // event index k
  double time = 0;   // in [0, T]
  Vector before;     // y-
  Vector after;      // y+ = g_k(y-)
  double speed = 0;  // D / |n|: the speed at which the orbit meets the surface (> 0)
};

// What one shot from y0 over the period found.
struct HybridShot {
  enum class Failure { none, period, integration, reset, grazing, too_many_events, lost_event };
  bool ok = false;
  Failure failure = Failure::none;
  std::string message;      // why not
  Vector end;               // y(T)
  Matrix monodromy;         // Phi(T) = dy(T)/dy0, n x n
  Vector parameter_column;  // dy(T)/dp_free at fixed T
  std::vector<HybridEvent> events;
  // Per event k: the largest value of h_k (times its direction, +1 for direction 0) at the
  // extrema between its crossings, the companion roots; -inf when there is none.
  std::vector<double> extremum;
  std::vector<double> extremum_time;  // where each was reached (NaN: none)
  double period = 0;
};

class HybridOrbitProblem : public Problem, public FloquetProblem {
 public:
  // n: state size (>= 1); parameter_names: the system's parameters, in the order p holds them
  // (at least one; values 0 until set_parameter).
  HybridOrbitProblem(int n, std::vector<std::string> parameter_names,
                     HybridOrbitOptions options = {});

  // --- the system (a subclass gives these) ---
  virtual void field(double t, const double* y, const Vector& p, double* dy) const = 0;
  // f_y (n x n); default: central differences of field.
  virtual void field_jacobian(double t, const double* y, const Vector& p, Matrix& J) const;
  // A forced system returns true and its forcing period (finite and > 0 at every p it is
  // evaluated at: check_guess refuses a guess where it is not); an autonomous one (the
  // default) has no forcing period and an unknown period.
  virtual bool forced() const { return false; }
  virtual double forcing_period(const Vector& p) const { return 0; }
  virtual int num_events() const { return 0; }
  virtual double event(int k, double t, const double* y, const Vector& p) const { return 0; }
  // +1: the event fires where h_k rises through 0 (the default), -1: falls, 0: both.
  virtual int event_direction(int k) const { return 1; }
  // y+ = g_k(y-; p); default: the identity (a switch without a jump).
  virtual void reset(int k, const double* y, const Vector& p, double* y_plus) const;
  // Whether the guess's orbit must meet event k (check_guess); default: every event.
  virtual bool event_required(int k) const { return true; }
  // Autonomous systems: the phase condition c(y0; p) = 0 that picks one point of the orbit.
  // Default: f_0(0, y0; p) = 0, the first component at an extremum (for y = (x, v): v0 = 0).
  virtual double phase_condition(const double* y0, const Vector& p) const;
  // Multipliers at +1 by construction and symplecticity (FloquetStructure); default: one for
  // an autonomous system, none for a forced one, not conservative.
  FloquetStructure floquet_structure() const override;

  // --- names of the observables ---
  // Default observables: period, every parameter by name, then event_count_name() (events per
  // period), event_speed_name() (the smallest event speed; NaN without events) and
  // event_gap_name() (the smallest gap between crossings; NaN without extrema).
  Observables observables(const Vector& x) const override;
  virtual std::string event_count_name() const { return "events_per_period"; }
  virtual std::string event_speed_name() const { return "event_speed"; }
  // The smallest distance -h_k at the extrema of h_k between crossings (NaN without any): 0 where
  // the orbit touches a surface it does not cross.
  virtual std::string event_gap_name() const { return "event_gap"; }
  std::vector<std::string> grazing_observables() const override;

  // --- parameters and layout ---
  int state_size() const { return n_; }
  const std::vector<std::string>& parameter_names() const { return names_; }
  const Vector& parameters() const { return parameters_; }
  // InputError naming the parameter when the name is unknown or the value not finite.
  void set_parameter(const std::string& name, double value);
  void set_free_parameter(const std::string& name);
  int free_parameter() const { return free_; }
  // The orbit spans this many forcing periods (forced systems; 1 by default, 2 on a branch
  // born at a period doubling). InputError("forcing_periods", ...) unless >= 1.
  void set_forcing_periods(int m);
  int forcing_periods() const { return periods_; }
  // p at x: parameters() with the free one read from x.
  Vector parameters_at(const Vector& x) const;
  // The orbit's period at x.
  double period_at(const Vector& x) const;
  int num_unknowns() const override;
  int num_equations() const override;
  const HybridOrbitOptions& options() const { return options_; }

  // One shot from x's y0 over its period (with variational equations). Cached: the last shot
  // is returned again for the same x (observables, monodromy and Jacobian after a residual).
  HybridShot shoot(const Vector& x) const;
  EvalStatus monodromy(const Vector& x, Matrix& M) const override;
  // An event switched off within a window of time: there its surface is crossed freely, and its
  // extrema are still recorded (HybridShot::extremum counts only those in the window).
  struct Suppression {
    int event = -1;  // -1: none
    double from = 0, to = 0;
    bool covers(int k, double t, double period) const;  // t, t +- period in [from, to]
  };
  // The shot with `suppressed`. Not cached.
  HybridShot shoot_without(const Vector& x, const Suppression& suppressed) const;
  // A copy (clone()) with forcing_periods() doubled for a forced system; an autonomous one's copy
  // as it is, the period being an unknown (doubled_unknowns doubles it). nullptr when the
  // subclass has no clone().
  std::unique_ptr<Problem> doubled_problem() const override;
  Vector doubled_unknowns(const Vector& x) const override;
  // Grazing orbits (GrazingOrbitProblem): for event_speed_name(), of the slowest event at x; for
  // event_gap_name(), of the extremum with the smallest gap; nullptr for another name or
  // without events.
  std::unique_ptr<Problem> grazing_problem(const std::string& observable,
                                           const Vector& x) const override;
  // Before any work: InputError when the guess cannot start a branch: a forcing period that is
  // not finite and > 0 (key "forcing_period"), a period <= 0 in an autonomous guess ("period"),
  // a required event that never fires over the guess's period ("event"), a reset that returns
  // NaN or Inf ("reset"), a field that does ("field").
  void check_guess(const Vector& x) const;

 protected:
  // A copy has the settings and no cached shot (a subclass's clone() uses it).
  HybridOrbitProblem(const HybridOrbitProblem& other);
  EvalStatus compute_residual(const Vector& x, Vector& r) const override;
  EvalStatus compute_jacobian(const Vector& x, Matrix& J) const override;
  // The monodromy with saltation (variational); a forced system's dT/dp, or an autonomous one's
  // phase row, by central differences.
  std::string jacobian_description() const override {
    return forced() ? "variational (the monodromy with saltation); dT/dp by central differences"
                    : "variational (the monodromy with saltation); the phase row by central "
                      "differences";
  }
  // A subclass that changes the system after construction calls this (the cache is stale).
  void forget_last_shot() const;

 private:
  HybridShot shoot_uncached(const Vector& x, const Suppression& suppressed) const;

  int n_;
  std::vector<std::string> names_;
  Vector parameters_;
  int free_ = 0;
  int periods_ = 1;
  HybridOrbitOptions options_;
  mutable std::mutex last_mutex_;
  mutable Vector last_x_;
  mutable HybridShot last_shot_;
};

// The orbits of a HybridOrbitProblem that graze the surface of one event: with that event off
// in a window of time around the grazing (from half-way to the orbit's neighbouring events, so
// that its other impacts still happen), the periodic orbit whose extremum of h_k in the window
// lies on the surface. Same unknowns as the base, one
// more equation, h_k at its extremum (the companion root, hybrid_orbit.hpp's header); a smooth
// problem where the base has no saltation matrix, so that a corrector converges to the grazing
// orbit itself. Finite-difference Jacobian. Observables: the base's, with that event counted
// once and its speed 0.
class GrazingOrbitProblem : public Problem {
 public:
  GrazingOrbitProblem(const HybridOrbitProblem& base, HybridOrbitProblem::Suppression window);
  int num_unknowns() const override { return base_.num_unknowns(); }
  int num_equations() const override { return base_.num_equations() + 1; }
  std::string name() const override { return base_.name() + " grazing"; }
  Observables observables(const Vector& x) const override;
  Vector typical_scale() const override { return base_.typical_scale(); }

 protected:
  EvalStatus compute_residual(const Vector& x, Vector& r) const override;

 private:
  const HybridOrbitProblem& base_;
  HybridOrbitProblem::Suppression window_;
};

}  // namespace backbone::core
