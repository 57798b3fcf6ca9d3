// The bar solvers a contact-bar scene can run, by name: tdbem (problems/contact_bar), fem
// (problems/fem_bar) and exact (problems/exact_bar), all behind bar::BarSolver.
//
//   auto names = contact_bar::bar_solver_names();          // {"tdbem", "fem", "exact"}
//   std::unique_ptr<bar::BarSolver> s =
//       contact_bar::make_bar_solver("tdbem", ContactMethod::event);
//   bar::History h = s->simulate(setup, options);
//   contact_bar::make_bar_solver("magic", ...);             // InputError "method: must be one of
//   ..."
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "problems/bar/bar.hpp"
#include "problems/contact_bar/solver/tdbem.hpp"

namespace backbone::contact_bar {

const std::vector<std::string>& bar_solver_names();
// `contact` selects the TD-BEM contact treatment; the other solvers have their own.
std::unique_ptr<bar::BarSolver> make_bar_solver(const std::string& method, ContactMethod contact);

}  // namespace backbone::contact_bar
