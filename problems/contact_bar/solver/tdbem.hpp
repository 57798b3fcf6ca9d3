// Time-domain boundary element method (TD-BEM) for the 1D bar with unilateral contact.
//
// The internal point equation of the wave equation u_tt = c^2 u_xx + b (b = body_force / rho)
// on [0, L], with tau = L / c, reads for xi in [0, L]
//   u(xi, t) = IC(xi, t) + Q_L(t - (L - xi) / c) + Q_0(t - xi / c) + Body(xi, t),
//   Q_e(s) = (c/2) S_e(s) + 1/2 U_e(s) for s > 0 and 0 for s <= 0,
// U_e the end displacement, S_e(s) = int_0^s du/dn(e) the time integral of the outward normal
// derivative, IC the d'Alembert term of u0, v0 extended by zero outside [0, L], and
// Body(xi, t) = b/(2c) [F(t, xi) + F(t, L - xi)], F(t, a) = int_0^t min(c s, a) ds.
// At xi = e it gives one boundary equation per end, 1/2 U_e(t) - (c/2) S_e(t) = R_e(t), where
// R_e depends only on the data and on the OTHER end's history at t - tau: the two ends march
// independently, O(1) work per step, and only the last tau of history (a ring of about
// tau / dt + 2 knots) is kept. Tractions are piecewise constant in time (S, U, Q piecewise
// linear). Each end has one unknown per step: U (free, open contact) or S (fixed, closed
// contact). Interior u, v, u_x and exact hat-function projections come from the same equation
// on demand. Contact force lambda = -EA u_x = -EA n dS/dt >= 0 (compressive).
//
// Contact: `projection` is the paper's Algorithm 1 (free prediction; on penetration the end is
// put on the wall for the whole step; release when the step force would be tensile). Exactly:
// the closed-step force is EA n (U_free - wall) / (c dt), so "penetration" and "positive force"
// are the same test. `event` splits the step at the closing instant (root of the free
// displacement, exact for linear data), at the release instant (sign change of the force) and
// at the echoes of every such kink arriving from the other end (tau later), so that piecewise
// linear solutions (problems/contact_bar/orbits/README.md, 'Mode 1') are reproduced to round-off
// off the time grid too. Requires dt <= L / c (one step may not cross the bar).
//
//   contact_bar::TdbemSolver tdbem(contact_bar::ContactMethod::event);
//   bar::SimulationOptions o; o.t_end = 3.1; o.dt = 1e-2;
//   bar::History h = tdbem.simulate(setup, o);          // t, u_contact, contact_force, energy
//   bar::SnapshotRequest r; r.dt = 1e-2; r.elements = 100; r.projected_v = true;
//   bar::FieldSnapshot s = tdbem.snapshot(setup, 1.55, r);  // marches to 1.55 only
//   contact_bar::TdbemMarch m(setup, 1e-2, contact_bar::ContactMethod::event);
//   m.advance_to(2.5);  double v = m.velocity(0.3);  auto events = m.events();
//
// Tangent (tdbem_tangent.cpp): constructed with TangentDirections, the march also carries the
// derivative of every history knot in the hats of a node grid (u0 and v0 at its nodes 1..N):
// of its value and of its time, so the contact instants and their echoes move with the data.
// The readouts give the derivative of the field at the current time: the march's own tangent,
// no differences. A kink within a round-off of the readout is on it, and takes the mean of the
// two sides; at a contact decision on a kink (tangent_on_kink) it is the side of the march's
// own decisions (solver/README.md, 'Tangent').
//   contact_bar::TdbemMarch m(setup, dt, ContactMethod::event, {nodes, true});
//   m.advance_to(T);  Eigen::VectorXd du = m.tangent_displacement(0.3);  // P = 2N entries
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <compare>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "problems/bar/bar.hpp"

namespace backbone::contact_bar {

enum class ContactMethod { projection, event };
const char* to_string(ContactMethod m);
ContactMethod parse_contact_method(const std::string& key, const std::string& value);  // InputError

// A change of contact state of one end.
struct ContactEvent {
  double t = 0;
  bool right_end = true;
  bool closing = true;     // false: release
  bool back_wall = false;  // the wall behind a clearance end
};

// The directions of the march's tangent: the hats psi_1..psi_N of `nodes` (0 = y_0 < ... <
// y_N = L) as perturbations of u0, then, with `velocity`, of v0 (P = N or 2N).
struct TangentDirections {
  std::vector<double> nodes;
  bool velocity = true;
};

// The boundary march with its history window; the field at the current time on demand.
class TdbemMarch {
 public:
  // Throws InputError for a bad setup or dt (dt must be finite, > 0 and <= L / c).
  TdbemMarch(const bar::BarSetup& setup, double dt, ContactMethod method);
  // With the tangent in `directions`: the event method, no body force, u0 and v0 without
  // jumps, no fixed end at x = L (InputError "tangent" otherwise). The data's knots gain the
  // nodes (a hat's kink is a kink of the perturbed data), and every echo of a kink is kept: the
  // values agree with the plain march's to round-off, and the window grows with each contact
  // event, so the tangent suits marches of a period or a few.
  TdbemMarch(const bar::BarSetup& setup, double dt, ContactMethod method,
             const TangentDirections& directions);

  // Marches on the grid k dt and takes a last partial step to t (t need not be on the grid).
  // Returns false (and stays false) when the march produced non-finite values.
  bool advance_to(double t);
  double time() const { return t_; }
  bool ok() const { return ok_; }
  const bar::BarSetup& setup() const { return setup_; }

  double end_displacement(bool right) const;  // U_e at the current time [m]
  double end_force(bool right) const;  // compressive end force -EA u_x over the last sub-step [N]
  bool in_contact(bool right) const;
  const std::vector<ContactEvent>& events() const { return events_; }
  int regauges() const { return regauges_; }  // shifts of the gauge so far (regauge() below)

  // Field at the current time, x in [0, L]. On a front (jump of v or u_x) the value is one of
  // the one-sided limits; projections below are exact and unambiguous.
  double displacement(double x) const;
  double velocity(double x) const;
  double strain(double x) const;
  // int_0^L w psi_i dx on the uniform grid of `elements` intervals (exact integration).
  std::vector<double> projected_displacement(int elements) const;
  std::vector<double> projected_velocity(int elements) const;
  // int_0^L v psi_i dx for the hats psi_i of any node grid (nodes increasing from 0 to L), exact.
  std::vector<double> projected_velocity(const std::vector<double>& nodes) const;
  // 1/2 int (rho A v^2 + EA u_x^2) dx - int body_force A u dx, integrated exactly.
  double energy() const;
  // Where the field may change form at the current time, increasing from 0 to L: the data's
  // knots carried along both characteristics and the ends' history knots. Between two of them
  // u, v and u_x are polynomials (v and u_x linear).
  std::vector<double> breakpoints() const { return breakpoints(std::vector<double>{0.0, L_}); }
  std::size_t stored_knots() const;  // history window size (both ends)

  // The tangent at the current time (P = tangent_size(); 0 without one): d/dp of
  // displacement(x), and of projected_velocity(nodes) (one row per node, any node grid).
  int tangent_size() const { return tangent_ ? tangent_->size : 0; }
  Eigen::VectorXd tangent_displacement(double x) const;
  Eigen::MatrixXd tangent_projected_velocity(const std::vector<double>& nodes) const;
  // Whether a contact decision of the march came within round-off (1e-12 of the scene's
  // displacement scale) of the other outcome: a held or released end whose force test was
  // round-off, a grazing at a kink of R, a closing on a kink of R. The map may have a kink
  // there (it does at a grazing); the tangent is the side of the march's own decisions.
  bool tangent_on_kink() const { return tangent_ && tangent_->on_kink; }

 private:
  // A time on the march's step grid: step + tick / 2^62 steps of step_ seconds, tick in
  // [0, 2^62). The march never forms an absolute time in seconds, so a sub-step, a retarded time
  // t - tau and an echo t + tau keep the precision of the first step however long the run, and
  // the fraction is fixed-point: an echo of an echo is exact, so kinks that coincide in exact
  // arithmetic coincide here (README.md, 'Hard cases').
  struct GridTime {
    std::int64_t step = 0;
    std::int64_t tick = 0;
    auto operator<=>(const GridTime&) const = default;
  };
  static constexpr std::int64_t ticks_per_step = std::int64_t{1} << 62;
  static constexpr double step_per_tick = 0x1p-62;
  static GridTime normalized(std::int64_t step, double frac);  // any frac, |frac| < 2^52
  static GridTime plus(GridTime a, GridTime b) {
    GridTime t{a.step + b.step, a.tick + b.tick};
    if (t.tick >= ticks_per_step) {
      t.tick -= ticks_per_step;
      t.step += 1;
    }
    return t;
  }
  static GridTime minus(GridTime a, GridTime b) {
    GridTime t{a.step - b.step, a.tick - b.tick};
    if (t.tick < 0) {
      t.tick += ticks_per_step;
      t.step -= 1;
    }
    return t;
  }
  static GridTime later(GridTime t, double steps) { return plus(t, normalized(0, steps)); }
  static double fraction(GridTime t) { return static_cast<double>(t.tick) * step_per_tick; }
  // a - b in steps (exact for a == b; meant for nearby times).
  static double steps_between(GridTime a, GridTime b) {
    return static_cast<double>(a.step - b.step) +
           static_cast<double>(a.tick - b.tick) * step_per_tick;
  }
  double seconds(GridTime t) const { return (static_cast<double>(t.step) + fraction(t)) * step_; }
  double seconds_between(GridTime a, GridTime b) const { return steps_between(a, b) * step_; }
  GridTime grid_time(double t) const;  // seconds -> grid time, round-off of a grid point snapped
  GridTime retarded(double t_seconds_before) const;  // now_ - t_seconds_before

  struct Knot {
    GridTime t;
    double u, s, q;  // U, S, Q = (c/2) S + U/2
    // dQ/dt [m/s] over (previous knot, this knot): (q - q_prev) / (t - t_prev), formed once
    // when the knot is pushed (and again after regauge()); 0 for the first knot.
    double slope;
    bool kink;  // a slope change whose echo must be tracked (event method)
  };
  // A first-in first-out sequence in one contiguous array (a vector and the index of its first
  // live element): the knot searches index the window on every query, which a std::deque turns
  // into a division per access. pop_front is O(1); the dead prefix is dropped when it is as
  // long as the live part and the array is full (amortized O(1) per element).
  template <class T>
  class Fifo {
   public:
    std::size_t size() const { return data_.size() - head_; }
    bool empty() const { return data_.size() == head_; }
    T& operator[](std::size_t i) { return data_[head_ + i]; }
    const T& operator[](std::size_t i) const { return data_[head_ + i]; }
    T& front() { return data_[head_]; }
    const T& front() const { return data_[head_]; }
    T& back() { return data_.back(); }
    const T& back() const { return data_.back(); }
    T* begin() { return data_.data() + head_; }
    T* end() { return data_.data() + data_.size(); }
    const T* begin() const { return data_.data() + head_; }
    const T* end() const { return data_.data() + data_.size(); }
    void reserve(std::size_t n) { data_.reserve(n); }
    void push_back(const T& value) {
      if (data_.size() == data_.capacity() && head_ >= size()) drop_dead();
      data_.push_back(value);
    }
    void push_back(T&& value) {
      if (data_.size() == data_.capacity() && head_ >= size()) drop_dead();
      data_.push_back(std::move(value));
    }
    void pop_front() {
      if (++head_ == data_.size()) {
        data_.clear();
        head_ = 0;
      }
    }
    T* insert(const T* at, const T& value) {
      const auto offset = at - data_.data();
      return &*data_.insert(data_.begin() + offset, value);
    }
    void erase(const T* at) { data_.erase(data_.begin() + (at - data_.data())); }
    template <class It>
    void assign(It first, It last) {
      data_.assign(first, last);
      head_ = 0;
    }

   private:
    void drop_dead() {
      data_.erase(data_.begin(), data_.begin() + static_cast<std::ptrdiff_t>(head_));
      head_ = 0;
    }
    std::vector<T> data_;
    std::size_t head_ = 0;
  };
  // A knot's derivative in the P directions: of its time (seconds; zero on the step grid, the
  // contact instant's or the arriving kink's otherwise) and of its values taken at that time.
  struct KnotTangent {
    Eigen::VectorXd dt, du, ds, dq;
    bool moving = false;  // dt != 0
  };
  struct Tangent {
    std::vector<double> nodes;  // y_0..y_N
    int n = 0;                  // N
    bool velocity = true;
    int size = 0;            // P
    KnotTangent next;        // the next pushed knot's (push_knot), filled by its caller
    Eigen::VectorXd end_dt;  // the time derivative of the current sub-step's end
    Eigen::VectorXd zero;    // P zeros
    bool on_kink = false;    // tangent_on_kink()
  };
  struct EndState {
    bar::End end;
    double normal = 1;     // outward normal
    double wall = 0;       // wall position n * gap
    double wall_back = 0;  // a clearance end's back wall, -n * gap_back
    bool has_back = false;
    int side = 1;          // the wall of a closed end: +1 the front one, -1 the back one
    double contact_u = 0;  // U held while closed: the wall, or a round-off off it (solve_open)
    double wall_at(int s) const { return s > 0 ? wall : wall_back; }
    Fifo<Knot> knots;
    Fifo<KnotTangent> tangents;  // knots' derivatives, index for index (with a tangent)
    Fifo<GridTime> pending;      // times of kinks of R_e still ahead (event method)
    double force = 0;
    bool closed = false;
  };

  double r_end(int e, GridTime t) const;  // R_e(t), t > 0
  // Q_e(s) (s > 0) and its slope. hint: when given, the knot search walks from the index of the
  // previous query and stores the new one there (O(1) for monotone queries: the march's
  // retarded times, a projection's sweep in x); else a binary search. Same value either way.
  double q_at(int e, GridTime s, std::size_t* hint = nullptr) const;
  double q_slope(int e, GridTime s, std::size_t* hint = nullptr) const;
  // Index of the first knot of end e with time >= s (std::lower_bound), see hint above.
  std::size_t knot_index(int e, GridTime s, std::size_t* hint) const;
  // velocity(x) with the knot searches of both ends walking from hints (project's sweep).
  double velocity(double x, std::size_t* hints) const;
  double strain(double x, std::size_t* hints) const;
  void velocity_and_strain(double x, std::size_t* hints, double& v, double& ux) const;
  void step_end(int e, GridTime ta, GridTime tb);
  void substep_event(int e, GridTime ta, GridTime tb, bool kink_at_end);
  void push_knot(int e, GridTime t, double u, double s, bool kink);
  void mark_kink(int e);  // flags the last knot of end e as a kink and schedules its echo
  void solve_open(int e, GridTime ta, GridTime tb, bool kink_at_end);
  void solve_closed_to(int e, GridTime ta, GridTime tb, bool kink_at_end);
  void regauge();  // moves a constant between the ends' Q (u unchanged) to keep both small
  std::vector<double> breakpoints(int elements) const;
  // The field's breakpoints merged with `nodes` (breakpoints(elements) with other nodes).
  std::vector<double> breakpoints(const std::vector<double>& nodes) const;
  template <class F>
  void integrate_pieces(int elements, F&& f) const;
  std::vector<double> project(int elements, bool velocity) const;
  double window_energy() const;  // energy() without body force once t > tau, O(window)

  // The tangent's pieces (tdbem_tangent.cpp).
  static bar::BarSetup with_node_knots(const bar::BarSetup& setup,
                                       const TangentDirections& directions);
  // The hats' values at x, their slopes on `side`, their integrals over [a, b], times coef,
  // added to the u0 block (first N) or the v0 block of d.
  void add_hat_values(Eigen::VectorXd& d, bool v_block, double x, double coef) const;
  void add_hat_slopes(Eigen::VectorXd& d, bool v_block, double x, int side, double coef) const;
  void add_hat_integrals(Eigen::VectorXd& d, bool v_block, double a, double b, double coef) const;
  // dQ_e(s) with s moving by ds (nullptr: s fixed); on a knot the left interval's slope.
  Eigen::VectorXd q_tangent(int e, GridTime s, const Eigen::VectorXd* ds) const;
  // dQ_e/dt just after time t (the last knot's, or a kink's arriving next), from the end's
  // contact state and R (a readout on that knot).
  double next_slope(int e, GridTime t) const;
  // The slope of Q_e just after knot i (past a sliver interval; next_slope after the last).
  double slope_after(int e, std::size_t i) const;
  // d of the slope q_slope(e, s) reads, s fixed.
  Eigen::VectorXd q_slope_tangent(int e, GridTime s) const;
  // Before tau, R_e reads the data at x = L - c t (e = 1) or c t (e = 0): that point, and
  // dR_e/dt there.
  double data_point(int e, GridTime t) const;
  double data_rate(int e, GridTime t) const;
  // dR_e(t), t moving by dt.
  Eigen::VectorXd r_tangent(int e, GridTime t, const Eigen::VectorXd& dt) const;
  // The time derivative of a kink of R_e arriving at p: its source knot's on the other end
  // (tau earlier), zero for a data knot.
  Eigen::VectorXd arrival_dt(int e, GridTime p) const;
  // The last knot of end e moves with dt: its values follow along its left interval.
  void retag_last(int e, const Eigen::VectorXd& dt);
  double kink_margin() const { return 1e-12 * gauge_scale_; }
  void set_next_tangent(const Eigen::VectorXd& dt, const Eigen::VectorXd& du,
                        const Eigen::VectorXd& ds);
  // The next knot holds U at t (a fixed end, a closed one): du = 0, ds = -2 dR_e(t) / c.
  void set_next_tangent_holding(int e, GridTime t);

  bar::BarSetup setup_;
  ContactMethod method_;
  double dt_, L_, c_, tau_, ea_, body_coef_, v0_total_;
  bool v0_is_zero_ = false;  // every value of v0 is +0
  double step_ = 0;          // grid step [s]: dt, or tau / m when tau is m dt to round-off
  GridTime tau_grid_;        // tau on the grid (m steps exactly when tau is m dt to round-off)
  double merge_steps_ = 0;   // sub-step instants closer than this (in steps) are one
  double gauge_scale_ = 0;   // displacement scale of the scene; regauge() keeps Q within it
  double t_ = 0;             // time() [s]: the last target reached
  GridTime now_;             // the current time on the grid
  bool ok_ = true;
  int regauges_ = 0;
  EndState ends_[2];  // 0: x = 0, 1: x = L
  // Knot index of the last retarded-time query of each end's R (r_end reads the OTHER end's
  // history at t - tau, increasing over the march). Only the march itself updates it.
  mutable std::size_t retarded_hint_[2] = {0, 0};
  std::vector<GridTime> cuts_;  // step_end's sub-step instants (kept to reuse its storage)
  std::vector<ContactEvent> events_;
  std::unique_ptr<Tangent> tangent_;  // with TangentDirections
};

// The march's hot lookups, shared by tdbem.cpp and tdbem_tangent.cpp.
inline TdbemMarch::GridTime TdbemMarch::retarded(double t_seconds_before) const {
  return minus(now_, normalized(0, t_seconds_before / step_));
}

inline std::size_t TdbemMarch::knot_index(int e, GridTime s, std::size_t* hint) const {
  const auto& k = ends_[e].knots;
  if (!hint)
    return static_cast<std::size_t>(
        std::lower_bound(k.begin(), k.end(), s,
                         [](const Knot& a, const GridTime& v) { return a.t < v; }) -
        k.begin());
  // Times are sorted: stepping down while the previous knot is not before s, then up while
  // this one is before s, lands on the lower bound from any start.
  std::size_t i = std::min(*hint, k.size());
  while (i > 0 && k[i - 1].t >= s) --i;
  while (i < k.size() && k[i].t < s) ++i;
  *hint = i;
  return i;
}

class TdbemSolver : public bar::BarSolver {
 public:
  explicit TdbemSolver(ContactMethod method = ContactMethod::event) : method_(method) {}
  std::string name() const override { return "tdbem"; }
  ContactMethod method() const { return method_; }
  bar::History simulate(const bar::BarSetup& setup,
                        const bar::SimulationOptions& options) const override;
  bar::FieldSnapshot snapshot(const bar::BarSetup& setup, double t,
                              const bar::SnapshotRequest& request) const override;

 private:
  ContactMethod method_;
};

}  // namespace backbone::contact_bar
