#include "problems/fem_bar/fem.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "core/errors.hpp"

namespace backbone::fem_bar {

using core::InputError;

namespace {

// Central-difference march on the uniform grid. State: u_prev = u_{n-1}, u = u_n; step()
// computes u_next = u_{n+1} and the contact multipliers lambda_n of both ends.
class CentralDifference {
 public:
  CentralDifference(const bar::BarSetup& setup, int elements, double dt)
      : setup_(setup), elements_(elements), dt_(dt) {
    const bar::Material& m = setup.material;
    h_ = m.length / elements;
    stiffness_ = m.axial_stiffness() / h_;
    const std::size_t nodes = static_cast<std::size_t>(elements) + 1;
    mass_.assign(nodes, m.density * m.area * h_);
    load_.assign(nodes, setup.body_force * m.area * h_);  // consistent = lumped for constant b
    mass_.front() *= 0.5;
    mass_.back() *= 0.5;
    load_.front() *= 0.5;
    load_.back() *= 0.5;
    u_.resize(nodes);
    std::vector<double> v(nodes);
    for (std::size_t i = 0; i < nodes; ++i) {
      u_[i] = setup.u0(x(i));
      v[i] = setup.v0(x(i));
    }
    if (setup.left.type == bar::EndType::fixed) v.front() = 0;
    if (setup.right.type == bar::EndType::fixed) v.back() = 0;
    // Fictitious u_{-1} = u_0 - dt v_0 + dt^2 / 2 a_0 (a_0 without contact): the first step is
    // then u_1 = u_0 + dt v_0 + dt^2 / 2 a_0, the Taylor start-up.
    accelerations(u_, acc_);
    u_prev_.resize(nodes);
    for (std::size_t i = 0; i < nodes; ++i)
      u_prev_[i] = u_[i] - dt_ * v[i] + 0.5 * dt_ * dt_ * acc_[i];
    u_next_.resize(nodes);
  }

  double x(std::size_t i) const {
    return i == static_cast<std::size_t>(elements_) ? setup_.material.length
                                                    : static_cast<double>(i) * h_;
  }
  std::size_t nodes() const { return u_.size(); }

  // u_{n+1} from u_n, u_{n-1}; the contact multipliers of step n.
  void step() {
    accelerations(u_, acc_);
    const double dt2 = dt_ * dt_;
    const std::size_t last = u_.size() - 1;
    for (std::size_t i = 0; i <= last; ++i) u_next_[i] = 2 * u_[i] - u_prev_[i] + dt2 * acc_[i];
    lambda_left_ = apply_end(setup_.left, 0, -1.0);
    lambda_right_ = apply_end(setup_.right, last, +1.0);
  }

  // After step(): u_prev <- u, u <- u_next.
  void advance() {
    std::swap(u_prev_, u_);
    std::swap(u_, u_next_);
  }

  const std::vector<double>& u() const { return u_; }
  const std::vector<double>& u_prev() const { return u_prev_; }
  const std::vector<double>& u_next() const { return u_next_; }
  double lambda_left() const { return lambda_left_; }
  double lambda_right() const { return lambda_right_; }
  double h() const { return h_; }
  const std::vector<double>& mass() const { return mass_; }

  // Nodal velocity at t_n (valid after step()): (u_{n+1} - u_{n-1}) / (2 dt).
  double velocity(std::size_t i) const { return (u_next_[i] - u_prev_[i]) / (2 * dt_); }

  // Kinetic (lumped mass) + strain + body-force potential at t_n (valid after step()).
  double energy() const {
    double kinetic = 0, strain = 0, potential = 0;
    for (std::size_t i = 0; i < u_.size(); ++i) {
      const double v = velocity(i);
      kinetic += mass_[i] * v * v;
      potential += load_[i] * u_[i];
      if (i + 1 < u_.size()) strain += (u_[i + 1] - u_[i]) * (u_[i + 1] - u_[i]);
    }
    return 0.5 * kinetic + 0.5 * stiffness_ * strain - potential;
  }

  bool finite() const {
    return std::all_of(u_next_.begin(), u_next_.end(), [](double w) { return std::isfinite(w); });
  }

 private:
  // a = M^{-1} (f - K u), with zero acceleration at fixed ends.
  void accelerations(const std::vector<double>& u, std::vector<double>& a) const {
    const std::size_t last = u.size() - 1;
    a.resize(u.size());
    a[0] = (load_[0] - stiffness_ * (u[0] - u[1])) / mass_[0];
    for (std::size_t i = 1; i < last; ++i)
      a[i] = (load_[i] - stiffness_ * (2 * u[i] - u[i - 1] - u[i + 1])) / mass_[i];
    a[last] = (load_[last] - stiffness_ * (u[last] - u[last - 1])) / mass_[last];
    if (setup_.left.type == bar::EndType::fixed) a[0] = 0;
    if (setup_.right.type == bar::EndType::fixed) a[last] = 0;
  }

  // Fixed: u = 0. Contact: forward-increment multiplier if the prediction penetrates.
  double apply_end(const bar::End& end, std::size_t node, double normal) {
    if (end.type == bar::EndType::fixed) {
      u_next_[node] = 0;
      return 0;
    }
    if (!end.has_wall()) return 0;
    const double penetration = normal * u_next_[node] - end.gap;
    if (penetration > 0) {
      u_next_[node] = normal * end.gap;
      return mass_[node] * penetration / (dt_ * dt_);
    }
    // The back wall of a clearance end: the same projection from the other side; the
    // multiplier is tensile (negative compressive force).
    const double behind = -normal * u_next_[node] - end.gap_back;
    if (!end.has_back_wall() || !(behind > 0)) return 0;
    u_next_[node] = -normal * end.gap_back;
    return -mass_[node] * behind / (dt_ * dt_);
  }

  const bar::BarSetup& setup_;
  int elements_;
  double dt_;
  double h_ = 0, stiffness_ = 0;
  std::vector<double> mass_, load_;
  std::vector<double> u_prev_, u_, u_next_, acc_;
  double lambda_left_ = 0, lambda_right_ = 0;
};

void check_setup(const bar::BarSetup& setup) {
  setup.validate();
  const double L = setup.material.length;
  double scale = 0;
  for (double y : setup.u0.values()) scale = std::max(scale, std::abs(y));
  scale = std::max(
      {scale, setup.left.gap, setup.right.gap, setup.left.gap_back, setup.right.gap_back, 1e-300});
  auto check_fixed = [&](const bar::End& end, double x, const char* which) {
    if (end.type == bar::EndType::fixed && std::abs(setup.u0(x)) > 1e-12 * scale)
      throw InputError("u0", fmt::format("u0 = {} at the fixed {} end (x = {}) must be 0",
                                         setup.u0(x), which, x));
  };
  check_fixed(setup.left, 0.0, "left");
  check_fixed(setup.right, L, "right");
}

void check_stability(const bar::BarSetup& setup, int elements, double dt) {
  const double limit = FemBarSolver::stable_time_step(setup, elements);
  // A relative slack of 1e-12 lets dt = dx / c computed by the caller through.
  if (dt > limit * (1 + 1e-12))
    throw InputError("dt", fmt::format("central differences are unstable for dt = {} > dx / c = {} "
                                       "on {} elements",
                                       dt, limit, elements));
}

// Consistent: h/6 (w_{i-1} + 4 w_i + w_{i+1}) (h/6 (2 w_0 + w_1) at the ends); lumped: h w_i.
std::vector<double> project(const std::vector<double>& w, double h, Projection projection) {
  const std::size_t n = w.size();
  std::vector<double> p(n);
  if (projection == Projection::lumped) {
    for (std::size_t i = 0; i < n; ++i) p[i] = h * w[i];
    p.front() *= 0.5;
    p.back() *= 0.5;
    return p;
  }
  for (std::size_t i = 0; i < n; ++i) {
    double s = 0;
    if (i > 0) s += 2 * w[i] + w[i - 1];
    if (i + 1 < n) s += 2 * w[i] + w[i + 1];
    p[i] = h / 6 * s;
  }
  return p;
}

// A march to t in equal steps no longer than dt: n = ceil(t / dt) steps of t / n, where a t / dt
// within 1e-12 of an integer counts as that integer and keeps dt itself (the grid n dt, and the
// exactness of Courant 1, are then unchanged).
struct March {
  long steps = 0;
  double dt = 0;
};
March march_to(double t, double dt) {
  if (t == 0) return {0, dt};
  const long steps = std::max(1L, static_cast<long>(std::ceil(t / dt * (1 - 1e-12))));
  const bool on_grid = std::abs(static_cast<double>(steps) * dt - t) <= 1e-12 * t;
  return {steps, on_grid ? dt : t / static_cast<double>(steps)};
}

}  // namespace

double FemBarSolver::stable_time_step(const bar::BarSetup& setup, int elements) {
  return setup.material.length / elements / setup.material.wave_speed();
}

bar::History FemBarSolver::simulate(const bar::BarSetup& setup,
                                    const bar::SimulationOptions& options) const {
  check_setup(setup);
  options.validate();
  check_stability(setup, options.elements, options.dt);
  const double L = setup.material.length;
  for (double p : options.probes)
    if (p < 0 || p > L)
      throw InputError("probes", fmt::format("probe x = {} lies outside [0, {}]", p, L));

  const March plan = march_to(options.t_end, options.dt);
  const long steps = plan.steps;
  const long rows = std::min<long>(options.history_samples, steps + 1);
  const bool right = setup.observed_end_is_right();

  bar::History history;
  history.probes = options.probes;
  history.probe_u.resize(options.probes.size());
  CentralDifference march(setup, options.elements, plan.dt);
  const double h = march.h();
  const std::size_t last = march.nodes() - 1;
  long next_row = 0;  // index of the next recorded row; step of row k: round(k steps / (rows-1))
  auto row_step = [&](long k) {
    return rows == 1 ? 0L
                     : std::lround(static_cast<double>(k) * static_cast<double>(steps) /
                                   static_cast<double>(rows - 1));
  };
  for (long n = 0; n <= steps && next_row < rows; ++n) {
    march.step();
    if (!march.finite()) break;
    if (n == row_step(next_row)) {
      const auto& u = march.u();
      history.t.push_back(n == steps ? options.t_end : static_cast<double>(n) * plan.dt);
      history.u_contact.push_back(right ? u[last] : u[0]);
      history.contact_force.push_back(right ? march.lambda_right() : march.lambda_left());
      if (options.energy) history.energy.push_back(march.energy());
      for (std::size_t k = 0; k < options.probes.size(); ++k) {
        const double s = options.probes[k] / h;
        const std::size_t i = std::min(static_cast<std::size_t>(s), last - 1);
        const double w = s - static_cast<double>(i);
        history.probe_u[k].push_back((1 - w) * u[i] + w * u[i + 1]);
      }
      ++next_row;
    }
    march.advance();
  }
  return history;
}

bar::FieldSnapshot FemBarSolver::snapshot(const bar::BarSetup& setup, double t,
                                          const bar::SnapshotRequest& request) const {
  check_setup(setup);
  if (!std::isfinite(t) || t < 0) throw InputError("t", fmt::format("must be >= 0 (got {})", t));
  if (request.elements < 1)
    throw InputError("elements", fmt::format("must be >= 1 (got {})", request.elements));
  if (!request.nodes.empty())
    throw InputError("nodes", "fem: snapshots on the uniform mesh of `elements` only");
  if (!std::isfinite(request.dt) || !(request.dt > 0))
    throw InputError("dt", fmt::format("must be > 0 (got {})", request.dt));
  check_stability(setup, request.elements, request.dt);

  const March plan = march_to(t, request.dt);
  const long steps = plan.steps;
  const double dt = plan.dt;
  CentralDifference march(setup, request.elements, dt);
  bar::FieldSnapshot snap;
  snap.t = t;
  for (std::size_t i = 0; i < march.nodes(); ++i) snap.x.push_back(march.x(i));
  for (long n = 0; n <= steps; ++n) {
    march.step();  // the last step only gives u_{n+1} for the velocity at t_n
    if (!march.finite()) {
      snap.ok = false;
      snap.message = fmt::format("non-finite displacement at t = {} (step {} of dt = {})",
                                 static_cast<double>(n + 1) * dt, n + 1, dt);
      return snap;
    }
    if (n < steps) march.advance();
  }
  std::vector<double> v(march.nodes());
  for (std::size_t i = 0; i < march.nodes(); ++i) v[i] = march.velocity(i);
  if (request.nodal_u) snap.u = march.u();
  if (request.nodal_v) snap.v = v;
  if (request.projected_u) snap.u_projected = project(march.u(), march.h(), options_.projection);
  if (request.projected_v) snap.v_projected = project(v, march.h(), options_.projection);
  return snap;
}

}  // namespace backbone::fem_bar
