#include "problems/contact_bar/solver/bar_solvers.hpp"

#include <fmt/format.h>

#include "core/errors.hpp"
#include "problems/exact_bar/exact_bar_solver.hpp"
#include "problems/fem_bar/fem.hpp"

namespace backbone::contact_bar {

const std::vector<std::string>& bar_solver_names() {
  static const std::vector<std::string> names{"tdbem", "fem", "exact"};
  return names;
}

std::unique_ptr<bar::BarSolver> make_bar_solver(const std::string& method, ContactMethod contact) {
  if (method == "tdbem") return std::make_unique<TdbemSolver>(contact);
  if (method == "fem") return std::make_unique<fem_bar::FemBarSolver>();
  if (method == "exact") return std::make_unique<exact_bar::ExactBarSolver>();
  throw core::InputError("method",
                         fmt::format("must be one of tdbem, fem, exact, all (got '{}')", method));
}

}  // namespace backbone::contact_bar
