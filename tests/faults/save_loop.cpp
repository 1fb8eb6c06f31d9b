// autograv_save_loop <path> <versions>: saves map files to <path> with writeFileAtomically (what
// saveMap does), over and over, until killed; the fault tests SIGKILL it at random moments. Map k
// (0 <= k < versions) carries the serial number "version-k" and its own values, so that a file
// mixing two versions fails the checksum and a whole one names its version. The texts are made
// once, so that the loop spends its time in write(), fsync() and rename(). Prints "ready" once
// they are made (the saves start right after) and "saved k" after each save.
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "autograv/error.h"
#include "autograv/map/map_io.h"

namespace {

/// A grid of 7^3 vertices with a history each: a file of about half a megabyte, long enough to
/// write that kills land inside write(), fsync() and rename() as well as between saves.
autograv::GravityMap makeVersion(int version) {
  const autograv::WorkspaceGrid grid(Eigen::Vector3d(0.0, 0.0, 0.0), 0.08, 7);
  std::vector<autograv::VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (int i = 0; i < grid.vertexCount(); ++i) {
    autograv::VertexEstimate& v = vertices[static_cast<std::size_t>(i)];
    v.gravity_n = Eigen::Vector3d(0.001 * i, -0.5 + 0.01 * version, 2.0 + 1e-3 * (i + version));
    v.iterations = 8;
    v.seconds = 1.0 + 0.1 * version;
    v.outcome = autograv::VertexOutcome::kConverged;
    for (int j = 0; j < v.iterations; ++j) {
      autograv::IterationRecord record;
      record.position_error_m = 1e-3 / (j + 1 + version);
      record.mass_estimate_kg = 0.2 + 1e-3 * j;
      record.gravity_estimate_n = v.gravity_n * (1.0 - 0.01 * j);
      record.duration_s = 0.125;
      v.history.push_back(record);
    }
  }
  autograv::MapMetadata metadata;
  metadata.device_model = "sim:omega";
  metadata.device_serial = "version-" + std::to_string(version);
  metadata.created_utc = "2026-11-30T12:00:00Z";
  return autograv::GravityMap(grid, std::move(vertices), metadata);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s <path> <versions>\n", argv[0]);
    return 2;
  }
  const std::string path = argv[1];
  const int versions = std::atoi(argv[2]);
  if (versions < 1) return 2;
  std::vector<std::string> texts;
  for (int k = 0; k < versions; ++k) texts.push_back(autograv::mapToJson(makeVersion(k)));
  std::printf("ready\n");
  std::fflush(stdout);
  try {
    for (long n = 0;; ++n) {
      const int k = static_cast<int>(n % versions);
      autograv::writeFileAtomically(path, texts[static_cast<std::size_t>(k)], "map");
      std::printf("saved %d\n", k);
      std::fflush(stdout);
    }
  } catch (const autograv::Error& error) {
    std::fprintf(stderr, "autograv_save_loop: %s\n", error.what());
    return 1;
  }
}
