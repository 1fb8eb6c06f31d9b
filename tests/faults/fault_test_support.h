#pragma once

// What the fault tests share: a scratch folder per test, and the check that a vertex finished
// before a fault is still there, bit for bit.

#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "autograv/map/gravity_map.h"
#include "scratch_folder.h"
#include "subprocess.h"

namespace autograv::testing {

/// A fault test's scratch folder, autograv-faults-XXXXXX (see support/scratch_folder.h).
class TestFolder : public ScratchFolder {
 public:
  TestFolder() : ScratchFolder("faults") {}
};

inline bool sameBits(const double& a, const double& b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

inline bool sameBits(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::memcmp(a.data(), b.data(), 3 * sizeof(double)) == 0;
}

/// Estimate, iterations, time, outcome and every history record identical to the bit.
inline bool sameBits(const VertexEstimate& a, const VertexEstimate& b) {
  if (!sameBits(a.gravity_n, b.gravity_n) || a.iterations != b.iterations ||
      !sameBits(a.seconds, b.seconds) || a.outcome != b.outcome ||
      a.history.size() != b.history.size()) {
    return false;
  }
  for (std::size_t j = 0; j < a.history.size(); ++j) {
    const IterationRecord& x = a.history[j];
    const IterationRecord& y = b.history[j];
    if (!sameBits(x.position_error_m, y.position_error_m) ||
        !sameBits(x.mass_estimate_kg, y.mass_estimate_kg) ||
        !sameBits(x.gravity_estimate_n, y.gravity_estimate_n) ||
        !sameBits(x.duration_s, y.duration_s)) {
      return false;
    }
  }
  return true;
}

inline int convergedCount(const std::vector<VertexEstimate>& vertices) {
  int count = 0;
  for (const VertexEstimate& v : vertices) count += v.outcome == VertexOutcome::kConverged;
  return count;
}

/// Every converged vertex of `before` is in `after`, bit for bit; `where` names `after`.
inline void expectKept(const std::vector<VertexEstimate>& before,
                       const std::vector<VertexEstimate>& after, const std::string& where) {
  ASSERT_EQ(before.size(), after.size()) << where;
  for (std::size_t i = 0; i < before.size(); ++i) {
    if (before[i].outcome != VertexOutcome::kConverged) continue;
    EXPECT_TRUE(sameBits(before[i], after[i])) << "vertex " << i << " changed in " << where;
  }
}

/// What a file system error looks like where `run` could not write: a read-only bind mount says
/// so; a folder without write permission says "Permission denied".
inline const char* unwritableReason(const ConfinedRun& run) {
  return run.confinement == Confinement::kReadOnlyBindMount ? "Read-only file system"
                                                            : "Permission denied";
}

/// Runs `autograv <arguments>` unable to write in `folder`; expects exit code 2 and an error
/// that names the file `named` (quoted) and the reason.
inline void expectAutogravRefused(const std::string& folder, const std::string& arguments,
                                  const std::string& named) {
  const ConfinedRun run = runWithReadOnlyFolder(folder, [&] {
    const ProgramRun program = runAutograv(arguments);
    return Findings{{"exit", std::to_string(program.exit_code)}, {"output", program.output}};
  });
  ASSERT_TRUE(run.ran) << run.why_not;
  const std::string& output = run.findings.at("output");
  EXPECT_EQ(run.findings.at("exit"), "2") << output;
  EXPECT_NE(output.find("autograv: error:"), std::string::npos) << output;
  EXPECT_NE(output.find("'" + named + "'"), std::string::npos) << output;
  EXPECT_NE(output.find(unwritableReason(run)), std::string::npos) << output;
}

}  // namespace autograv::testing
