#include "core/io/scene.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>
#include <typeinfo>

#include "core/errors.hpp"

namespace backbone::core {

namespace {

constexpr const char* utf8_byte_order_mark = "\xEF\xBB\xBF";

// Boost builds its message by replacing placeholders such as %value% with the user's text
// until none is left: a value that itself contains "%value%" never ends (found by the fuzzer,
// tests/fuzz/). The user's text is given a lookalike percent sign (U+FF05) before what().
struct SubstitutionsOf : po::error_with_option_name {
  static constexpr auto member = &SubstitutionsOf::m_substitutions;
};

std::string message_of(const po::error& e) {
  const auto* named = dynamic_cast<const po::error_with_option_name*>(&e);
  if (!named) return e.what();
  po::error_with_option_name copy = *named;
  for (auto& [placeholder, text] : copy.*SubstitutionsOf::member) {
    std::string safe;
    for (char ch : text) safe += ch == '%' ? std::string("\xEF\xBC\x85") : std::string(1, ch);
    text = std::move(safe);
  }
  return copy.what();
}

// What a value of `key` must be, from its type in `keys` ("a number", "a whole number", ...).
std::string value_rule(const po::options_description* keys, const std::string& key) {
  const po::option_description* option = keys ? keys->find_nothrow(key, false) : nullptr;
  const auto* typed =
      option
          ? dynamic_cast<const po::value_semantic_codecvt_helper<char>*>(option->semantic().get())
          : nullptr;
  const auto* base = dynamic_cast<const po::typed_value_base*>(typed);
  if (!base) return "a valid value";
  const std::type_info& type = base->value_type();
  if (type == typeid(double)) return "a number (like 1e-3)";
  if (type == typeid(long) || type == typeid(int)) return "a whole number in the range of a long";
  if (type == typeid(bool)) return "true or false";
  return "a valid value";
}

// Boost's messages quote the option with its dashes; the user wants the key. A value that does
// not parse is named with the rule it breaks (keys: where the key's type is looked up).
[[noreturn]] void rethrow_as_input_error(const po::error& e, const std::string& where,
                                         const po::options_description* keys = nullptr) {
  if (const auto* invalid = dynamic_cast<const po::invalid_option_value*>(&e)) {
    std::string key = invalid->get_option_name();
    while (!key.empty() && key.front() == '-') key.erase(0, 1);
    po::error_with_option_name copy = *invalid;
    const auto& substitutions = copy.*SubstitutionsOf::member;
    const auto value = substitutions.find("value");
    if (!key.empty() && value != substitutions.end())
      throw InputError(key, fmt::format("'{}' is not {}", message_of(po::error(value->second)),
                                        value_rule(keys, key)));
  }
  std::string message = message_of(e);
  throw InputError("", where.empty() ? message : where + ": " + message);
}

std::string locate_scene(const std::string& ini_path) {
  std::error_code error;
  const std::filesystem::path path(ini_path);
  if (path.empty() || path.is_absolute() || std::filesystem::exists(path, error)) return ini_path;
  const std::filesystem::path shipped = shipped_path(path);
  return shipped.empty() ? ini_path : shipped.string();
}

// A scene file is a regular text file of at most this many bytes (the shipped ones are < 1 KiB).
constexpr std::uintmax_t max_scene_bytes = 1 << 20;

// Refuses what is not a scene's text: NUL bytes (a binary file), UTF-16 (a byte-order mark of
// FF FE or FE FF; Boost would read it as raw bytes), and [section] headers (Boost would prefix
// every key after one with the section's name, so `problem` would not be found).
void check_scene_text(const std::string& path, const std::string& content) {
  if (content.rfind("\xff\xfe", 0) == 0 || content.rfind("\xfe\xff", 0) == 0)
    throw InputError("scene", fmt::format("'{}' is UTF-16 text: save it as UTF-8", path));
  if (const auto nul = content.find('\0'); nul != std::string::npos)
    throw InputError("scene",
                     fmt::format("'{}' holds a NUL byte at offset {}: not a text file", path, nul));
  std::istringstream lines(content);
  std::string line;
  for (int number = 1; std::getline(lines, line); ++number) {
    const auto first = line.find_first_not_of(" \t");
    if (first != std::string::npos && line[first] == '=')
      throw InputError("scene", fmt::format("'{}' line {}: '{}' names no key (a scene line is "
                                            "`key = value`)",
                                            path, number, line));
    if (first != std::string::npos && line[first] == '[')
      throw InputError("scene", fmt::format("'{}' line {}: a scene has no [sections], only flat "
                                            "`key = value` lines",
                                            path, number));
  }
}

// The file's text without a leading UTF-8 byte-order mark (Boost would read it as part of the
// first key: "unrecognised option '\ufeffproblem'"). Only a regular file of at most
// max_scene_bytes is read: a device (/dev/zero) or a FIFO is refused before it is opened.
std::istringstream open_scene(const std::string& given_path) {
  if (given_path.rfind("--", 0) == 0)
    throw InputError("scene", fmt::format("the scene file comes first: backbone COMMAND SCENE "
                                          "[--key value ...] (got '{}' in its place)",
                                          given_path));
  const std::string ini_path = locate_scene(given_path);
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(ini_path, error);
  if (std::filesystem::is_directory(status))
    throw InputError("scene", fmt::format("'{}' is a directory, not a scene file", ini_path));
  if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
    throw InputError("scene", fmt::format("'{}' is not a regular file (a device, FIFO or "
                                          "socket), not a scene file",
                                          ini_path));
  if (std::filesystem::exists(status)) {
    const std::uintmax_t bytes = std::filesystem::file_size(ini_path, error);
    if (!error && bytes > max_scene_bytes)
      throw InputError("scene", fmt::format("'{}' has {} bytes; a scene file has at most {}",
                                            ini_path, bytes, max_scene_bytes));
  }
  std::ifstream in(ini_path);
  if (!in)
    throw InputError("scene", fmt::format("cannot read scene file '{}' (nor in the source tree "
                                          "{})",
                                          ini_path, BACKBONE_SOURCE_DIR));
  std::stringstream text;
  text << in.rdbuf();
  std::string content = text.str();
  if (content.rfind(utf8_byte_order_mark, 0) == 0)
    content.erase(0, std::string_view(utf8_byte_order_mark).size());
  check_scene_text(ini_path, content);
  return std::istringstream(content);
}

// "--gap -1" would read "-1" as an option: glue a negative number to its key.
// The key of a word `--key` (without `=value`), or empty.
std::string key_of(const std::string& word) {
  if (word.rfind("--", 0) != 0 || word.find('=') != std::string::npos) return {};
  return word.substr(2);
}

// Refuses, naming the key, a `--key` that needs a value but is followed by another `--key` or
// by nothing (Boost would take the next key as its value, or report a word further on), and a
// word that follows a key that takes no value (Boost would report the word, not the key).
void check_key_values(const std::vector<std::string>& words, const po::options_description& keys) {
  for (std::size_t i = 0; i < words.size(); ++i) {
    const std::string key = key_of(words[i]);
    const po::option_description* option = key.empty() ? nullptr : keys.find_nothrow(key, false);
    if (!option) continue;
    const bool next_is_key = i + 1 < words.size() && !key_of(words[i + 1]).empty();
    if (option->semantic()->min_tokens() > 0 && (i + 1 == words.size() || next_is_key))
      throw InputError(key,
                       i + 1 == words.size()
                           ? std::string("needs a value (none given at the end)")
                           : fmt::format("needs a value (got the key '{}' next)", words[i + 1]));
    if (option->semantic()->max_tokens() == 0 && i + 1 < words.size() && !next_is_key &&
        words[i + 1].rfind("-", 0) != 0)
      throw InputError(key, fmt::format("takes no value (got '{}' after it)", words[i + 1]));
  }
}

std::vector<std::string> glue_negative_values(const std::vector<std::string>& words) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < words.size(); ++i) {
    const std::string& w = words[i];
    if (w.rfind("--", 0) == 0 && w.find('=') == std::string::npos && i + 1 < words.size() &&
        words[i + 1].size() > 1 && words[i + 1][0] == '-' &&
        (std::isdigit(static_cast<unsigned char>(words[i + 1][1])) || words[i + 1][1] == '.')) {
      out.push_back(w + "=" + words[i + 1]);
      ++i;
    } else {
      out.push_back(w);
    }
  }
  return out;
}

}  // namespace

std::filesystem::path shipped_path(const std::filesystem::path& relative) {
  std::error_code error;
  std::vector<std::filesystem::path> roots;
  const std::filesystem::path executable = std::filesystem::read_symlink("/proc/self/exe", error);
  if (!error) roots.push_back(executable.parent_path().parent_path() / "share" / "backbone");
  roots.emplace_back(BACKBONE_SOURCE_DIR);
  for (const std::filesystem::path& root : roots)
    if (std::filesystem::exists(root / relative, error)) return root / relative;
  return {};
}

double Scene::number(const std::string& key) const {
  if (!has(key)) throw InputError(key, "is required but was not given");
  double v = 0;
  try {
    v = values_[key].as<double>();
  } catch (const boost::bad_any_cast&) {
    throw InputError(key, "is not a number");
  }
  if (!std::isfinite(v)) throw InputError(key, fmt::format("must be a finite number (got {})", v));
  return v;
}

double Scene::positive(const std::string& key) const {
  double v = number(key);
  if (!(v > 0)) throw InputError(key, fmt::format("must be > 0 (got {})", v));
  return v;
}

double Scene::non_negative(const std::string& key) const {
  double v = number(key);
  if (!(v >= 0)) throw InputError(key, fmt::format("must be >= 0 (got {})", v));
  return v;
}

long Scene::integer(const std::string& key, long min_value, long max_value) const {
  if (!has(key)) throw InputError(key, "is required but was not given");
  long v = 0;
  try {
    v = values_[key].as<long>();
  } catch (const boost::bad_any_cast&) {
    throw InputError(key, "is not an integer");
  }
  if (v < min_value) throw InputError(key, fmt::format("must be >= {} (got {})", min_value, v));
  if (v > max_value) throw InputError(key, fmt::format("must be <= {} (got {})", max_value, v));
  return v;
}

std::string Scene::text(const std::string& key) const {
  if (!has(key)) throw InputError(key, "is required but was not given");
  return values_[key].as<std::string>();
}

std::string Scene::choice(const std::string& key,
                          std::initializer_list<const char*> allowed) const {
  std::string v = text(key);
  std::string list;
  for (const char* a : allowed) {
    if (v == a) return v;
    list += list.empty() ? a : std::string(", ") + a;
  }
  throw InputError(key, fmt::format("must be one of {} (got '{}')", list, v));
}

bool Scene::flag(const std::string& key) const {
  return has(key) && values_[key].as<bool>();
}

Scene read_scene(const po::options_description& scene_keys, const std::string& ini_path,
                 const std::vector<std::string>& arguments,
                 const po::options_description& driver_keys) {
  po::variables_map vm;
  // The scene file may name its problem; that key belongs to every scene.
  po::options_description file_keys;
  file_keys.add(scene_keys);
  if (!scene_keys.find_nothrow("problem", false))
    file_keys.add_options()("problem", po::value<std::string>(), "problem the scene is for");
  po::options_description cli_keys;
  cli_keys.add(file_keys).add(driver_keys);
  try {
    // Command line first: po::store keeps the first value it sees, so the command line wins.
    std::vector<std::string> words = glue_negative_values(arguments);
    check_key_values(words, cli_keys);
    const po::parsed_options parsed =
        po::command_line_parser(words)
            .options(cli_keys)
            .style(po::command_line_style::unix_style ^ po::command_line_style::allow_guessing)
            .run();
    // Boost keeps a word that is no `--key value` as a positional value and would drop it.
    for (const std::string& word : po::collect_unrecognized(parsed.options, po::include_positional))
      throw InputError(
          "command line",
          fmt::format("unexpected argument '{}' (keys are given as --key value)", word));
    po::store(parsed, vm);
  } catch (const po::error& e) {
    rethrow_as_input_error(e, "command line", &cli_keys);
  }
  if (!ini_path.empty()) {
    std::istringstream in = open_scene(ini_path);
    try {
      po::store(po::parse_config_file(in, file_keys, /*allow_unregistered=*/false), vm);
    } catch (const po::error& e) {
      rethrow_as_input_error(e, ini_path, &file_keys);
    }
  }
  try {
    po::notify(vm);
  } catch (const po::error& e) {
    rethrow_as_input_error(e, "", &cli_keys);
  }
  return Scene(std::move(vm), ini_path);
}

po::variables_map parse_options(const po::options_description& keys,
                                const std::vector<std::string>& arguments) {
  po::variables_map vm;
  check_key_values(glue_negative_values(arguments), keys);
  try {
    const po::parsed_options parsed = po::command_line_parser(arguments).options(keys).run();
    for (const std::string& word : po::collect_unrecognized(parsed.options, po::include_positional))
      throw InputError(
          "command line",
          fmt::format("unexpected argument '{}' (keys are given as --key value)", word));
    po::store(parsed, vm);
    po::notify(vm);
  } catch (const po::error& e) {
    rethrow_as_input_error(e, "", &keys);
  }
  return vm;
}

std::string scene_problem_name(const std::string& ini_path) {
  std::istringstream in = open_scene(ini_path);
  po::options_description keys;
  keys.add_options()("problem", po::value<std::string>()->default_value(""), "");
  po::variables_map vm;
  try {
    po::store(po::parse_config_file(in, keys, /*allow_unregistered=*/true), vm);
    po::notify(vm);
  } catch (const po::error& e) {
    rethrow_as_input_error(e, ini_path);
  }
  return vm["problem"].as<std::string>();
}

std::vector<std::string> list_words(const std::string& text, const std::string& separators) {
  std::string spaced = text;
  for (char& ch : spaced)
    if (separators.find(ch) != std::string::npos) ch = ' ';
  std::istringstream in(spaced);
  std::vector<std::string> words;
  for (std::string word; in >> word;) words.push_back(word);
  return words;
}

std::vector<int> parse_increasing_integers(const std::string& text, const std::string& key,
                                           long min_value, long max_value,
                                           const std::string& what) {
  std::vector<int> list;
  for (const std::string& word : list_words(text)) {
    std::size_t used = 0;
    long value = 0;
    try {
      value = std::stol(word, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != word.size() || value < min_value || value > max_value)
      throw InputError(key, fmt::format("'{}' is not {} in {}..{} (in '{}')", word, what, min_value,
                                        max_value, text));
    if (!list.empty() && value <= list.back())
      throw InputError(
          key, fmt::format("must increase ({} after {} in '{}')", value, list.back(), text));
    list.push_back(static_cast<int>(value));
  }
  if (list.empty()) throw InputError(key, fmt::format("no {} in '{}'", what, text));
  return list;
}

}  // namespace backbone::core
