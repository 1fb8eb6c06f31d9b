// Map files: the input is the content of a map file, loaded with loadMap as an application loads
// one. A bad file must fail with autograv::Error and nothing else; a file that loads must give
// finite gravity everywhere and save to a text that loads back to the same map.
//
// Build with -DAUTOGRAV_FUZZ=ON (clang); run: build/fuzz/tests/fuzz/map_fuzzer
// -dict=tests/fuzz/map.dict <scratch corpus> tests/fuzz/corpus/map
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "autograv/error.h"
#include "autograv/map/map_io.h"

namespace {

using autograv::GravityMap;

[[noreturn]] void fail(const char* what) {
  std::fprintf(stderr, "map_fuzzer: %s\n", what);
  std::abort();
}

/// One file per fuzzing process, rewritten for every input.
const std::string& scratchFile() {
  static const std::string path = (std::filesystem::temp_directory_path() /
                                   ("autograv-map-fuzzer-" + std::to_string(::getpid()) + ".json"))
                                      .string();
  return path;
}

void checkLoadedMap(const GravityMap& map) {
  const autograv::WorkspaceGrid& grid = map.grid();
  for (int i = 0; i < grid.vertexCount(); ++i) {
    if (!map.gravityAt(grid.vertexPosition(i)).allFinite()) fail("non-finite gravity at a vertex");
  }
  if (!map.gravityAt(grid.center_m()).allFinite()) fail("non-finite gravity at the centre");

  // What loads must save, and the saved text must load back bit for bit.
  const GravityMap again = autograv::mapFromJson(autograv::mapToJson(map), "round trip");
  if (again.vertices().size() != map.vertices().size()) fail("round trip changed the size");
  for (std::size_t i = 0; i < map.vertices().size(); ++i) {
    if (again.vertices()[i].gravity_n != map.vertices()[i].gravity_n) {
      fail("round trip changed a gravity value");
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  {
    std::ofstream out(scratchFile(), std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) fail("cannot write the scratch file");
  }
  try {
    checkLoadedMap(autograv::loadMap(scratchFile()));
  } catch (const autograv::Error&) {
    // The one exception a bad file may cause; any other escapes and is reported.
  }
  return 0;
}
