// The table of problems `backbone trace` can follow (see trace_registry.hpp).
#include "drivers/trace_registry.hpp"

namespace backbone::drivers {

namespace {
std::map<std::string, TraceProblem>& trace_table() {
  static std::map<std::string, TraceProblem> table;
  return table;
}
}  // namespace

bool register_trace_problem(TraceProblem problem) {
  std::string name = problem.name;
  return trace_table().emplace(name, std::move(problem)).second;
}

const std::map<std::string, TraceProblem>& trace_problems() {
  return trace_table();
}

}  // namespace backbone::drivers
