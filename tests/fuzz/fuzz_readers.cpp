// Fuzz targets of the readers a user feeds by hand: scene INI files (core::read_scene against
// the contact bar's keys, then every typed accessor and the bar setup they build), CSV tables
// (core::Table::read_csv) and the restart format (continuation::read_unknowns). Each input is
// written to a scratch file and read; bad input must end in core::InputError, never in a
// crash, a hang, undefined behaviour or another exception.
//
// Built two ways (tests/fuzz/CMakeLists.txt): with clang's libFuzzer when BACKBONE_FUZZ=ON
// (`fuzz_readers -max_total_time=120 tests/fuzz/corpus/scene`), and always as a ctest test
// that replays the corpus in tests/fuzz/corpus, so the targets cannot rot.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "continuation/outputs.hpp"
#include "core/errors.hpp"
#include "core/io/scene.hpp"
#include "core/io/table.hpp"
#include "problems/contact_bar/solver/scene.hpp"

namespace {

namespace fs = std::filesystem;

fs::path scratch_file(const char* name) {
  static const fs::path dir = [] {
    fs::path d = fs::temp_directory_path() / ("backbone_fuzz_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir / name;
}

void write(const fs::path& path, const std::uint8_t* data, std::size_t size) {
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

void read_scene_file(const fs::path& path) {
  using namespace backbone;
  try {
    const core::Scene scene = core::read_scene(contact_bar::scene_keys(), path.string(), {}, {});
    const bar::BarSetup setup = contact_bar::setup_from_scene(scene);
    (void)contact_bar::simulation_from_scene(scene, 1.0);
    (void)contact_bar::contact_method_from_scene(scene);
    (void)setup;
  } catch (const core::InputError&) {
  }
}

void read_table_file(const fs::path& path) {
  using namespace backbone;
  try {
    const core::Table t = core::Table::read_csv(path);
    for (const auto& c : t.columns()) (void)t.column(c);
  } catch (const core::InputError&) {
  }
}

void read_unknowns_file(const fs::path& path) {
  using namespace backbone;
  try {
    (void)continuation::read_unknowns(path, -1, "start");
    (void)continuation::read_unknowns(path, 0, "start");
  } catch (const core::InputError&) {
  }
}

}  // namespace

// The first byte picks the reader, the rest is the file.
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const fs::path path = scratch_file("input");
  write(path, data + 1, size - 1);
  switch (data[0] % 3) {
    case 0:
      read_scene_file(path);
      break;
    case 1:
      read_table_file(path);
      break;
    default:
      read_unknowns_file(path);
      break;
  }
  return 0;
}
