#include "core/orbits/hybrid_orbit.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "core/errors.hpp"
#include "core/jacobians/finite_difference.hpp"
#include "core/orbits/cvode_integrator.hpp"

namespace backbone::core {

namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();

// Central-difference step for a value z: cbrt(eps) max(|z|, 1), rounded so that z + h is exact
// (the step rule of finite_difference.hpp with a unit scale).
double central_step(double z) {
  return finite_difference_step(z, 1.0, std::cbrt(std::numeric_limits<double>::epsilon()));
}

// A segment is integrated again with steps below (time to the lost crossing) / this, at most
// max_redo times, before the shot is refused.
constexpr double redo_divisor = 8;
constexpr int max_redo = 12;

HybridShot failed(HybridShot::Failure why, std::string message) {
  HybridShot s;
  s.failure = why;
  s.message = std::move(message);
  return s;
}

}  // namespace

void HybridOrbitOptions::validate() const {
  if (!(relative_tolerance > 0 && relative_tolerance < 1e-3))
    throw InputError("rtol", fmt::format("must be in (0, 1e-3) (got {})", relative_tolerance));
  if (!(max_steps > 0))
    throw InputError("max_steps", fmt::format("must be > 0 (got {})", max_steps));
  if (!(max_events > 0 && max_events <= 1000000))
    throw InputError("max_events", fmt::format("must be in [1, 1e6] (got {})", max_events));
}

HybridOrbitProblem::HybridOrbitProblem(int n, std::vector<std::string> parameter_names,
                                       HybridOrbitOptions options)
    : n_(n), names_(std::move(parameter_names)), options_(options) {
  if (n < 1) throw InputError("dimension", fmt::format("must be >= 1 (got {})", n));
  if (names_.empty()) throw InputError("parameters", "a hybrid orbit problem needs a parameter");
  parameters_ = Vector::Zero(static_cast<Eigen::Index>(names_.size()));
  options_.validate();
}

HybridOrbitProblem::HybridOrbitProblem(const HybridOrbitProblem& other)
    : Problem(other),
      n_(other.n_),
      names_(other.names_),
      parameters_(other.parameters_),
      free_(other.free_),
      periods_(other.periods_),
      options_(other.options_) {}

std::unique_ptr<Problem> HybridOrbitProblem::doubled_problem() const {
  std::unique_ptr<Problem> copy = clone();
  auto* hybrid = dynamic_cast<HybridOrbitProblem*>(copy.get());
  if (!hybrid) return nullptr;
  if (forced()) hybrid->set_forcing_periods(2 * periods_);
  return copy;
}

Vector HybridOrbitProblem::doubled_unknowns(const Vector& x) const {
  Vector doubled = x;
  if (!forced()) doubled[n_] *= 2;
  return doubled;
}

void HybridOrbitProblem::field_jacobian(double t, const double* y, const Vector& p,
                                        Matrix& J) const {
  J.resize(n_, n_);
  Vector shifted = Eigen::Map<const Vector>(y, n_), plus(n_), minus(n_);
  for (int j = 0; j < n_; ++j) {
    const double h = central_step(y[j]);
    shifted[j] = y[j] + h;
    field(t, shifted.data(), p, plus.data());
    shifted[j] = y[j] - h;
    field(t, shifted.data(), p, minus.data());
    shifted[j] = y[j];
    J.col(j) = (plus - minus) / (2 * h);
  }
}

void HybridOrbitProblem::reset(int, const double* y, const Vector&, double* y_plus) const {
  std::copy(y, y + n_, y_plus);
}

double HybridOrbitProblem::phase_condition(const double* y0, const Vector& p) const {
  Vector f(n_);
  field(0.0, y0, p, f.data());
  return f[0];
}

FloquetStructure HybridOrbitProblem::floquet_structure() const {
  return {forced() ? 0 : 1, false};
}

std::vector<std::string> HybridOrbitProblem::grazing_observables() const {
  return num_events() > 0 ? std::vector<std::string>{event_speed_name(), event_gap_name()}
                          : std::vector<std::string>{};
}

void HybridOrbitProblem::set_parameter(const std::string& name, double value) {
  const auto it = std::find(names_.begin(), names_.end(), name);
  if (it == names_.end())
    throw InputError(name, fmt::format("is not a parameter of {} (its parameters: {})",
                                       this->name(), fmt::join(names_, ", ")));
  if (!std::isfinite(value)) throw InputError(name, fmt::format("must be finite (got {})", value));
  parameters_[it - names_.begin()] = value;
  forget_last_shot();
}

void HybridOrbitProblem::set_free_parameter(const std::string& name) {
  const auto it = std::find(names_.begin(), names_.end(), name);
  if (it == names_.end())
    throw InputError("continuation_parameter",
                     fmt::format("'{}' is not a parameter of {} (its parameters: {})", name,
                                 this->name(), fmt::join(names_, ", ")));
  free_ = static_cast<int>(it - names_.begin());
  forget_last_shot();
}

void HybridOrbitProblem::set_forcing_periods(int m) {
  if (!(m >= 1 && m <= 64))
    throw InputError("forcing_periods", fmt::format("must be in [1, 64] (got {})", m));
  periods_ = m;
  forget_last_shot();
}

int HybridOrbitProblem::num_unknowns() const {
  return n_ + (forced() ? 0 : 1) + 1;
}

int HybridOrbitProblem::num_equations() const {
  return n_ + (forced() ? 0 : 1);
}

Vector HybridOrbitProblem::parameters_at(const Vector& x) const {
  Vector p = parameters_;
  p[free_] = x[x.size() - 1];
  return p;
}

double HybridOrbitProblem::period_at(const Vector& x) const {
  return forced() ? periods_ * forcing_period(parameters_at(x)) : x[n_];
}

HybridShot HybridOrbitProblem::shoot(const Vector& x) const {
  {
    const std::lock_guard<std::mutex> lock(last_mutex_);
    if (last_x_.size() == x.size() && last_x_ == x) return last_shot_;
  }
  HybridShot shot = shoot_uncached(x, {});
  const std::lock_guard<std::mutex> lock(last_mutex_);
  last_x_ = x;
  last_shot_ = shot;
  return shot;
}

void HybridOrbitProblem::forget_last_shot() const {
  const std::lock_guard<std::mutex> lock(last_mutex_);
  last_x_.resize(0);
}

bool HybridOrbitProblem::Suppression::covers(int k, double t, double period) const {
  if (k != event) return false;
  for (const double s : {t, t + period, t - period})
    if (s >= from && s <= to) return true;
  return false;
}

HybridShot HybridOrbitProblem::shoot_without(const Vector& x, const Suppression& suppressed) const {
  return shoot_uncached(x, suppressed);
}

namespace {

// One shot's fixed data and steps: the parameters (and their central-difference neighbours in
// the free one), the period, the switched-off window; the right-hand side with the variational
// equations, the root functions with their companions, and what happens at a root.
class Shot {
 public:
  Shot(const HybridOrbitProblem& problem, const Vector& x,
       const HybridOrbitProblem::Suppression& suppressed)
      : problem_(problem),
        n_(problem.state_size()),
        K_(problem.num_events()),
        p_(problem.parameters_at(x)),
        T_(problem.period_at(x)),
        suppressed_(suppressed) {
    const int free = problem.free_parameter();
    dp_ = central_step(p_[free]);
    p_plus_ = p_minus_ = p_;
    p_plus_[free] += dp_;
    p_minus_[free] -= dp_;
  }
  double period() const { return T_; }

  // Y = [y | Phi (column-major) | psi]; each call works in its own copies (concurrent shots
  // share nothing).
  OdeRightHandSide rhs() const {
    return [&problem = problem_, n = n_, p = p_, p_plus = p_plus_, p_minus = p_minus_, dp = dp_,
            A = Matrix(n_, n_), fp = Vector(n_),
            fm = Vector(n_)](double t, const double* s, double* ds) mutable {
      problem.field(t, s, p, ds);
      problem.field_jacobian(t, s, p, A);
      const Eigen::Map<const Matrix> Phi(s + n, n, n);
      const Eigen::Map<const Vector> psi(s + n + n * n, n);
      Eigen::Map<Matrix>(ds + n, n, n).noalias() = A * Phi;
      problem.field(t, s, p_plus, fp.data());
      problem.field(t, s, p_minus, fm.data());
      Eigen::Map<Vector>(ds + n + n * n, n).noalias() = A * psi + (fp - fm) / (2 * dp);
    };
  }

  // Roots 0..K-1: the events; K..2K-1: their companions, dh/dt along the flow (header).
  OdeRootFunctions roots() const {
    const double step = central_step(T_);
    return [&problem = problem_, n = n_, K = K_, p = p_, T = T_, step, suppressed = suppressed_,
            f = Vector(n_), ahead = Vector(n_),
            behind = Vector(n_)](double t, const double* s, double* g) mutable {
      problem.field(t, s, p, f.data());
      const Eigen::Map<const Vector> y(s, n);
      ahead = y + step * f;
      behind = y - step * f;
      for (int k = 0; k < K; ++k) {
        // A switched-off event stays on its near side (no change of sign at the window's ends,
        // where the orbit is away from the surface).
        g[k] = suppressed.covers(k, t, T) ? -(problem.event_direction(k) < 0 ? -1.0 : 1.0)
                                          : problem.event(k, t, s, p);
        g[K + k] = (problem.event(k, t + step, ahead.data(), p) -
                    problem.event(k, t - step, behind.data(), p)) /
                   (2 * step);
      }
    };
  }

  std::vector<int> directions() const {
    std::vector<int> d(2 * K_);
    for (int k = 0; k < K_; ++k) {
      d[k] = problem_.event_direction(k);
      d[K_ + k] = -problem_.event_direction(k);
    }
    return d;
  }

  // An extremum of h_k found on the far side of its surface by a segment that started on the near
  // side (one that starts on the surface, after an event, may reach beyond it: a switch without a
  // jump): a crossing was stepped over.
  bool crossing_lost(const std::vector<int>& found, double t, const Vector& Y, double t_start,
                     const Vector& start) const {
    for (int r : found) {
      if (r < K_ || suppressed_.covers(r - K_, t, T_)) continue;
      const int k = r - K_, dir = problem_.event_direction(k);
      const double h = problem_.event(k, t, Y.data(), p_);
      const double h0 = problem_.event(k, t_start, start.data(), p_);
      if ((dir > 0 && h0 < 0 && h > 0) || (dir < 0 && h0 > 0 && h < 0) || (dir == 0 && h * h0 < 0))
        return true;
    }
    return false;
  }

  void record_extrema(const std::vector<int>& found, double t, const Vector& Y,
                      HybridShot& shot) const {
    for (int r : found) {
      if (r < K_) continue;
      const int k = r - K_;
      const double h =
          (problem_.event_direction(k) < 0 ? -1.0 : 1.0) * problem_.event(k, t, Y.data(), p_);
      if ((suppressed_.event < 0 || suppressed_.covers(k, t, T_)) && h > shot.extremum[k]) {
        shot.extremum[k] = h;
        shot.extremum_time[k] = t;
      }
    }
  }

  // Event k at t: the reset, and the saltation of Phi and psi (header). Empty on success, else
  // the failed shot.
  std::optional<HybridShot> apply_event(int k, double t, Vector& Y, HybridShot& shot) const;

 private:
  // n = dh_k/dy and dh_k/dt at (t, y), central differences.
  void event_gradient(int k, double t, const Vector& y, Vector& n, double& dh_dt) const;

  const HybridOrbitProblem& problem_;
  int n_, K_;
  Vector p_, p_plus_, p_minus_;
  double dp_ = 0, T_;
  HybridOrbitProblem::Suppression suppressed_;
};

void Shot::event_gradient(int k, double t, const Vector& y, Vector& n, double& dh_dt) const {
  n.resize(n_);
  Vector shifted = y;
  for (int j = 0; j < n_; ++j) {
    const double h = central_step(y[j]);
    shifted[j] = y[j] + h;
    const double plus = problem_.event(k, t, shifted.data(), p_);
    shifted[j] = y[j] - h;
    const double minus = problem_.event(k, t, shifted.data(), p_);
    shifted[j] = y[j];
    n[j] = (plus - minus) / (2 * h);
  }
  const double h = central_step(t);
  dh_dt =
      (problem_.event(k, t + h, y.data(), p_) - problem_.event(k, t - h, y.data(), p_)) / (2 * h);
}

std::optional<HybridShot> Shot::apply_event(int k, double t, Vector& Y, HybridShot& shot) const {
  const int n = n_;
  const Vector y_minus = Y.head(n);
  Vector f_minus(n), f_plus(n), normal, y_plus(n), g_plus(n), g_minus(n);
  problem_.field(t, y_minus.data(), p_, f_minus.data());
  double dh_dt = 0;
  event_gradient(k, t, y_minus, normal, dh_dt);
  const double D = dh_dt + normal.dot(f_minus);
  const double speed = std::abs(D) / std::max(normal.norm(), 1e-300);
  if (!(speed > 0) || !std::isfinite(speed))
    return failed(HybridShot::Failure::grazing,
                  fmt::format("event {} is met tangentially at t = {} (grazing)", k, t));
  problem_.reset(k, y_minus.data(), p_, y_plus.data());
  if (!y_plus.allFinite())
    return failed(HybridShot::Failure::reset,
                  fmt::format("reset {} returned NaN or Inf at t = {}", k, t));
  // G = dg/dy and g_p, h_p by central differences.
  Matrix G(n, n);
  Vector shifted = y_minus;
  for (int j = 0; j < n; ++j) {
    const double h = central_step(y_minus[j]);
    shifted[j] = y_minus[j] + h;
    problem_.reset(k, shifted.data(), p_, g_plus.data());
    shifted[j] = y_minus[j] - h;
    problem_.reset(k, shifted.data(), p_, g_minus.data());
    shifted[j] = y_minus[j];
    G.col(j) = (g_plus - g_minus) / (2 * h);
  }
  problem_.reset(k, y_minus.data(), p_plus_, g_plus.data());
  problem_.reset(k, y_minus.data(), p_minus_, g_minus.data());
  const Vector g_p = (g_plus - g_minus) / (2 * dp_);
  const double h_p = (problem_.event(k, t, y_minus.data(), p_plus_) -
                      problem_.event(k, t, y_minus.data(), p_minus_)) /
                     (2 * dp_);
  problem_.field(t, y_plus.data(), p_, f_plus.data());
  const Vector w = f_plus - G * f_minus;
  const Matrix S = G + w * normal.transpose() / D;
  Eigen::Map<Matrix> Phi(Y.data() + n, n, n);
  Eigen::Map<Vector> psi(Y.data() + n + n * n, n);
  Phi = (S * Phi).eval();
  psi = (S * psi + g_p + w * (h_p / D)).eval();
  Y.head(n) = y_plus;
  shot.events.push_back({k, t, y_minus, y_plus, speed});
  return std::nullopt;
}

}  // namespace

HybridShot HybridOrbitProblem::shoot_uncached(const Vector& x,
                                              const Suppression& suppressed) const {
  const int n = n_, K = num_events();
  if (x.size() != num_unknowns() || !x.allFinite())
    return failed(HybridShot::Failure::period, "the unknowns are not finite");
  const Shot step(*this, x, suppressed);
  const double T = step.period();
  if (!(T > 0) || !std::isfinite(T))
    return failed(HybridShot::Failure::period,
                  fmt::format("the period is not finite and > 0 (got {})", T));
  const int size = n + n * n + n;
  Vector Y = Vector::Zero(size);
  Y.head(n) = x.head(n);
  Eigen::Map<Matrix>(Y.data() + n, n, n).setIdentity();
  CvodeOptions cvode;
  cvode.relative_tolerance = options_.relative_tolerance;
  cvode.max_steps = options_.max_steps;
  cvode.absolute_tolerance = Vector::Constant(size, 1e-3 * options_.relative_tolerance);
  const double amplitude = std::max(x.head(n).lpNorm<Eigen::Infinity>(), 1e-300);
  cvode.absolute_tolerance.head(n).setConstant(1e-3 * options_.relative_tolerance * amplitude);
  const OdeRightHandSide rhs = step.rhs();
  const OdeRootFunctions roots = step.roots();
  const std::vector<int> directions = step.directions();

  HybridShot shot;
  shot.period = T;
  shot.extremum.assign(K, -std::numeric_limits<double>::infinity());
  shot.extremum_time.assign(K, nan);
  double t = 0;
  int redo = 0;
  while (true) {
    const Vector start = Y;
    const double t_start = t;
    const SegmentResult seg = integrate_to_event(rhs, roots, directions, Y, t, T, cvode);
    if (!seg.ok) return failed(HybridShot::Failure::integration, seg.message);
    t = seg.t;
    if (seg.roots.empty()) break;
    if (step.crossing_lost(seg.roots, t, Y, t_start, start)) {
      if (++redo > max_redo)
        return failed(HybridShot::Failure::lost_event,
                      fmt::format("an event crossed twice within a step near t = {}", t));
      Y = start;
      cvode.max_step = (t - t_start) / redo_divisor;
      t = t_start;
      continue;
    }
    cvode.max_step = 0;
    step.record_extrema(seg.roots, t, Y, shot);
    for (int k : seg.roots) {
      if (k >= K) continue;
      if (static_cast<int>(shot.events.size()) >= options_.max_events)
        return failed(
            HybridShot::Failure::too_many_events,
            fmt::format("more than {} events in a period (max_events)", options_.max_events));
      if (auto failure = step.apply_event(k, t, Y, shot)) return *failure;
    }
    if (!(t < T)) break;
  }
  shot.end = Y.head(n);
  shot.monodromy = Eigen::Map<const Matrix>(Y.data() + n, n, n);
  shot.parameter_column = Y.tail(n);
  shot.ok = shot.end.allFinite() && shot.monodromy.allFinite();
  if (!shot.ok) return failed(HybridShot::Failure::integration, "the orbit became NaN or Inf");
  return shot;
}

EvalStatus HybridOrbitProblem::compute_residual(const Vector& x, Vector& r) const {
  const HybridShot shot = shoot(x);
  if (!shot.ok) return EvalStatus::failed;
  r.resize(num_equations());
  r.head(n_) = shot.end - x.head(n_);
  if (!forced()) r[n_] = phase_condition(x.data(), parameters_at(x));
  return EvalStatus::ok;
}

EvalStatus HybridOrbitProblem::compute_jacobian(const Vector& x, Matrix& J) const {
  const HybridShot shot = shoot(x);
  if (!shot.ok) return EvalStatus::failed;
  const int n = n_;
  const Vector p = parameters_at(x);
  J = Matrix::Zero(num_equations(), num_unknowns());
  J.topLeftCorner(n, n) = shot.monodromy - Matrix::Identity(n, n);
  Vector f_end(n);
  field(shot.period, shot.end.data(), p, f_end.data());
  const int last = num_unknowns() - 1;
  if (forced()) {
    // y(T(p); p): the period moves with the parameter when the forcing does.
    const double h = central_step(p[free_]);
    Vector plus = p, minus = p;
    plus[free_] += h;
    minus[free_] -= h;
    const double dT_dp = periods_ * (forcing_period(plus) - forcing_period(minus)) / (2 * h);
    J.col(last) = shot.parameter_column + f_end * dT_dp;
    return EvalStatus::ok;
  }
  J.block(0, n, n, 1) = f_end;
  J.block(0, last, n, 1) = shot.parameter_column;
  Vector y = x.head(n);
  for (int j = 0; j < n; ++j) {
    const double h = central_step(y[j]);
    y[j] = x[j] + h;
    const double plus = phase_condition(y.data(), p);
    y[j] = x[j] - h;
    const double minus = phase_condition(y.data(), p);
    y[j] = x[j];
    J(n, j) = (plus - minus) / (2 * h);
  }
  const double h = central_step(p[free_]);
  Vector plus = p, minus = p;
  plus[free_] += h;
  minus[free_] -= h;
  J(n, last) = (phase_condition(y.data(), plus) - phase_condition(y.data(), minus)) / (2 * h);
  return EvalStatus::ok;
}

EvalStatus HybridOrbitProblem::monodromy(const Vector& x, Matrix& M) const {
  const HybridShot shot = shoot(x);
  if (!shot.ok) return EvalStatus::failed;
  M = shot.monodromy;
  return EvalStatus::ok;
}

Observables HybridOrbitProblem::observables(const Vector& x) const {
  Observables o;
  o.emplace_back("period", period_at(x));
  const Vector p = parameters_at(x);
  for (std::size_t i = 0; i < names_.size(); ++i) o.emplace_back(names_[i], p[i]);
  const HybridShot shot = shoot(x);
  double speed = nan;
  for (const HybridEvent& e : shot.events)
    speed = std::isnan(speed) ? e.speed : std::min(speed, e.speed);
  o.emplace_back(event_count_name(), shot.ok ? static_cast<double>(shot.events.size()) : nan);
  o.emplace_back(event_speed_name(), shot.ok ? speed : nan);
  double gap = nan;
  for (const double e : shot.extremum)
    if (std::isfinite(e)) gap = std::isnan(gap) ? -e : std::min(gap, -e);
  o.emplace_back(event_gap_name(), shot.ok ? gap : nan);
  return o;
}

void HybridOrbitProblem::check_guess(const Vector& x) const {
  if (x.size() != num_unknowns())
    throw InputError("guess",
                     fmt::format("has {} entries for {} unknowns", x.size(), num_unknowns()));
  if (!x.allFinite()) throw InputError("guess", "contains NaN or Inf");
  const Vector p = parameters_at(x);
  if (forced()) {
    const double T = forcing_period(p);
    if (!(T > 0) || !std::isfinite(T))
      throw InputError("forcing_period",
                       fmt::format("must be finite and > 0 (got {} at the guess)", T));
  } else if (!(x[n_] > 0) || !std::isfinite(x[n_])) {
    throw InputError("period", fmt::format("must be finite and > 0 (got {})", x[n_]));
  }
  const HybridShot shot = shoot(x);
  if (shot.failure == HybridShot::Failure::reset) throw InputError("reset", shot.message);
  if (shot.failure == HybridShot::Failure::integration)
    throw InputError("field",
                     fmt::format("the guess's orbit cannot be integrated: {}", shot.message));
  if (!shot.ok) return;  // a numerical failure: the corrector may still move off it
  for (int k = 0; k < num_events(); ++k) {
    if (!event_required(k)) continue;
    const bool fired = std::any_of(shot.events.begin(), shot.events.end(),
                                   [k](const HybridEvent& e) { return e.which == k; });
    if (!fired)
      throw InputError("event", fmt::format("event {} never fires over the guess's period {} "
                                            "(the orbit from the guess does not reach its "
                                            "surface)",
                                            k, shot.period));
  }
}

std::unique_ptr<Problem> HybridOrbitProblem::grazing_problem(const std::string& observable,
                                                             const Vector& x) const {
  if (num_events() == 0) return nullptr;
  const HybridShot shot = shoot(x);
  if (!shot.ok) return nullptr;
  int event = -1;
  double time = nan;
  const HybridEvent* slowest = nullptr;
  if (observable == event_speed_name()) {
    if (shot.events.empty()) return nullptr;
    slowest = &*std::min_element(
        shot.events.begin(), shot.events.end(),
        [](const HybridEvent& a, const HybridEvent& b) { return a.speed < b.speed; });
    event = slowest->which;
    time = slowest->time;
  } else if (observable == event_gap_name()) {
    for (int k = 0; k < num_events(); ++k)
      if (std::isfinite(shot.extremum[k]) && (event < 0 || shot.extremum[k] > shot.extremum[event]))
        event = k;
    if (event < 0) return nullptr;
    time = shot.extremum_time[event];
  } else {
    return nullptr;
  }
  // Half-way to the nearest other event (over the period's wrap), a quarter period without one.
  double half_gap = shot.period / 4;
  for (const HybridEvent& e : shot.events) {
    if (&e == slowest) continue;
    const double gap = std::abs(e.time - time);
    half_gap = std::min(half_gap, 0.5 * std::min(gap, shot.period - gap));
  }
  return std::make_unique<GrazingOrbitProblem>(
      *this, Suppression{event, time - half_gap, time + half_gap});
}

GrazingOrbitProblem::GrazingOrbitProblem(const HybridOrbitProblem& base,
                                         HybridOrbitProblem::Suppression window)
    : base_(base), window_(window) {}

EvalStatus GrazingOrbitProblem::compute_residual(const Vector& x, Vector& r) const {
  const HybridShot shot = base_.shoot_without(x, window_);
  if (!shot.ok || !std::isfinite(shot.extremum[window_.event])) return EvalStatus::failed;
  const int n = base_.state_size();
  r.resize(num_equations());
  r.head(n) = shot.end - x.head(n);
  if (!base_.forced()) r[n] = base_.phase_condition(x.data(), base_.parameters_at(x));
  r[num_equations() - 1] = shot.extremum[window_.event];
  return EvalStatus::ok;
}

Observables GrazingOrbitProblem::observables(const Vector& x) const {
  const HybridShot shot = base_.shoot_without(x, window_);
  Observables o;
  o.emplace_back("period", base_.period_at(x));
  const Vector p = base_.parameters_at(x);
  for (std::size_t i = 0; i < base_.parameter_names().size(); ++i)
    o.emplace_back(base_.parameter_names()[i], p[static_cast<Eigen::Index>(i)]);
  o.emplace_back(base_.event_count_name(),
                 shot.ok ? static_cast<double>(shot.events.size() + 1) : nan);
  o.emplace_back(base_.event_speed_name(), 0.0);
  o.emplace_back(base_.event_gap_name(), 0.0);
  return o;
}

}  // namespace backbone::core
