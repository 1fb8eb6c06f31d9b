// The pictures and exports of `autograv render`, `plot` and `export` aimed at a read-only folder
// and at /dev/full: the user is told which file and why, and the files already there are kept.
// Needs an X display (label xvfb), as every VTK render here does.
#include <sys/stat.h>

#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../fault_test_support.h"

namespace autograv {
namespace {

namespace fs = std::filesystem;

const std::string kMap = AUTOGRAV_SOURCE_DIR "/tests/visual/golden/omega_map.json";

class UnwritablePicturesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(testing::kAutogravProgram)) {
      GTEST_SKIP() << testing::kAutogravProgram << " is not built (AUTOGRAV_BUILD_DEMO=OFF)";
    }
    // Earlier results in the folder that becomes read-only.
    for (const char* name : {"scene.png", "diff.png", "plot.png", "map.vti"}) {
      testing::writeFile(folder_.file(name), std::string("earlier ") + name);
    }
  }

  /// `autograv <arguments>` is refused with a message naming `named`; the earlier files are kept.
  void expectRefused(const std::string& arguments, const std::string& named) {
    SCOPED_TRACE("autograv " + arguments);
    testing::expectAutogravRefused(folder_.path(), arguments, named);
    expectEarlierFilesKept();
  }

  void expectEarlierFilesKept() const {
    EXPECT_EQ(folder_.names(),
              (std::vector<std::string>{"diff.png", "map.vti", "plot.png", "scene.png"}));
    for (const std::string& name : folder_.names()) {
      EXPECT_EQ(testing::readFile(folder_.file(name)), "earlier " + name);
    }
  }

  std::string file(const std::string& name) const { return folder_.file(name); }

 private:
  testing::TestFolder folder_;
};

TEST_F(UnwritablePicturesTest, RenderPlotAndExportIntoAReadOnlyFolder) {
  expectRefused("render " + kMap + " -o " + file("scene.png") + " --size-px 320x240",
                file("scene.png"));
  expectRefused("plot " + kMap + " --summary -o " + file("plot.png"), file("plot.png"));
  expectRefused("export " + kMap + " -o " + file("map.vti"), file("map.vti"));
}

TEST_F(UnwritablePicturesTest, TheDifferencePictureOfACompareIntoAReadOnlyFolder) {
  // The picture itself goes elsewhere; only the difference picture is refused.
  const testing::TestFolder open_folder;
  fs::permissions(open_folder.path(), fs::perms::all);
  const testing::ProgramRun golden = testing::runAutograv(
      "render " + kMap + " -o " + open_folder.file("iso.png") + " --view iso --size-px 320x240");
  ASSERT_EQ(golden.exit_code, 0) << golden.output;
  expectRefused("render " + kMap + " -o " + open_folder.file("top.png") +
                    " --view top --size-px 320x240 --compare " + open_folder.file("iso.png") +
                    " --diff " + file("diff.png"),
                file("diff.png"));
}

TEST_F(UnwritablePicturesTest, PicturesToDevFullSayTheDiskIsFull) {
  // (An export needs a .vti or .vtu name, which /dev/full is not.)
  for (const std::string& arguments : {"render " + kMap + " -o /dev/full --size-px 320x240",
                                       "plot " + kMap + " --summary -o /dev/full"}) {
    SCOPED_TRACE(arguments);
    const testing::ProgramRun run = testing::runAutograv(arguments);
    EXPECT_EQ(run.exit_code, 2) << run.output;
    EXPECT_NE(run.output.find("'/dev/full'"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("No space left on device"), std::string::npos) << run.output;
  }
  struct stat status {};
  EXPECT_TRUE(::stat("/dev/full", &status) == 0 && S_ISCHR(status.st_mode));
}

}  // namespace
}  // namespace autograv
