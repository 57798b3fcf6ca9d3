#include "continuation/restart.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "continuation/internal/loop_steps.hpp"
#include "continuation/outputs.hpp"
#include "core/errors.hpp"
#include "core/io/table.hpp"

namespace backbone::continuation {

namespace {

// fmt's "{}" is the shortest text that reads back to the same double (std::strtod).
std::string number(double v) {
  return fmt::format("{}", v);
}

std::string numbers(const core::Vector& v) {
  std::string text;
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (i) text += ',';
    text += number(v[i]);
  }
  return text;
}

class StateReader {
 public:
  StateReader(const std::string& line, const std::string& key, const std::string& where)
      : key_(key), where_(where) {
    std::istringstream in(line);
    std::string token;
    while (in >> token) {
      const auto eq = token.find('=');
      if (eq == std::string::npos || eq == 0) fail(fmt::format("'{}' is not name=value", token));
      fields_[token.substr(0, eq)] = token.substr(eq + 1);
    }
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw core::InputError(key_, fmt::format("{}: {}", where_, what));
  }
  const std::string& text(const std::string& name) const {
    const auto it = fields_.find(name);
    if (it == fields_.end()) fail(fmt::format("no '{}'", name));
    return it->second;
  }
  bool has(const std::string& name) const { return fields_.count(name) > 0; }
  double value(const std::string& name) const { return parse(text(name), name); }
  int whole(const std::string& name) const {
    const double v = value(name);
    if (!(v >= -1 && v < 1e9 && v == std::floor(v)))
      fail(fmt::format("'{}' = {} is not a whole number in [-1, 1e9)", name, v));
    return static_cast<int>(v);
  }
  core::Vector vector(const std::string& name) const {
    const std::string& t = text(name);
    std::vector<double> values;
    std::size_t start = 0;
    while (start < t.size()) {
      const auto comma = std::min(t.find(',', start), t.size());
      values.push_back(parse(t.substr(start, comma - start), name));
      start = comma + 1;
    }
    return Eigen::Map<const core::Vector>(values.data(), static_cast<Eigen::Index>(values.size()));
  }

 private:
  double parse(const std::string& t, const std::string& name) const {
    char* end = nullptr;
    const double v = std::strtod(t.c_str(), &end);
    if (t.empty() || end != t.c_str() + t.size())
      fail(fmt::format("'{}' of '{}' is not a number", t, name));
    return v;
  }
  std::string key_, where_;
  std::map<std::string, std::string> fields_;
};

}  // namespace

std::string format_state(const LoopState& s) {
  std::string line = fmt::format(
      "method={} index={} arclength={} ds={} lambda={} previous_step={} switch_index={} "
      "jacobian_scale={} scale={} z={} tangent={} previous={} jacobian_point={} chord_misses={} "
      "rejected_corrections={} brackets={} samples={}",
      to_string(s.method), s.index, number(s.arclength), number(s.ds), number(s.lambda),
      number(s.previous_step), s.switch_index, number(s.jacobian_scale), numbers(s.scale),
      numbers(s.z), numbers(s.tangent), numbers(s.previous), numbers(s.jacobian_point),
      s.chord_misses, s.rejected_corrections, s.brackets, s.samples.size());
  for (std::size_t k = 0; k < s.samples.size(); ++k) {
    const TestFunctionSample& a = s.samples[k];
    line += fmt::format(
        " sample{0}.index={1} sample{0}.s={2} sample{0}.value={3} sample{0}.continued={4} "
        "sample{0}.z={5} sample{0}.tangent={6} sample{0}.left={7} sample{0}.right={8}",
        k, a.index, number(a.s), number(a.tau.value), a.tau.continued ? 1 : 0, numbers(a.z),
        numbers(a.tangent), numbers(a.tau.left), numbers(a.tau.right));
  }
  return line;
}

LoopState parse_state(const std::string& line, const std::string& key, const std::string& where) {
  const StateReader in(line, key, where);
  LoopState s;
  const std::string& method = in.text("method");
  if (method != to_string(Method::arclength) && method != to_string(Method::natural))
    in.fail(fmt::format("method '{}' is not arclength or natural", method));
  s.method = parse_method(method);
  s.index = in.whole("index");
  s.arclength = in.value("arclength");
  s.ds = in.value("ds");
  s.lambda = in.value("lambda");
  s.previous_step = in.value("previous_step");
  s.switch_index = in.whole("switch_index");
  s.jacobian_scale = in.value("jacobian_scale");
  s.scale = in.vector("scale");
  s.z = in.vector("z");
  s.tangent = in.vector("tangent");
  s.previous = in.vector("previous");
  // Absent from states written before chord corrections: the first step then corrects with a
  // fresh Jacobian.
  if (in.has("jacobian_point")) s.jacobian_point = in.vector("jacobian_point");
  if (in.has("chord_misses")) s.chord_misses = in.whole("chord_misses");
  if (in.has("rejected_corrections")) {
    s.rejected_corrections = in.whole("rejected_corrections");
    if (s.rejected_corrections < 0)
      in.fail(fmt::format("rejected_corrections {} is negative", s.rejected_corrections));
  }
  if (in.has("brackets")) s.brackets = in.whole("brackets");
  const int samples = in.whole("samples");
  if (samples < 0 || samples > 3) in.fail(fmt::format("{} detector samples (at most 3)", samples));
  for (int k = 0; k < samples; ++k) {
    const std::string p = fmt::format("sample{}.", k);
    TestFunctionSample a;
    a.index = in.whole(p + "index");
    a.s = in.value(p + "s");
    a.tau.value = in.value(p + "value");
    a.tau.continued = in.value(p + "continued") != 0;
    a.z = in.vector(p + "z");
    a.tangent = in.vector(p + "tangent");
    a.tau.left = in.vector(p + "left");
    a.tau.right = in.vector(p + "right");
    s.samples.push_back(std::move(a));
  }
  const Eigen::Index n = s.z.size();
  const bool sizes_agree =
      n > 0 && s.scale.size() == n && (s.tangent.size() == n || s.tangent.size() == 0) &&
      (s.previous.size() == n || s.previous.size() == 0) &&
      (s.jacobian_point.size() == n || s.jacobian_point.size() == 0) &&
      std::all_of(s.samples.begin(), s.samples.end(), [&](const TestFunctionSample& a) {
        return a.z.size() == n && a.tangent.size() == n && a.tau.right.size() == n;
      });
  if (!sizes_agree) in.fail(fmt::format("the vectors of the loop state differ in size"));
  if (s.method == Method::arclength && s.tangent.size() == 0)
    in.fail("an arclength state needs its tangent");
  if (!(s.ds > 0) || !s.z.allFinite() || !s.scale.allFinite())
    in.fail("the loop state has no finite point, scale and positive step");
  return s;
}

std::pair<std::filesystem::path, int> parse_saved_point(const std::string& text,
                                                        const std::string& key) {
  const auto colon = text.rfind(':');
  int point = -1;
  try {
    std::size_t used = 0;
    if (colon != std::string::npos) point = std::stoi(text.substr(colon + 1), &used);
    if (colon == std::string::npos || used != text.size() - colon - 1) point = -1;
  } catch (const std::exception&) {
    point = -1;
  }
  if (point < 0) throw core::InputError(key, fmt::format("'{}' is not DIR:K with K >= 0", text));
  std::filesystem::path dir = text.substr(0, colon);
  if (dir.has_extension()) dir = dir.parent_path();
  return {dir, point};
}

namespace {

// The state saved with point `point` in state.txt (null when the file or the state is absent).
std::shared_ptr<const LoopState> read_state(const std::filesystem::path& path, int point,
                                            const std::string& key) {
  std::ifstream in(path);
  if (!in) return nullptr;
  std::string line;
  const std::string prefix = fmt::format("{} ", point);
  while (std::getline(in, line)) {
    if (line.rfind(prefix, 0) != 0) continue;
    const std::string rest = line.substr(prefix.size());
    if (rest == "-") return nullptr;
    auto state = std::make_shared<LoopState>(
        parse_state(rest, key, fmt::format("'{}', point {}", path.string(), point)));
    if (state->index != point)
      throw core::InputError(key, fmt::format("'{}': the state of point {} says index {}",
                                              path.string(), point, state->index));
    return state;
  }
  return nullptr;
}

// Per line of state.txt after its header: the point and the whole value of its state's field
// `name`; -1 for a point without a state (`K -`), -2 for a state without the field (or with a
// negative value).
std::vector<std::pair<int, int>> saved_field(const std::filesystem::path& path,
                                             const std::string& name) {
  std::vector<std::pair<int, int>> out;
  std::ifstream in(path);
  std::string line;
  const std::string token = " " + name + "=";
  for (bool header = true; std::getline(in, line); header = false) {
    if (header) continue;
    const int point = std::atoi(line.c_str());
    const auto at = line.find(token);
    const bool stateless = line.size() >= 2 && line.compare(line.size() - 2, 2, " -") == 0;
    const int value = at == std::string::npos ? -2 : std::atoi(line.c_str() + at + token.size());
    out.emplace_back(point, stateless ? -1 : value < 0 ? -2 : value);
  }
  return out;
}

// LoopState::rejected_corrections of the last state saved at or before point `point` (0 when
// there is none): the count a restart from a point without a state carries on.
int refused_up_to(const std::filesystem::path& path, int point) {
  int refused = 0;
  for (const auto& [k, n] : saved_field(path, "rejected_corrections"))
    if (k <= point && n >= 0) refused = n;
  return refused;
}

}  // namespace

RestartPoint restart_point(const std::filesystem::path& dir, int point,
                           const ContinuationOptions& options, const std::string& key) {
  RestartPoint r;
  core::Table table({"point"});
  try {
    table = core::Table::read_csv(dir / "branch.csv");
  } catch (const core::InputError& e) {
    throw core::InputError(key, e.what());
  }
  const std::string file = (dir / "branch.csv").string();
  const auto column = [&](const char* name) {
    try {
      return table.column(name);
    } catch (const core::InputError& e) {
      throw core::InputError(key, e.what());
    }
  };
  const auto index = column("point"), step = column("step_size"),
             iterations = column("newton_iterations"), arclength = column("arclength");
  if (index.empty()) throw core::InputError(key, fmt::format("'{}' holds no point", file));
  const double wanted = point < 0 ? index.back() : point;
  const auto row = std::find(index.begin(), index.end(), wanted);
  if (row == index.end())
    throw core::InputError(
        key, fmt::format("'{}' has no point {}", file, static_cast<long long>(wanted)));
  const std::size_t i = static_cast<std::size_t>(row - index.begin());
  if (!(wanted >= 0 && wanted < 1e9 && iterations[i] >= 0 && iterations[i] < 1e6 &&
        std::isfinite(step[i]) && std::isfinite(arclength[i])))
    throw core::InputError(key, fmt::format("'{}': point {} has no valid step, iterations and "
                                            "arclength",
                                            file, wanted));
  r.index = static_cast<int>(wanted);
  r.x = read_unknowns(dir / "unknowns.csv", r.index, key);
  r.arclength = arclength[i];
  if (r.index > 0) {
    r.previous_x = read_unknowns(dir / "unknowns.csv", r.index - 1, key);
    r.secant = r.x - r.previous_x;
    const auto before = std::find(index.begin(), index.end(), wanted - 1);
    if (before != index.end())
      r.previous_arclength = arclength[static_cast<std::size_t>(before - index.begin())];
    else
      r.previous_x.resize(0);
    r.next_step = adapted_step(step[i], static_cast<int>(iterations[i]), options);
  }
  r.state = read_state(dir / "state.txt", r.index, key);
  r.rejected_corrections =
      r.state ? r.state->rejected_corrections : refused_up_to(dir / "state.txt", r.index);
  return r;
}

std::string state_mismatch(const LoopState& state, const core::Problem& problem,
                           const ContinuationOptions& options) {
  const bool natural_run =
      options.method == Method::natural ||
      (options.method == Method::natural_then_arclength && state.switch_index < 0);
  return state_mismatch(state, problem, options, natural_run ? Method::natural : Method::arclength);
}

std::string state_mismatch(const LoopState& state, const core::Problem& problem,
                           const ContinuationOptions& options, Method loop) {
  const int n = problem.num_unknowns();
  if (state.z.size() != n)
    return fmt::format("the saved state has {} unknowns, the problem {}", state.z.size(), n);
  const ScaledProblem scaled(problem, loop_unit_scale(problem, options));
  if (state.scale != scaled.scale())
    return "the saved state was taken in other scaled units (another scene or scale_unknowns)";
  if (state.method != loop)
    return fmt::format("the saved state is of a {} loop, this run's is {}", to_string(state.method),
                       to_string(loop));
  return {};
}

void take_up(RestartPoint& restart, const std::string& key, int direction,
             const core::Problem& problem, ContinuationOptions& options, core::Vector& guess,
             core::Vector& hint) {
  if (restart.x.size() != guess.size())
    throw core::InputError(key, fmt::format("the saved point has {} unknowns, this scene's "
                                            "problem {} (same grid keys?)",
                                            restart.x.size(), guess.size()));
  if (restart.index + 1 > options.max_points ||
      (restart.index + 1 == options.max_points && !restart.loop_complete))
    throw core::InputError(
        "max_points", fmt::format("the saved branch has {} points already", restart.index + 1));
  if (restart.state) {
    restart.note = state_mismatch(*restart.state, problem, options);
    if (!restart.note.empty()) restart.state = nullptr;
  }
  // Along the branch the loop looks back on the saved point and the one before, as the files
  // hold them (their observables recomputed from the saved unknowns: the same bits).
  if (restart.state && direction > 0 && restart.previous_x.size() == restart.x.size()) {
    auto known = std::make_shared<LoopState>(*restart.state);
    known->known_points = {
        {restart.index - 1, restart.previous_arclength, problem.observables(restart.previous_x)},
        {restart.index, restart.arclength, problem.observables(restart.x)}};
    restart.state = known;
  }
  if (restart.state && direction < 0) {
    auto back = std::make_shared<LoopState>(*restart.state);
    back->tangent = -back->tangent;
    back->previous = back->method == Method::natural ? back->z : core::Vector();
    back->previous_step = 0;
    back->samples.clear();
    restart.state = back;
  }
  guess = restart.x;
  if (restart.secant.size() == guess.size()) hint = restart.secant;
  hint *= static_cast<double>(direction);
  // A state carries its own step (options.ds stays the first step of a later arclength part).
  if (restart.next_step > 0 && !restart.state)
    options.ds = std::clamp(restart.next_step, options.ds_min, options.ds_max);
}

namespace {

const char* const saved_branch_points_header =
    "branch points located so far (continuation/README.md, section 'Restart files')";

std::string format_branch_point(const BranchPointReport& r) {
  std::string line = fmt::format(
      "bracket={} after_point={} arclength={} test_value={} sign_change={} location_steps={} "
      "jacobian_evaluations={} residual_evaluations={} nullity={} attached_dimension={} "
      "candidates={} probed={} verified_dimension={} tangent_angle={} x={} attached_point={} "
      "attached_points={}",
      r.bracket, r.after_point, number(r.arclength), number(r.test_value), r.sign_change ? 1 : 0,
      r.location_steps, r.jacobian_evaluations, r.residual_evaluations, r.nullity,
      r.attached_dimension, r.candidates, r.probed, r.verified_dimension, number(r.tangent_angle),
      numbers(r.x), numbers(r.attached_point), r.attached_points.size());
  for (std::size_t k = 0; k < r.attached_points.size(); ++k)
    line += fmt::format(" attached{}={}", k, numbers(r.attached_points[k]));
  line += fmt::format(" described={}", r.attached_description.size());
  for (std::size_t k = 0; k < r.attached_description.size(); ++k) {
    const std::string& name = r.attached_description[k].first;
    // The problem's observable names (csv columns): one token each.
    if (name.empty() || name.find_first_of(" \t\n=") != std::string::npos)
      throw std::logic_error(fmt::format("the description name '{}' is not one token", name));
    line +=
        fmt::format(" name{0}={1} value{0}={2}", k, name, number(r.attached_description[k].second));
  }
  return line;
}

BranchPointReport parse_branch_point(const std::string& line, const core::Problem& problem,
                                     const std::string& key, const std::string& where) {
  const StateReader in(line, key, where);
  BranchPointReport r;
  r.bracket = in.whole("bracket");
  r.after_point = in.whole("after_point");
  r.arclength = in.value("arclength");
  r.test_value = in.value("test_value");
  r.sign_change = in.whole("sign_change") != 0;
  r.location_steps = in.whole("location_steps");
  // Counts of a long run: whole numbers below 2^53.
  const auto count = [&](const std::string& name) {
    const double v = in.value(name);
    if (!(v >= 0 && v < 9e15 && v == std::floor(v)))
      in.fail(fmt::format("'{}' = {} is not a count", name, v));
    return static_cast<long>(v);
  };
  r.jacobian_evaluations = count("jacobian_evaluations");
  r.residual_evaluations = count("residual_evaluations");
  r.nullity = in.whole("nullity");
  r.attached_dimension = in.whole("attached_dimension");
  r.candidates = in.whole("candidates");
  r.probed = in.whole("probed");
  r.verified_dimension = in.whole("verified_dimension");
  r.tangent_angle = in.value("tangent_angle");
  r.x = in.vector("x");
  r.attached_point = in.vector("attached_point");
  const int attached = in.whole("attached_points");
  for (int k = 0; k < attached; ++k)
    r.attached_points.push_back(in.vector(fmt::format("attached{}", k)));
  const int described = in.whole("described");
  for (int k = 0; k < described; ++k)
    r.attached_description.emplace_back(in.text(fmt::format("name{}", k)),
                                        in.value(fmt::format("value{}", k)));
  const Eigen::Index n = problem.num_unknowns();
  const bool sizes_agree =
      r.x.size() == n && r.x.allFinite() &&
      (r.attached_point.size() == 0 || r.attached_point.size() == n) &&
      r.attached_point.allFinite() &&
      std::all_of(r.attached_points.begin(), r.attached_points.end(),
                  [&](const core::Vector& y) { return y.size() == n && y.allFinite(); });
  if (r.bracket < 0 || attached < 0 || described < 0 || !sizes_agree)
    in.fail(fmt::format("not a located candidate of this problem's {} unknowns", n));
  r.observables = problem.observables(r.x);
  return r;
}

}  // namespace

void SavedBranchPoints::write(const std::filesystem::path& out) const {
  std::string text = fmt::format("{}\nsettled={}\n", saved_branch_points_header, settled);
  for (const BranchPointReport& r : reports) text += format_branch_point(r) + "\n";
  core::write_text_atomically(out / "branch_points.txt", text);
}

SavedBranchPoints read_saved_branch_points(const std::filesystem::path& dir,
                                           const core::Problem& problem, const std::string& key) {
  const std::filesystem::path path = dir / "branch_points.txt";
  std::ifstream in(path);
  if (!in) throw core::InputError(key, fmt::format("cannot read '{}'", path.string()));
  SavedBranchPoints saved;
  std::string line;
  int number_of_line = 0;
  while (std::getline(in, line)) {
    ++number_of_line;
    const std::string where = fmt::format("'{}', line {}", path.string(), number_of_line);
    if (number_of_line == 1) {
      if (line != saved_branch_points_header)
        throw core::InputError(key, fmt::format("{}: not the header of a list of located "
                                                "branch points",
                                                where));
      continue;
    }
    if (number_of_line == 2) {
      const StateReader settled(line, key, where);
      saved.settled = settled.whole("settled");
      continue;
    }
    saved.reports.push_back(parse_branch_point(line, problem, key, where));
    if (saved.reports.size() > 1 &&
        saved.reports.back().bracket <= saved.reports[saved.reports.size() - 2].bracket)
      throw core::InputError(key, fmt::format("{}: the brackets are not in order", where));
  }
  if (number_of_line < 2 || saved.settled < 0)
    throw core::InputError(key,
                           fmt::format("'{}' has no count of settled brackets", path.string()));
  // A candidate is written before the count that settles its bracket.
  if (!saved.reports.empty())
    saved.settled = std::max(saved.settled, saved.reports.back().bracket + 1);
  return saved;
}

std::optional<BranchPointResume> branch_point_resume(const std::filesystem::path& dir, int last,
                                                     const core::Problem& problem,
                                                     const std::string& key) {
  if (!std::filesystem::exists(dir / "branch_points.txt")) return std::nullopt;
  // The brackets each point's state had made, in the order of the file: -1 for a point without
  // a state, -2 for a state that does not count them (a run without detection, or a loop
  // without a detector).
  const std::vector<std::pair<int, int>> brackets = saved_field(dir / "state.txt", "brackets");
  BranchPointResume r;
  r.saved = read_saved_branch_points(dir, problem, key);
  int made = -1;
  for (auto it = brackets.rbegin(); it != brackets.rend(); ++it) {
    if (it->first > last) continue;
    if (it->second == -2) return std::nullopt;  // a state that does not count brackets
    if (it->second < 0) continue;               // a point without a state (landed on a bound)
    if (it->second <= r.saved.settled) {
      r.point = it->first;
      made = it->second;
      break;
    }
  }
  if (made < 0) return std::nullopt;
  std::erase_if(r.saved.reports, [&](const BranchPointReport& b) { return b.bracket >= made; });
  r.saved.settled = made;
  return r;
}

}  // namespace backbone::continuation
