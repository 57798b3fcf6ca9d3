// Scenes: INI files of named keys, merged as defaults < scene file < command line.
//
// A problem declares its keys (with defaults and a one-line description giving the unit) in a
// boost::program_options::options_description. read_scene parses the INI file against exactly
// those keys and then the command-line overrides (`--key value`) against those keys plus the
// driver's own options (`--gap -1` reads -1 as the value). Unknown keys, unreadable files,
// malformed or non-finite numbers, integers beyond the int range, a directory given as the file
// and words that are not `--key value` pairs are InputErrors naming the key: the CLI turns them
// into one line on stderr and exit code 2. A UTF-8 byte-order mark at the start of a file is
// skipped (editors on Windows write one). Keys are flat (no INI sections) so that every key reads
// the same in the file and on the command line. The key `problem` names the problem the scene is
// for (no default: core knows no problem; the CLI says which are known when it is missing).
//
//   namespace po = boost::program_options;
//   po::options_description keys("contact bar");
//   keys.add_options()("length", po::value<double>()->default_value(1.0), "bar length L [m]");
//   Scene scene = read_scene(keys, "paper.ini", {"--length", "2"}, driver_keys);
//   double L = scene.positive("length");      // 2, or InputError "length: must be > 0 (got -1)"
#pragma once

#include <boost/program_options.hpp>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <string>
#include <vector>

namespace backbone::core {

namespace po = boost::program_options;

class Scene {
 public:
  Scene() = default;
  Scene(po::variables_map values, std::string path)
      : values_(std::move(values)), path_(std::move(path)) {}

  bool has(const std::string& key) const { return values_.count(key) > 0; }
  // Typed, validated accessors. Each throws InputError(key, constraint) on violation.
  double number(const std::string& key) const;        // finite
  double positive(const std::string& key) const;      // finite and > 0
  double non_negative(const std::string& key) const;  // finite and >= 0
  // Integral and in [min_value, max_value]; the default max is INT_MAX since callers store the
  // value in an int ("max_points: must be <= 2147483647 (got 4294967298)").
  long integer(const std::string& key, long min_value,
               long max_value = std::numeric_limits<int>::max()) const;
  std::string text(const std::string& key) const;
  std::string choice(const std::string& key, std::initializer_list<const char*> allowed) const;
  bool flag(const std::string& key) const;

  const po::variables_map& values() const { return values_; }
  const std::string& path() const { return path_; }

 private:
  po::variables_map values_;
  std::string path_;
};

// Parses `ini_path` against `scene_keys` (unknown key -> InputError), then `arguments`
// (command-line words after the scene path) against scene_keys + driver_keys. Values given on
// the command line win. An empty ini_path means "defaults + command line only".
Scene read_scene(const po::options_description& scene_keys, const std::string& ini_path,
                 const std::vector<std::string>& arguments,
                 const po::options_description& driver_keys);

// Options of a command without a scene (bench, figures, reproduce): parses `arguments` against
// `keys`; an unknown option, a missing value or a stray word is an InputError.
po::variables_map parse_options(const po::options_description& keys,
                                const std::vector<std::string>& arguments);

// The words of a list separated by spaces or any of `separators` ("1, 2 3" -> 1 2 3).
std::vector<std::string> list_words(const std::string& text, const std::string& separators = ",");

// "20,40,80" or "20 40 80": whole numbers in [min_value, max_value], strictly increasing, at
// least one; InputError(key) naming the word and `what` each must be ("a node", "a grid of
// intervals") otherwise.
std::vector<int> parse_increasing_integers(const std::string& text, const std::string& key,
                                           long min_value, long max_value, const std::string& what);

// The value of the `problem` key of an INI file (empty when absent), read before the
// problem's keys are known. Throws InputError when the file cannot be read.
std::string scene_problem_name(const std::string& ini_path);

// A file or folder shipped with backbone (scenes, stored peer data), by its path in the source
// tree (`problems/contact_bar/scenes/paper.ini`): PREFIX/share/backbone/PATH of the install the
// running executable belongs to, else the source tree the binary was built from; empty when
// neither holds it. A relative scene path that names no file in the working directory is looked
// up there, so the shipped scenes (and the steps of `backbone reproduce`) work from any folder.
std::filesystem::path shipped_path(const std::filesystem::path& relative);

}  // namespace backbone::core
