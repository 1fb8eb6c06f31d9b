#include "autograv/map/map_library.h"

#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "autograv/device/device_specifications.h"
#include "autograv/error.h"
#include "autograv/map/map_io.h"
#include "scratch_folder.h"

namespace autograv {
namespace {

namespace fs = std::filesystem;

GravityMap makeMap(const std::string& model, const std::string& serial) {
  const WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.04, 2);
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (VertexEstimate& vertex : vertices) {
    vertex.gravity_n = Eigen::Vector3d(0.0, 0.0, 2.0);
    vertex.outcome = VertexOutcome::kConverged;
  }
  MapMetadata metadata;
  metadata.device_model = model;
  metadata.device_serial = serial;
  return GravityMap(grid, std::move(vertices), metadata);
}

DeviceSpecifications device(const std::string& model, const std::string& serial) {
  DeviceSpecifications specifications;
  specifications.model_name = model;
  specifications.serial_number = serial;
  return specifications;
}

class MapLibraryTest : public ::testing::Test {
 protected:
  testing::ScratchFolder scratch_{"map-library"};
  // The library's folder, not made yet: saving makes it.
  std::string dir_ = scratch_.file("maps");
};

TEST_F(MapLibraryTest, FilesMapsByModelAndSerialWithSafeNames) {
  const MapLibrary library(dir_);
  EXPECT_EQ(fs::path(library.pathFor(device("sim:omni", ""))).filename(), "sim_omni.json");
  EXPECT_EQ(fs::path(library.pathFor(device("omega.3", "SN 12/4"))).filename(),
            "omega.3@SN_12_4.json");
  EXPECT_THROW(library.pathFor(device("", "")), Error);
}

TEST_F(MapLibraryTest, SavesIntoANewFolderAndFindsTheMapOfThatUnitOnly) {
  const MapLibrary library(dir_);
  EXPECT_TRUE(library.list().empty());
  const std::string path = library.save(makeMap("omega.3", "A1"));
  EXPECT_EQ(library.find(device("omega.3", "A1")), path);
  EXPECT_EQ(library.find(device("omega.3", "B2")), "");  // another unit of the same model
  EXPECT_EQ(library.find(device("omega.3", "")), "");
  const GravityMap loaded = loadMapForDevice(device("omega.3", "A1"), dir_);
  EXPECT_EQ(loaded.metadata().device_serial, "A1");
  EXPECT_EQ(library.list().size(), 1u);
}

TEST_F(MapLibraryTest, NoFittingMapIsAnErrorThatNamesTheFolderAndWhatItHolds) {
  MapLibrary(dir_).save(makeMap("falcon", ""));
  try {
    loadMapForDevice(device("omega.3", "A1"), dir_);
    FAIL() << "expected autograv::Error";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("\"omega.3\" (serial A1)"), std::string::npos) << message;
    EXPECT_NE(message.find(dir_), std::string::npos) << message;
    EXPECT_NE(message.find("falcon.json"), std::string::npos) << message;
    EXPECT_NE(message.find("CalibrationWizard"), std::string::npos) << message;
  }
}

TEST_F(MapLibraryTest, AMapFiledUnderTheWrongNameIsRefused) {
  fs::create_directories(dir_);
  saveMap(makeMap("omega.3", "OTHER"), MapLibrary(dir_).pathFor(device("omega.3", "A1")));
  EXPECT_THROW(loadMapForDevice(device("omega.3", "A1"), dir_), Error);
}

TEST(MapLibraryDirTest, FollowsXdgDataHomeThenHome) {
  const char* saved_xdg = std::getenv("XDG_DATA_HOME");
  const char* saved_home = std::getenv("HOME");
  const std::string xdg = saved_xdg ? saved_xdg : "", home = saved_home ? saved_home : "";
  ::setenv("XDG_DATA_HOME", "/data", 1);
  EXPECT_EQ(defaultMapLibraryDir(), "/data/autograv/maps");
  ::setenv("XDG_DATA_HOME", "", 1);
  ::setenv("HOME", "/home/user", 1);
  EXPECT_EQ(defaultMapLibraryDir(), "/home/user/.local/share/autograv/maps");
  ::unsetenv("HOME");
  ::unsetenv("XDG_DATA_HOME");
  EXPECT_THROW(defaultMapLibraryDir(), Error);
  if (saved_xdg) ::setenv("XDG_DATA_HOME", xdg.c_str(), 1);
  if (saved_home) ::setenv("HOME", home.c_str(), 1);
}

}  // namespace
}  // namespace autograv
