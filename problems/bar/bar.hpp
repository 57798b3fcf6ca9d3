// The elastic bar shared by every bar solver: material, end conditions, initial state, and
// the one simulation interface that TD-BEM (contact_bar), the exact characteristics oracle
// (exact_bar) and the FEM baseline (fem_bar) all implement.
//
// Coordinates: x in [0, L]. Outward normal n = -1 at x = 0 and +1 at x = L. An end is fixed
// (u = 0), free (u_x = 0) or in unilateral contact with a rigid wall at outward gap g:
//     g(t) = gap - n u(end, t) >= 0,  lambda = -EA u_x >= 0,  g * lambda = 0   (Signorini)
// so at x = L the wall sits at u = +gap, at x = 0 at u = -gap. lambda is the compressive
// contact force [N] (compression, u_x < 0, at either end). A clearance end moves between two
// walls: the front one as above and a back one at outward distance gap_back behind it,
//     gap_back + n u(end, t) >= 0,  -lambda >= 0,  (gap_back + n u) lambda = 0   (Signorini),
// where the contact force is tensile (lambda < 0: the back wall pulls the end outwards). body_force
// is a constant force per unit volume along +x [N/m^3]; its potential enters the energy: E = 1/2
// int (rho A v^2 + EA u_x^2) dx - int body_force A u dx. Initial displacement and velocity are
// piecewise linear (knots may be anywhere in [0, L]).
//
//   bar::BarSetup s;
//   s.material = {1.0, 1.0, 1.0, 1.0};                     // L, E, rho, A  (c = 1)
//   s.left = {bar::EndType::fixed}; s.right = {bar::EndType::contact, 1e-3};
//   s.u0 = bar::PiecewiseLinear({0.0, 1.0}, {0.0, -0.01});  //
//   problems/contact_bar/orbits/README.md 'Mode 1' bar::SimulationOptions o; o.t_end = 3.1; o.dt =
//   1e-3; bar::History h = solver.simulate(s, o);                // h.contact_force, h.u_contact,
//   ...
#pragma once

#include <string>
#include <vector>

#include "core/io/table.hpp"

namespace backbone::bar {

enum class EndType { fixed, free, contact, clearance };
const char* to_string(EndType e);
EndType parse_end_type(const std::string& key, const std::string& value);  // InputError

struct End {
  EndType type = EndType::fixed;
  double gap = 0;       // contact, clearance: outward distance to the (front) wall at rest [m]
  double gap_back = 0;  // clearance only: inward distance to the back wall at rest [m]
  bool has_wall() const { return type == EndType::contact || type == EndType::clearance; }
  bool has_back_wall() const { return type == EndType::clearance; }
};

struct Material {
  double length = 1;               // L [m]
  double youngs_modulus = 1;       // E [Pa]
  double density = 1;              // rho [kg/m^3]
  double area = 1;                 // A [m^2]
  double wave_speed() const;       // c = sqrt(E / rho)
  double axial_stiffness() const;  // EA
  double impedance() const;        // rho A c
  double travel_time() const;      // L / c
};

// Continuous piecewise-linear function on sorted knots (constant extrapolation outside).
// Knots close to a uniform grid (a shooting state's u0 on N equal elements) are found by index
// arithmetic, floor((x - x_0) / dx) corrected by a walk to the exact search's answer; other
// knots by binary search. Values are the same either way.
class PiecewiseLinear {
 public:
  PiecewiseLinear() : x_{0.0}, y_{0.0} {}
  PiecewiseLinear(std::vector<double> x, std::vector<double> y);  // throws InputError
  // The same with jumps: two consecutive interior knots may share an x (never three), the left
  // limit then the right one. The function takes the right limit there, slope() the one-sided
  // slopes; integral() stays exact.
  // A velocity in characteristic form has them (exact_bar, 'Fronts').
  static PiecewiseLinear with_jumps(std::vector<double> x, std::vector<double> y);
  static PiecewiseLinear zero(double length) { return {{0.0, length}, {0.0, 0.0}}; }
  double operator()(double x) const;
  double slope(double x, int side) const;     // side -1: left derivative, +1: right derivative
  double integral(double a, double b) const;  // exact
  const std::vector<double>& knots() const { return x_; }
  const std::vector<double>& values() const { return y_; }

 private:
  PiecewiseLinear(std::vector<double> x, std::vector<double> y, bool jumps);
  // Index of the first knot > x (or_equal: >= x), as std::upper_bound (std::lower_bound).
  std::size_t first_knot_above(double x, bool or_equal) const;

  double integral_with_jumps(double a, double b) const;

  std::vector<double> x_, y_;
  bool has_jumps_ = false;
  double inverse_spacing_ = 0;  // (knots - 1) / (x_back - x_front) when near uniform, else 0
};

struct BarSetup {
  Material material;
  End left{EndType::fixed, 0};
  End right{EndType::contact, 0};
  double body_force = 0;  // [N/m^3] along +x
  PiecewiseLinear u0, v0;
  void validate() const;  // throws InputError naming the key (length, gap, u0...)
  // The end whose displacement and force are reported: the contact end if any (right first),
  // else x = L.
  bool observed_end_is_right() const;
};

struct SimulationOptions {
  double t_end = 1;    // [s]
  double dt = 1e-3;    // [s] time step (TD-BEM, FEM); ignored by the exact solver except
                       // as the default sampling interval
  int elements = 100;  // space intervals of the node grid (TD-BEM interior output, FEM mesh)
  int history_samples = 2000;  // at most this many rows in the history (decimated evenly)
  bool energy = true;          // compute the energy column (costs an interior evaluation per row)
  std::vector<double> probes;  // interior points whose u is recorded per row
  void validate() const;
};

// Sampled history: one entry per recorded instant.
struct History {
  std::vector<double> t, u_contact, contact_force, energy;
  std::vector<std::vector<double>> probe_u;  // probe_u[k][row]
  std::vector<double> probes;
  core::Table to_table() const;  // columns t,u_contact,contact_force,energy,u_probe0,...
};

// What a shooting residual needs from a simulation: the field at ONE instant t, on the uniform
// node grid x_i = i L / elements (i = 0..elements). Only the requested parts are computed.
struct SnapshotRequest {
  double dt = 1e-3;          // time step of the march (TD-BEM, FEM); the exact solver ignores it
  int elements = 100;        // node grid: elements + 1 nodes including both ends
  bool nodal_u = true;       // u(x_i, t)
  bool nodal_v = false;      // v(x_i, t) (one-sided limits are ambiguous on a front: prefer
                             // the projection below for residuals)
  bool projected_u = false;  // int_0^L u(x, t) psi_i(x) dx, psi_i the hat function of node i
  bool projected_v = false;  // int_0^L v(x, t) psi_i(x) dx (exact for piecewise fields)
  // Another node grid (increasing from 0 to L; elements is then its size - 1) for the nodal
  // values and the hats psi_i: TD-BEM and the exact solver; the FEM refuses it (InputError).
  std::vector<double> nodes;
};

struct FieldSnapshot {
  double t = 0;
  std::vector<double> x;                               // node positions (size elements + 1)
  std::vector<double> u, v, u_projected, v_projected;  // empty unless requested
  bool ok = true;  // false: the march failed (non-finite values)
  std::string message;
};

class BarSolver {
 public:
  virtual ~BarSolver() = default;
  virtual std::string name() const = 0;
  virtual History simulate(const BarSetup& setup, const SimulationOptions& options) const = 0;
  // The field at time t only (no history is kept beyond what the march itself needs).
  virtual FieldSnapshot snapshot(const BarSetup& setup, double t,
                                 const SnapshotRequest& request) const = 0;
};

}  // namespace backbone::bar
