// The bar solvers the CLI can run, by name: tdbem (problems/contact_bar), fem (problems/fem_bar)
// and exact (problems/exact_bar), all behind bar::BarSolver.
//
//   auto names = drivers::bar_solver_names();          // {"tdbem", "fem", "exact"}
//   std::unique_ptr<bar::BarSolver> s =
//       drivers::make_bar_solver("tdbem", contact_bar::ContactMethod::event);
//   bar::History h = s->simulate(setup, options);
//   drivers::make_bar_solver("magic", ...);             // InputError "method: must be one of ..."
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "problems/bar/bar.hpp"
#include "problems/contact_bar/tdbem.hpp"

namespace backbone::drivers {

const std::vector<std::string>& bar_solver_names();
// `contact` selects the TD-BEM contact treatment; the other solvers have their own.
std::unique_ptr<bar::BarSolver> make_bar_solver(const std::string& method,
                                                contact_bar::ContactMethod contact);

}  // namespace backbone::drivers
