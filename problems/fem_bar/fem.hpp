// The finite-element baseline of the bar: linear elements on the uniform grid of `elements`
// intervals, lumped (row-sum) mass, explicit central differences, and unilateral contact by
// forward-increment Lagrange multipliers (Carpenter, Taylor & Katona, IJNME 1991).
//
// One step: M (u_{n+1} - 2 u_n + u_{n-1}) / dt^2 = f - K u_n - n lambda_n at a contact end.
// The end displacement at t_{n+1} is first predicted with lambda_n = 0; if the prediction
// penetrates the wall, lambda_n = m_end (n u_pred - gap) / dt^2 >= 0 puts the end exactly on
// the wall (the multiplier is only ever compressive: that is the force sign check; with a
// lumped mass the constraint decouples, so this is exact, not iterative). The body force enters
// as the consistent nodal load (for a constant force it equals the lumped one). Stability:
// dt <= dx / c (InputError "dt" otherwise). At Courant number c dt / dx = 1 the scheme is the
// exact d'Alembert update at the nodes for fixed and free ends (v0 = 0 start-up included),
// but if both ends are free (or a contact end is open) the grid-scale mode u_i = (-1)^i then
// has a double amplification factor -1 and grows linearly from round-off and contact kicks
// (`backbone bench --case bouncing_bar` shows it); use Courant < 1 for long runs.
//
//   fem_bar::FemBarSolver fem;                       // FemOptions{} defaults
//   bar::SimulationOptions o; o.t_end = 3.1; o.elements = 100; o.dt = 1e-2;  // dt <= dx / c
//   bar::History h = fem.simulate(setup, o);         // lambda_n reported at t_n
//   bar::SnapshotRequest r; r.elements = 100; r.dt = 1e-2; r.projected_v = true;
//   bar::FieldSnapshot s = fem.snapshot(setup, 1.55, r);  // marches with dt' = t / ceil(t / dt)
//   if (!s.ok) { /* non-finite march: s.message */ }
#pragma once

#include <string>

#include "problems/bar/bar.hpp"

namespace backbone::fem_bar {

// How int w_h psi_i dx is computed for a snapshot's projected_u / projected_v.
enum class Projection {
  consistent,  // exact integral of the piecewise-linear FE field: h/6 (w_{i-1} + 4 w_i + w_{i+1})
  lumped,      // row-sum (nodal) quadrature: h w_i (h/2 at the ends), the scheme's own mass
};

struct FemOptions {
  Projection projection = Projection::consistent;
};

class FemBarSolver : public bar::BarSolver {
 public:
  explicit FemBarSolver(FemOptions options = {}) : options_(options) {}
  std::string name() const override { return "fem"; }

  // Rows at t_n = n dt' for n = 0..N, N = ceil(t_end / dt), dt' = t_end / N <= dt (dt' = dt when
  // t_end is a multiple of dt), so the last row is t_end (decimated to history_samples). u_contact
  // is u at the observed end, contact_force the multiplier lambda_n of the balance at t_n (its
  // impulse lambda_n dt acts between t_n - dt/2 and t_n + dt/2); energy uses v_n = (u_{n+1} -
  // u_{n-1}) / (2 dt) with the lumped mass (so it fluctuates by (omega_h dt / 2)^2 of each mode's
  // energy and is blind to the kinetic energy of a grid-scale (period 2 dt) oscillation, e.g. after
  // a release at Courant 1). If the march produces a non-finite value the history stops at the last
  // finite row. Throws InputError for an invalid setup / options or dt > dx / c.
  bar::History simulate(const bar::BarSetup& setup,
                        const bar::SimulationOptions& options) const override;

  // The field at t: marches n = ceil(t / dt) steps of dt' = t / n <= dt (so t is hit exactly
  // and the result is smooth in t while n is fixed; dt' = dt when t is a multiple of dt). Nodal v
  // is the central difference (u_{n+1} - u_{n-1}) / (2 dt'). Projections follow
  // FemOptions::projection.
  bar::FieldSnapshot snapshot(const bar::BarSetup& setup, double t,
                              const bar::SnapshotRequest& request) const override;

  // The largest stable step on `elements` intervals: dx / c.
  static double stable_time_step(const bar::BarSetup& setup, int elements);

 private:
  FemOptions options_;
};

}  // namespace backbone::fem_bar
