#include "problems/contact_bar/orbits/monodromy.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <optional>
#include <random>
#include <vector>

#include "core/errors.hpp"
#include "core/job_queue.hpp"
#include "problems/contact_bar/orbits/periodic_bar.hpp"
#include "problems/contact_bar/solver/tdbem.hpp"
#include "problems/exact_bar/exact_solution.hpp"

namespace backbone::contact_bar {

using core::EvalStatus;
using core::Matrix;
using core::Vector;

MonodromyOptions::Representation parse_representation(const std::string& key,
                                                      const std::string& value) {
  if (value == "fronts") return MonodromyOptions::Representation::fronts;
  if (value == "grid") return MonodromyOptions::Representation::grid;
  throw core::InputError(key, fmt::format("must be fronts or grid (got '{}')", value));
}

namespace {

// The orbit x simulated by the exact solver and its state at a time of free flight
// (exact_bar::free_flight_state); t0 NaN with the reason in `why`.
exact_bar::OrbitState orbit_free_flight_state(const bar::BarSetup& setup, double period,
                                              std::string& why) {
  const exact_bar::ExactBarSolution orbit(setup, period);
  if (!orbit.ok()) {
    why = orbit.message();
    return {std::numeric_limits<double>::quiet_NaN(), {}};
  }
  exact_bar::OrbitState start = exact_bar::free_flight_state(orbit, period);
  if (std::isnan(start.t0)) why = "the end is on a wall at every sampled time";
  return start;
}

}  // namespace

exact_bar::FrontMonodromy orbit_front_monodromy(const ContactBarOrbitProblem& problem,
                                                const core::Vector& x) {
  exact_bar::FrontMonodromy out;
  const double period = problem.period(x);
  try {
    const bar::BarSetup setup = problem.setup_at(x);
    const exact_bar::OrbitState start = orbit_free_flight_state(setup, period, out.message);
    if (std::isnan(start.t0)) return out;
    return exact_bar::front_monodromy(setup, start.state, period);
  } catch (const core::InputError& e) {
    out.message = e.what();
    return out;
  }
}

TdbemFronts orbit_tdbem_front_monodromy(const ContactBarOrbitProblem& problem,
                                        const core::Vector& x) {
  TdbemFronts out;
  const auto* tdbem = dynamic_cast<const TdbemSolver*>(&problem.solver());
  if (!tdbem || tdbem->method() != ContactMethod::event) {
    out.message = "the problem's solver is not the TD-BEM's event march";
    return out;
  }
  const double period = problem.period(x);
  try {
    const bar::BarSetup setup = problem.setup_at(x);
    const exact_bar::OrbitState start = orbit_free_flight_state(setup, period, out.message);
    if (std::isnan(start.t0)) return out;
    return tdbem_front_monodromy(setup, start.t0, period, problem.time_step(period));
  } catch (const core::InputError& e) {
    out.message = e.what();
    return out;
  }
}

int jordan_defect(const Eigen::MatrixXd& K) {
  Eigen::VectorXcd mu;
  return front_eigenvalues(K, mu) ? jordan_defect(K, mu) : -1;
}

int jordan_defect(const Eigen::MatrixXd& K, const Eigen::VectorXcd& mu) {
  const auto n = K.rows();
  if (n == 0) return 0;
  const double scale = std::max(1.0, K.cwiseAbs().maxCoeff());
  std::vector<bool> done(static_cast<std::size_t>(n), false);
  int defect = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (done[static_cast<std::size_t>(i)]) continue;
    std::complex<double> mean = 0;
    int algebraic = 0;
    for (Eigen::Index j = i; j < n; ++j)
      if (!done[static_cast<std::size_t>(j)] && std::abs(mu[j] - mu[i]) <= 1e-4 * scale) {
        done[static_cast<std::size_t>(j)] = true;
        mean += mu[j];
        ++algebraic;
      }
    mean /= static_cast<double>(algebraic);
    const Eigen::MatrixXcd shifted =
        K.cast<std::complex<double>>() - mean * Eigen::MatrixXcd::Identity(n, n);
    const Eigen::VectorXd sigma = Eigen::JacobiSVD<Eigen::MatrixXcd>(shifted).singularValues();
    int geometric = 0;
    for (Eigen::Index k = 0; k < n; ++k)
      if (sigma[k] <= 1e-8 * scale) ++geometric;
    defect += std::max(0, algebraic - std::max(geometric, 1));
  }
  return defect;
}

void MonodromyOptions::validate() const {
  if (elements < 0)
    throw core::InputError("stability_elements",
                           fmt::format("must be >= 0 (0: the shooting grid; got {})", elements));
  if (!(relative_step > 0 && relative_step < 1e-2))
    throw core::InputError("stability_step",
                           fmt::format("must be in (0, 1e-2) (got {})", relative_step));
  if (!(courant > 0 && courant <= 1))
    throw core::InputError("stability_courant", fmt::format("must be in (0, 1] (got {})", courant));
  if (threads < 1) throw core::InputError("threads", "must be >= 1");
}

namespace {

// Nodal values 0, s_1..s_N on the nodes as a bar::PiecewiseLinear.
bar::PiecewiseLinear nodal_function(const std::vector<double>& nodes, const double* values) {
  std::vector<double> y(nodes.size());
  for (std::size_t i = 1; i < nodes.size(); ++i) y[i] = values[i - 1];
  return bar::PiecewiseLinear(nodes, std::move(y));
}

// The problem's bar started from the state s = [u_1..u_N | v_1..v_N] on the nodes.
bar::BarSetup state_setup(const ContactBarOrbitProblem& problem, const std::vector<double>& nodes,
                          const Vector& state) {
  const auto n = static_cast<Eigen::Index>(nodes.size()) - 1;
  bar::BarSetup s = problem.setup_template();
  s.u0 = nodal_function(nodes, state.data());
  s.v0 = nodal_function(nodes, state.data() + n);
  return s;
}

// Solves M v = b for the P1 mass matrix of nodes 1..N (node 0 fixed): row i has
// (h_i + h_{i+1}) / 3 on the diagonal and h / 6 beside it, the last row h_N / 3; symmetric
// positive definite and tridiagonal (Thomas).
Vector solve_mass(const std::vector<double>& nodes, const Vector& b) {
  const int n = static_cast<int>(b.size());
  const auto width = [&](int i) {  // h_i = y_i - y_{i-1}, i = 1..N
    return nodes[static_cast<std::size_t>(i)] - nodes[static_cast<std::size_t>(i) - 1];
  };
  Vector diagonal(n), off(n), rhs = b, v(n);
  for (int i = 1; i <= n; ++i) {
    diagonal[i - 1] = (width(i) + (i < n ? width(i + 1) : 0.0)) / 3;
    off[i - 1] = i < n ? width(i + 1) / 6 : 0.0;  // M(i, i + 1)
  }
  for (int i = 1; i < n; ++i) {
    const double w = off[i - 1] / diagonal[i - 1];
    diagonal[i] -= w * off[i - 1];
    rhs[i] -= w * rhs[i - 1];
  }
  v[n - 1] = rhs[n - 1] / diagonal[n - 1];
  for (int i = n - 2; i >= 0; --i) v[i] = (rhs[i] - off[i] * v[i + 1]) / diagonal[i];
  return v;
}

}  // namespace

std::vector<double> full_state_nodes(const ContactBarOrbitProblem& problem, const Vector& x,
                                     int elements) {
  const double length = problem.setup_template().material.length;
  std::vector<double> nodes{0.0};
  if (elements > 0) {
    for (int i = 1; i <= elements; ++i) nodes.push_back(length * i / elements);
  } else {
    const Vector y = problem.node_positions(x);
    for (int i = 0; i < problem.options().elements; ++i) nodes.push_back(y[i]);
    nodes.back() = length;
  }
  return nodes;
}

Vector full_state(const ContactBarOrbitProblem& problem, const Vector& x,
                  const std::vector<double>& nodes) {
  const int n = static_cast<int>(nodes.size()) - 1;
  const bar::BarSetup s = problem.setup_at(x);
  Vector state = Vector::Zero(2 * n);
  for (int i = 1; i <= n; ++i) state[i - 1] = s.u0(nodes[static_cast<std::size_t>(i)]);
  return state;
}

double full_state_time_step(const ContactBarOrbitProblem& problem, double period,
                            const std::vector<double>& nodes, double courant) {
  const bar::Material& m = problem.setup_template().material;
  double dx = m.length;
  for (std::size_t i = 1; i < nodes.size(); ++i) dx = std::min(dx, nodes[i] - nodes[i - 1]);
  const double target = std::min(problem.time_step(period), courant * dx / m.wave_speed());
  return period / std::ceil(period / target - 1e-9);
}

EvalStatus full_state_map(const ContactBarOrbitProblem& problem, const std::vector<double>& nodes,
                          double period, double dt, const Vector& state, Vector& mapped) {
  const int n = static_cast<int>(nodes.size()) - 1;
  if (n < 1 || state.size() != 2 * n || !(period > 0)) return EvalStatus::failed;
  const bar::BarSetup s = state_setup(problem, nodes, state);
  bar::SnapshotRequest request;
  request.dt = dt;
  request.elements = n;
  request.nodes = nodes;
  request.nodal_u = true;
  request.projected_v = true;
  bar::FieldSnapshot snap;
  try {
    snap = problem.solver().snapshot(s, period, request);
  } catch (const core::InputError&) {
    return EvalStatus::failed;
  }
  if (!snap.ok || static_cast<int>(snap.u.size()) != n + 1 ||
      static_cast<int>(snap.v_projected.size()) != n + 1)
    return EvalStatus::failed;
  mapped.resize(2 * n);
  Vector rhs(n);
  for (int i = 1; i <= n; ++i) {
    mapped[i - 1] = snap.u[static_cast<std::size_t>(i)];
    rhs[i - 1] = snap.v_projected[static_cast<std::size_t>(i)];
  }
  mapped.tail(n) = solve_mass(nodes, rhs);
  return mapped.allFinite() ? EvalStatus::ok : EvalStatus::non_finite;
}

namespace {

// M from one march with the tangent in the nodes' hats: the u rows are the nodal displacements'
// derivatives, the v rows the projected velocity's, solved with the mass matrix column by column.
EvalStatus tangent_monodromy(const ContactBarOrbitProblem& problem,
                             const std::vector<double>& nodes, double period, double dt,
                             const Vector& state, Matrix& M) {
  const int n = static_cast<int>(nodes.size()) - 1;
  const bar::BarSetup s = state_setup(problem, nodes, state);
  std::optional<TdbemMarch> tangent;
  try {
    tangent.emplace(s, dt, ContactMethod::event, TangentDirections{nodes, true});
  } catch (const core::InputError&) {
    return EvalStatus::failed;
  }
  TdbemMarch& march = *tangent;
  if (!march.advance_to(period)) return EvalStatus::non_finite;
  M.resize(2 * n, 2 * n);
  for (int i = 1; i <= n; ++i)
    M.row(i - 1) = march.tangent_displacement(nodes[static_cast<std::size_t>(i)]).transpose();
  const Matrix V = march.tangent_projected_velocity(nodes);
  for (int j = 0; j < 2 * n; ++j) M.col(j).tail(n) = solve_mass(nodes, V.col(j).segment(1, n));
  return M.allFinite() ? EvalStatus::ok : EvalStatus::non_finite;
}

}  // namespace

EvalStatus full_state_monodromy(const ContactBarOrbitProblem& problem, const Vector& x,
                                const MonodromyOptions& options, Matrix& M) {
  options.validate();
  const double period = x[problem.period_index()];
  if (!(period > 0) || !std::isfinite(period)) return EvalStatus::failed;
  const std::vector<double> nodes = full_state_nodes(problem, x, options.elements);
  const int n = static_cast<int>(nodes.size()) - 1;
  // Bounded cost: the time step follows the shortest interval (c dt <= courant dx), so a grid
  // with an interval under 1/64 of the uniform one (a free knot a hair from the end, as the
  // subharmonic members next to their grazing limit) would take over 64 times the steps and
  // the memory of the simulations: refused before any of them, the point's stability undecided.
  double shortest = problem.setup_template().material.length;
  for (std::size_t i = 1; i < nodes.size(); ++i)
    shortest = std::min(shortest, nodes[i] - nodes[i - 1]);
  if (!(shortest * 64 * n >= problem.setup_template().material.length)) return EvalStatus::failed;
  const Vector base = full_state(problem, x, nodes);
  const bar::Material& material = problem.setup_template().material;
  const double u_scale = std::max(base.head(n).cwiseAbs().maxCoeff(), problem.displacement_scale());
  const double h_u = options.relative_step * u_scale;
  const double h_v = h_u * material.wave_speed() / material.length;
  const double dt = full_state_time_step(problem, period, nodes, options.courant);
  M.resize(2 * n, 2 * n);
  std::vector<EvalStatus> status(static_cast<std::size_t>(2 * n), EvalStatus::ok);
  // A state on the wall (the subharmonic members start there): a step of u(L) or v(L) towards
  // the wall leaves the admissible set, and the map has a kink there (Signorini). Those two
  // columns take the one-sided difference away from the wall, (F(s) - F(s - h)) / h.
  const bar::End& right = problem.setup_template().right;
  const bool on_wall =
      right.type == bar::EndType::contact && std::abs(base[n - 1] - right.gap) <= 1e-12 * u_scale;
  const auto* tdbem = dynamic_cast<const TdbemSolver*>(&problem.solver());
  if (options.derivatives == MonodromyOptions::Derivatives::tangent && tdbem &&
      tdbem->method() == ContactMethod::event && !on_wall &&
      problem.setup_template().body_force == 0)
    return tangent_monodromy(problem, nodes, period, dt, base, M);
  Vector f_base;
  if (on_wall) {
    const EvalStatus st = full_state_map(problem, nodes, period, dt, base, f_base);
    if (st != EvalStatus::ok) return st;
  }
  core::run_tasks(2 * n, options.threads, [&](int j) {
    const double h = j < n ? h_u : h_v;
    const bool one_sided = on_wall && (j == n - 1 || j == 2 * n - 1);
    Vector plus = base, minus = base, f_plus, f_minus;
    plus[j] += h;
    minus[j] -= h;
    EvalStatus a =
        one_sided ? EvalStatus::ok : full_state_map(problem, nodes, period, dt, plus, f_plus);
    EvalStatus b =
        a == EvalStatus::ok ? full_state_map(problem, nodes, period, dt, minus, f_minus) : a;
    status[static_cast<std::size_t>(j)] = b;
    if (b != EvalStatus::ok) return;
    M.col(j) = one_sided ? Vector((f_base - f_minus) / h) : Vector((f_plus - f_minus) / (2 * h));
  });
  for (EvalStatus s : status)
    if (s != EvalStatus::ok) return s;
  return M.allFinite() ? EvalStatus::ok : EvalStatus::non_finite;
}

namespace {
// max |u0| on the `elements` uniform intervals' nodes: the perturbation's unit.
double nodal_amplitude(const bar::BarSetup& setup, int elements) {
  double amplitude = 0;
  for (int i = 0; i <= elements; ++i)
    amplitude = std::max(amplitude, std::abs(setup.u0(setup.material.length * i / elements)));
  return amplitude;
}
}  // namespace

std::optional<bar::BarSetup> perturbed_setup(const bar::BarSetup& setup, double relative_size,
                                             int elements, unsigned seed) {
  if (elements < 1 || !(relative_size != 0) || !std::isfinite(relative_size)) return std::nullopt;
  const double length = setup.material.length;
  std::vector<double> nodes(static_cast<std::size_t>(elements) + 1);
  for (int i = 0; i <= elements; ++i) nodes[static_cast<std::size_t>(i)] = length * i / elements;
  const double amplitude = nodal_amplitude(setup, elements);
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double size = relative_size * amplitude;
  std::vector<double> du(nodes.size()), dv(nodes.size());  // 0 at x = 0
  for (std::size_t i = 1; i < nodes.size(); ++i) {
    du[i] = size * unit(random);
    dv[i] = size * unit(random);
  }
  // The orbit's own state plus the draw: piecewise linear on the union of their knots (a knot
  // of the orbit off the uniform nodes is kept). The orbit's interior knots move too, each by
  // up to relative_size L: the fronts' shifts, which the values excite only through the
  // contact instants.
  const auto plus = [&](const bar::PiecewiseLinear& orbit_state, const std::vector<double>& d) {
    const bar::PiecewiseLinear draw(nodes, d);
    const std::vector<double>& original = orbit_state.knots();
    std::vector<double> knots = original;
    for (std::size_t i = 1; i + 1 < knots.size(); ++i) {
      // At most a quarter of either neighbouring interval of the orbit's knots: the knots keep
      // their order, and the draw of the opposite sign moves each by exactly the opposite.
      const double room = 0.25 *
                          std::min(original[i] - original[i - 1], original[i + 1] - original[i]) /
                          (std::abs(relative_size) * length);
      knots[i] += relative_size * length * std::clamp(unit(random), -room, room);
    }
    const bar::PiecewiseLinear f(knots, orbit_state.values());
    std::vector<double> x = f.knots();
    const double tol = 1e-12 * length;
    for (double node : nodes)
      if (std::none_of(f.knots().begin(), f.knots().end(),
                       [&](double k) { return std::abs(k - node) <= tol; }))
        x.push_back(node);
    std::sort(x.begin(), x.end());
    std::vector<double> y(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) y[i] = f(x[i]) + draw(x[i]);
    return std::pair{x, y};
  };
  bar::BarSetup perturbed = setup;
  try {
    auto [ux, uy] = plus(setup.u0, du);
    const auto [vx, vy] = plus(setup.v0, dv);
    // An end on its wall (a grazing orbit) stays on the admissible side: the draw is projected.
    for (std::size_t i = 0; i < ux.size(); ++i) {
      if (ux[i] < length * (1 - 1e-12)) continue;
      if (setup.right.has_wall()) uy[i] = std::min(uy[i], setup.right.gap);
      if (setup.right.has_back_wall()) uy[i] = std::max(uy[i], -setup.right.gap_back);
    }
    perturbed.u0 = bar::PiecewiseLinear(ux, uy);
    perturbed.v0 = bar::PiecewiseLinear(vx, vy);
  } catch (const core::InputError&) {
    return std::nullopt;  // knots the union cannot hold (a velocity with jumps)
  }
  return perturbed;
}

PerturbationGrowth perturbation_growth(const bar::BarSetup& setup, double period, int periods,
                                       double relative_size, int elements, unsigned seed) {
  PerturbationGrowth g;
  if (!(period > 0) || periods < 1) return g;
  const std::optional<bar::BarSetup> perturbed =
      perturbed_setup(setup, relative_size, elements, seed);
  if (!perturbed) return g;
  const double amplitude = nodal_amplitude(setup, elements);
  const exact_bar::ExactBarSolution solution(*perturbed, periods * period);
  const exact_bar::ExactBarSolution orbit(setup, period);
  if (!solution.ok() || !orbit.ok()) return g;
  // One profile of a solution per time, on 4 elements + 1 points: u at the nodes, and v
  // projected on their hats (int v psi_i dx, continuous in the fronts' positions where nodal v
  // jumps).
  bar::SnapshotRequest samples;
  samples.elements = 4 * elements;
  samples.projected_v = true;
  struct Profile {
    std::vector<double> u, v;
  };
  const auto profile = [&](const exact_bar::ExactBarSolution& of, double t) {
    bar::FieldSnapshot snap = of.snapshot(t, samples);
    return Profile{std::move(snap.u), std::move(snap.v_projected)};
  };
  // The orbit at time tau (mod T).
  const auto orbit_at = [&](double tau) {
    tau = std::fmod(tau, period);
    if (tau < 0) tau += period;
    return profile(orbit, tau);
  };
  // The distance of two states, relative to the amplitude: the larger of max |u - w| and
  // max_j |sum_{i <= j} int (v - v_w) psi_i dx| / c. The partial sums are int_0^x (v - v_w) dx
  // averaged over cell j; with u = f + g (d'Alembert), int_0^x v dx / c = g - f, so both parts
  // are on the footing of f and g, which the free wave carries along unchanged: a
  // perturbation's strain does not show up as growth when it turns into velocity. Two states
  // with the same u and other velocities (the orbit at tau and at -tau in a standing wave) are
  // apart.
  const double wave_speed = setup.material.wave_speed();
  const auto gap = [&](const Profile& a, const Profile& b) {
    double du = 0, dv = 0, partial = 0;
    for (std::size_t j = 0; j < a.u.size(); ++j) du = std::max(du, std::abs(a.u[j] - b.u[j]));
    for (std::size_t j = 0; j < a.v.size(); ++j) {
      partial += a.v[j] - b.v[j];
      dv = std::max(dv, std::abs(partial));
    }
    return std::max(du, dv / wave_speed) / amplitude;
  };
  const auto gap_at = [&](const Profile& a, double tau) { return gap(a, orbit_at(tau)); };
  // The whole-period scan's samples are the same at every k: the orbit there, once.
  constexpr int scan = 100;
  std::vector<Profile> scanned(2 * scan + 1);
  for (int i = -scan; i <= scan; ++i) scanned[i + scan] = orbit_at(0.5 * period * i / scan);
  // The nearest state of the orbit: a perturbation of the energy moves the period, so the
  // perturbed state drifts along the orbit (linearly in k: the trivial pair's Jordan block);
  // that drift is no growth. The distance is to the orbit as a set (orbital stability): the
  // best of a scan of +-window around k T and of one over the whole period (a drift beyond the
  // window: the clearance modes' period moves fast with the energy), each refined by golden
  // sections around its best sample.
  const double r = 0.5 * (std::sqrt(5.0) - 1);
  // profiles: the orbit at the scan's samples (width * i / n), when they are the whole period's.
  const auto nearest = [&](const Profile& a, double width, int n,
                           const std::vector<Profile>* profiles) {
    const auto sample = [&](int i) {
      return profiles ? gap(a, (*profiles)[i + n]) : gap_at(a, width * i / n);
    };
    double best = 0, best_d = sample(0);
    for (int i = -n; i <= n; ++i) {
      const double tau = width * i / n, d = sample(i);
      if (d < best_d) best_d = d, best = tau;
    }
    double lo = best - width / n, hi = best + width / n;
    for (int it = 0; it < 40; ++it) {
      const double m1 = hi - r * (hi - lo), m2 = lo + r * (hi - lo);
      if (gap_at(a, m1) < gap_at(a, m2))
        hi = m2;
      else
        lo = m1;
    }
    return std::min(best_d, gap_at(a, 0.5 * (lo + hi)));
  };
  const auto distance = [&](int k) {
    const double t = k * period,
                 window = std::min(0.25, 1e-2 + 10 * std::abs(relative_size) * k) * period;
    const Profile a = profile(solution, t);
    return std::min(nearest(a, window, 20, nullptr), nearest(a, 0.5 * period, scan, &scanned));
  };

  g.initial = distance(0);
  if (!(g.initial > 0)) return g;
  for (int k = 1; k <= periods; k = k < 10 ? k + 1 : (k * 3) / 2) {
    const double d = distance(k) / g.initial;
    g.history.emplace_back(k, d);
    g.largest = std::max(g.largest, d);
  }
  g.last = distance(periods) / g.initial;
  g.largest = std::max(g.largest, g.last);
  g.history.emplace_back(periods, g.last);
  g.ok = std::isfinite(g.largest);
  return g;
}

}  // namespace backbone::contact_bar
