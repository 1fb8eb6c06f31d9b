// A process killed with SIGKILL while it saves: the file on disk is always the old complete file
// or the new complete file, never a mix; and `autograv calibrate --resume` after each kill keeps
// every finished vertex bit for bit.
#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "autograv/error.h"
#include "autograv/map/map_io.h"
#include "fault_test_support.h"
#include "subprocess.h"

namespace autograv {
namespace {

namespace fs = std::filesystem;

using testing::convergedCount;
using testing::expectKept;
using testing::TestFolder;

/// Names in `folder` other than `except`.
std::vector<std::string> othersThan(const TestFolder& folder, const std::string& except) {
  std::vector<std::string> names = folder.names();
  names.erase(std::remove(names.begin(), names.end(), except), names.end());
  return names;
}

int versionOf(const GravityMap& map) {
  const std::string& serial = map.metadata().device_serial;
  const std::string prefix = "version-";
  if (serial.rfind(prefix, 0) != 0) return -1;
  return std::stoi(serial.substr(prefix.size()));
}

TEST(KillDuringSaveTest, AMapSaveKilledAtAnyMomentLeavesTheOldOrTheNewFileNeverAMix) {
  const TestFolder folder;
  const std::string path = folder.file("map.json");
  constexpr int kVersions = 4;
  constexpr int kKills = 30;
  std::mt19937 random(14);  // seeded: the same kill schedule on every run of the test
  std::uniform_int_distribution<int> saves_before_kill(0, 2);
  std::uniform_real_distribution<double> fraction_of_a_save(0.0, 1.0);
  double save_us = 20000.0;  // how long one save takes here, measured as the test goes
  int on_disk = -1;          // version in the file, -1 before the first complete save
  int versions_changed = 0;
  int renamed_unreported = 0;  // kills between a rename and its "saved" line
  for (int kill = 0; kill < kKills; ++kill) {
    SCOPED_TRACE("kill " + std::to_string(kill));
    testing::ChildProcess child({AUTOGRAV_SAVE_LOOP, path, std::to_string(kVersions)});
    ASSERT_TRUE(child.started());
    std::string line;
    ASSERT_TRUE(child.readLine(line));
    ASSERT_EQ(line, "ready");
    // Let it finish a few saves (timing them), then kill it at a random point of the next one.
    auto last = std::chrono::steady_clock::now();
    for (int n = saves_before_kill(random); n > 0; --n) {
      ASSERT_TRUE(child.readLine(line));
      const auto now = std::chrono::steady_clock::now();
      save_us = std::chrono::duration<double, std::micro>(now - last).count();
      last = now;
    }
    std::this_thread::sleep_for(
        std::chrono::microseconds(static_cast<long>(1.2 * save_us * fraction_of_a_save(random))));
    child.kill(SIGKILL);
    const testing::ProgramRun run = child.wait();
    ASSERT_EQ(run.signal, SIGKILL) << run.output;

    // The child saves versions 0, 1, 2, ... in turn; it printed "saved k" after each complete
    // save, and may have been killed after its next rename but before saying so.
    int saves = 0;
    for (std::size_t at = run.output.find("saved "); at != std::string::npos;
         at = run.output.find("saved ", at + 1)) {
      ++saves;
    }
    const int last_said = saves > 0 ? (saves - 1) % kVersions : on_disk;
    const int being_saved = saves % kVersions;
    if (!fs::exists(path)) {
      EXPECT_EQ(on_disk, -1) << "a complete map vanished";
      EXPECT_EQ(saves, 0);
      continue;
    }
    int version = -1;
    try {
      version = versionOf(loadMap(path));  // checks the whole file, checksum included
    } catch (const Error& error) {
      FAIL() << "the killed save left a damaged file: " << error.what();
    }
    EXPECT_TRUE(version == last_said || version == being_saved)
        << "the file holds version " << version << "; the last save said was " << last_said;
    renamed_unreported += version != last_said;
    versions_changed += version != on_disk;
    on_disk = version;
    // What a kill may leave besides the map: its own temporary file, never another name.
    for (const std::string& name : othersThan(folder, "map.json")) {
      EXPECT_EQ(name.rfind(".map.json.tmp-", 0), 0u) << name;
    }
  }
  // The kills were spread over the saves: the file changed between kills, and some kills came
  // after a rename the child had no time to report.
  EXPECT_GE(versions_changed, kKills / 4);
  std::printf("  %d kills: the file changed %d times, %d kills came right after a rename\n", kKills,
              versions_changed, renamed_unreported);
}

// --- autograv calibrate killed and resumed ------------------------------------------------------

TEST(KillDuringSaveTest, CalibrateKilledAgainAndAgainResumesKeepingEveryFinishedVertex) {
  if (!fs::exists(testing::kAutogravProgram)) {
    GTEST_SKIP() << testing::kAutogravProgram << " is not built (AUTOGRAV_BUILD_DEMO=OFF)";
  }
  const TestFolder folder;
  const std::string out = folder.file("map.json");
  const std::string checkpoint = out + ".partial";
  std::mt19937 random(14);
  // The first runs are killed around a random one of their next checkpoint writes, at a random
  // microsecond: before, during or after the write and its rename. The last run finishes.
  constexpr int kKilledRuns = 6;
  std::uniform_int_distribution<int> checkpoints_before_kill(1, 4);
  std::uniform_int_distribution<int> extra_us(0, 3000);
  // A save makes a new file: a new inode or at least a new modification time.
  const auto checkpoint_identity = [&checkpoint] {
    struct stat status {};
    if (::stat(checkpoint.c_str(), &status) != 0) return std::string();
    return std::to_string(status.st_ino) + ":" + std::to_string(status.st_mtim.tv_sec) + "." +
           std::to_string(status.st_mtim.tv_nsec);
  };
  std::vector<VertexEstimate> kept;  // what the last checkpoint held
  int kills = 0;
  int resumed_runs = 0;
  bool last_run_finished = false;
  for (int seed = 1; seed <= kKilledRuns + 1 && !fs::exists(out); ++seed) {
    SCOPED_TRACE("run " + std::to_string(seed));
    // Each run is another process with another noise seed, as after a real crash.
    std::vector<std::string> argv = {testing::kAutogravProgram,
                                     "calibrate",
                                     "--device",
                                     "sim:omega",
                                     "--grid",
                                     "4",
                                     "--side-mm",
                                     "40",
                                     "--seed",
                                     std::to_string(seed),
                                     "--out",
                                     out};
    if (fs::exists(checkpoint)) {
      argv.push_back("--resume");
      ++resumed_runs;
    }
    testing::ChildProcess child(argv);
    ASSERT_TRUE(child.started());
    if (seed <= kKilledRuns) {
      std::string seen = checkpoint_identity();
      for (int writes = checkpoints_before_kill(random); writes > 0 && !child.exited();) {
        std::this_thread::sleep_for(std::chrono::microseconds(200));
        const std::string now = checkpoint_identity();
        if (now != seen) --writes;
        seen = now;
      }
      std::this_thread::sleep_for(std::chrono::microseconds(extra_us(random)));
      child.kill(SIGKILL);
    }
    const testing::ProgramRun run = child.wait();
    last_run_finished = run.signal != SIGKILL;
    if (!last_run_finished) {
      ++kills;
    } else {
      ASSERT_EQ(run.exit_code, 0) << run.output;  // it finished before the kill
    }
    if (!fs::exists(checkpoint)) continue;
    std::vector<VertexEstimate> now;
    try {
      now = loadMap(checkpoint).vertices();
    } catch (const Error& error) {
      FAIL() << "the killed run left a damaged checkpoint: " << error.what();
    }
    if (!kept.empty()) expectKept(kept, now, checkpoint);
    kept = now;
  }
  ASSERT_TRUE(fs::exists(out)) << "no run got to the end";
  // (A kill between the map's save and the checkpoint's removal leaves both, legitimately.)
  if (last_run_finished) {
    EXPECT_FALSE(fs::exists(checkpoint)) << "the checkpoint outlived the map";
  }
  const GravityMap map = loadMap(out);
  expectKept(kept, map.vertices(), out);
  EXPECT_EQ(map.convergedCount(), map.grid().vertexCount());
  EXPECT_GE(kills, 2);
  EXPECT_GE(resumed_runs, 2);
  EXPECT_GT(convergedCount(kept), 0) << "no kill came after a checkpoint";
}

TEST(KillDuringSaveTest, ACheckpointIsNeverOverwrittenWithoutResume) {
  if (!fs::exists(testing::kAutogravProgram)) {
    GTEST_SKIP() << testing::kAutogravProgram << " is not built (AUTOGRAV_BUILD_DEMO=OFF)";
  }
  const TestFolder folder;
  const std::string out = folder.file("map.json");
  const std::string arguments =
      "calibrate --device sim:omega --grid 3 --side-mm 40 --seed 3 --out " + out;
  testing::ChildProcess first(testing::words(testing::kAutogravProgram + " " + arguments));
  // Killed once its first vertices are checkpointed.
  for (int wait_ms = 0; wait_ms < 20000 && !fs::exists(out + ".partial"); wait_ms += 5) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  first.kill(SIGKILL);
  first.wait();
  ASSERT_TRUE(fs::exists(out + ".partial"));
  const std::string checkpoint = testing::readFile(out + ".partial");
  const testing::ProgramRun again = testing::runAutograv(arguments);
  EXPECT_EQ(again.exit_code, 2) << again.output;
  EXPECT_NE(again.output.find(out + ".partial"), std::string::npos) << again.output;
  EXPECT_NE(again.output.find("add --resume"), std::string::npos) << again.output;
  EXPECT_EQ(testing::readFile(out + ".partial"), checkpoint);
}

}  // namespace
}  // namespace autograv
