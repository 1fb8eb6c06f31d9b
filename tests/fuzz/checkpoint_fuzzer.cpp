// Checkpoints and --resume: the input is the content of <map>.partial, read by loadCheckpoint for
// a run on a fixed grid exactly as `autograv calibrate --resume` and the wizard read it, then
// restored into the calibrator. A bad checkpoint must fail with autograv::Error and nothing else;
// a restored run must visit exactly the vertices that are not done and save as a map again (each
// finished vertex is checkpointed with saveMap).
//
// Build with -DAUTOGRAV_FUZZ=ON (clang); run: build/fuzz/tests/fuzz/checkpoint_fuzzer
// -dict=tests/fuzz/map.dict <scratch corpus> tests/fuzz/corpus/checkpoint
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "autograv/error.h"
#include "autograv/estimation/auto_calibrator.h"
#include "autograv/map/map_io.h"
#include "autograv/wizard/calibration_wizard.h"

namespace {

using autograv::VertexEstimate;

[[noreturn]] void fail(const char* what) {
  std::fprintf(stderr, "checkpoint_fuzzer: %s\n", what);
  std::abort();
}

// The run being resumed: `autograv calibrate --device sim:omega --grid 2 --side-mm 40`, the run
// that wrote the seeds.
constexpr const char* kDeviceModel = "sim:omega";
constexpr double kMaxForce_n = 12.0;
const autograv::WorkspaceGrid& runGrid() {
  static const autograv::WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.040, 2);
  return grid;
}

/// <scratch>/map.json.partial, one per fuzzing process, rewritten for every input.
const std::string& checkpointFile() {
  static const std::string path = [] {
    const std::filesystem::path folder =
        std::filesystem::temp_directory_path() /
        ("autograv-checkpoint-fuzzer-" + std::to_string(::getpid()));
    std::filesystem::create_directories(folder);
    return (folder / "map.json.partial").string();
  }();
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  {
    std::ofstream out(checkpointFile(), std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) fail("cannot write the scratch checkpoint");
  }
  std::vector<VertexEstimate> vertices;
  try {
    vertices = autograv::loadCheckpoint(checkpointFile(), runGrid(), kDeviceModel);
  } catch (const autograv::Error&) {
    return 0;  // the one exception a bad checkpoint may cause; any other escapes and is reported
  }
  if (static_cast<int>(vertices.size()) != runGrid().vertexCount()) fail("wrong vertex count");

  autograv::AutoCalibrator calibrator(runGrid(), autograv::EstimationParameters{}, kMaxForce_n);
  calibrator.restore(vertices);
  autograv::MapMetadata metadata;
  metadata.device_model = kDeviceModel;
  const autograv::GravityMap resumed = calibrator.makeMap(metadata);
  if (calibrator.toVisitCount() != runGrid().vertexCount() - resumed.convergedCount()) {
    fail("the resumed run does not visit exactly the vertices that have not converged");
  }
  try {
    autograv::mapFromJson(autograv::mapToJson(resumed), "re-saved");
  } catch (const autograv::Error& error) {
    std::fprintf(stderr, "checkpoint_fuzzer: %s\n", error.what());
    fail("a checkpoint that loaded cannot be checkpointed again");
  }
  return 0;
}
