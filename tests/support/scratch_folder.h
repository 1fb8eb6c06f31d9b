#pragma once

// A folder of a test's own for the files it writes: fresh and empty (mkdtemp) under the system's
// temporary folder, named autograv-<tag>-XXXXXX so that a leftover says which tests made it, and
// removed with everything in it when the ScratchFolder goes, unless a test failed: then it stays
// for a look, and its path goes to stderr so that a CI log says where.

#include <stdlib.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <iostream>
#include <string>
#include <system_error>
#include <vector>

#include <gtest/gtest.h>

namespace autograv::testing {

/// Whether what a scratch folder served failed: the running test while one runs (a test's own
/// folder, a fixture member or a local), else the running suite (a suite's folder, reset in
/// TearDownTestSuite), else the whole program (a static folder, gone at exit).
inline bool scratchOwnerFailed() {
  const ::testing::UnitTest& unit = *::testing::UnitTest::GetInstance();
  if (unit.current_test_info() != nullptr) return ::testing::Test::HasFailure();
  if (const ::testing::TestSuite* suite = unit.current_test_suite()) return suite->Failed();
  return unit.Failed();
}

class ScratchFolder {
 public:
  /// Makes autograv-<tag>-XXXXXX; throws std::system_error when it cannot. `keep` says at the end
  /// whether to keep it; a program without GoogleTest (a fuzzer) passes its own, so that it need
  /// not link GoogleTest.
  explicit ScratchFolder(const std::string& tag, bool (*keep)() = scratchOwnerFailed)
      : keep_(keep) {
    std::string pattern =
        (std::filesystem::temp_directory_path() / ("autograv-" + tag + "-XXXXXX")).string();
    if (::mkdtemp(pattern.data()) == nullptr) {
      throw std::system_error(errno, std::generic_category(), "cannot make " + pattern);
    }
    path_ = pattern;
  }
  ~ScratchFolder() {
    if (keep_()) {
      std::cerr << "autograv tests: kept the scratch folder " << path_.string() << '\n';
      return;
    }
    std::error_code ignored;
    // The fault tests take the write permission away; removing the files needs it back.
    std::filesystem::permissions(path_, std::filesystem::perms::owner_all,
                                 std::filesystem::perm_options::add, ignored);
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchFolder(const ScratchFolder&) = delete;
  ScratchFolder& operator=(const ScratchFolder&) = delete;

  const std::filesystem::path& path() const { return path_; }
  /// `name` in the folder (it may name a subfolder too: "maps/omni.json"); nothing is created.
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  /// The names in the folder, sorted.
  std::vector<std::string> names() const {
    std::vector<std::string> result;
    for (const auto& entry : std::filesystem::directory_iterator(path_))
      result.push_back(entry.path().filename().string());
    std::sort(result.begin(), result.end());
    return result;
  }

 private:
  bool (*keep_)();
  std::filesystem::path path_;
};

}  // namespace autograv::testing
