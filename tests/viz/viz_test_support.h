#pragma once

// Fixtures shared by the autograv::viz tests: maps with a known ground truth, and the display
// check every rendering test makes first (no X display = a clear failure, never a hang).

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "autograv/estimation/estimation_parameters.h"
#include "autograv/map/gravity_map.h"
#include "autograv/viz/common.h"
#include "autograv/viz/image.h"
#include "explored_fixture_map.h"

#if defined(__SANITIZE_ADDRESS__)
#include <dlfcn.h>

// Mesa's software rasterizer (llvmpipe, in swrast_dri.so) leaks a few hundred bytes per process
// and is unloaded before LeakSanitizer looks, so the leak cannot even be attributed. Keeping the
// driver loaded lets its frames be named, and suppressed: the leak is Mesa's, not ours.
extern "C" const char* __lsan_default_suppressions() { return "leak:swrast_dri.so\n"; }
namespace autograv::viz::testing {
inline const bool kMesaDriverPinned =
    dlopen("swrast_dri.so", RTLD_LAZY | RTLD_NODELETE) != nullptr ||
    dlopen("/usr/lib/x86_64-linux-gnu/dri/swrast_dri.so", RTLD_LAZY | RTLD_NODELETE) != nullptr;
}  // namespace autograv::viz::testing
#endif

namespace autograv::viz::testing {

/// Pixels of `image` for which `match(r, g, b)` holds.
template <typename Match>
int countPixels(const RgbImage& image, Match match) {
  int count = 0;
  for (int y = 0; y < image.height_px; ++y) {
    for (int x = 0; x < image.width_px; ++x) {
      const std::uint8_t* p = image.pixel(x, y);
      if (match(p[0], p[1], p[2])) ++count;
    }
  }
  return count;
}

/// A smooth apparent-gravity field shaped like a 3-DoF device's: about 0.2 kg hanging along -z,
/// with position-dependent terms of a few percent. Argument unit: [m]; result unit: [N].
inline Eigen::Vector3d analyticGravity(const Eigen::Vector3d& x) {
  return {-0.4 - 3.0 * x.x(), 1.5 * x.y(), -2.1 + 6.0 * x.z() + 20.0 * x.x() * x.x()};
}

struct FixtureSpec {
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
  double side_m = 0.08;
  int resolution = 5;
  std::vector<int> failed;       ///< Vertices marked kIterationCap.
  std::vector<int> not_visited;  ///< Vertices left kPending with a zero estimate.
  /// Relative size of the deterministic estimation error added to the truth.
  double error_fraction = 0.01;
  std::string model = "fixture:analytic";
};

/// A map whose estimates are the truth plus a small deterministic error, with a synthetic
/// convergence history per vertex (Delta_j shrinking geometrically, M_hat_j approaching the true
/// mass): enough to draw everything the scene and the plots show.
inline GravityMap makeFixtureMap(const GroundTruth& truth, const FixtureSpec& spec = {}) {
  WorkspaceGrid grid(spec.center_m, spec.side_m, spec.resolution);
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (int i = 0; i < grid.vertexCount(); ++i) {
    VertexEstimate& v = vertices[static_cast<std::size_t>(i)];
    const Eigen::Vector3d g = truth(grid.vertexPosition(i));
    const Eigen::Vector3d wobble(std::sin(1.7 * i), std::cos(2.3 * i), std::sin(0.9 * i + 1.0));
    v.gravity_n = g + spec.error_fraction * g.norm() * wobble;
    v.iterations = 6 + (i * 7) % 9;
    v.seconds = 0.25 * v.iterations;
    v.outcome = VertexOutcome::kConverged;
    const double true_mass_kg = g.norm() / kStandardGravity;
    for (int j = 1; j <= v.iterations; ++j) {
      IterationRecord record;
      record.position_error_m = 0.008 * std::pow(0.45, j - 1);
      record.mass_estimate_kg = true_mass_kg * (1.0 - 0.35 * std::pow(0.5, j - 1));
      record.gravity_estimate_n = v.gravity_n * (record.mass_estimate_kg / true_mass_kg);
      record.duration_s = 0.25;
      v.history.push_back(record);
    }
  }
  for (int i : spec.failed)
    vertices[static_cast<std::size_t>(i)].outcome = VertexOutcome::kIterationCap;
  for (int i : spec.not_visited) {
    VertexEstimate& v = vertices[static_cast<std::size_t>(i)];
    v = VertexEstimate{};
  }
  MapMetadata metadata;
  metadata.device_model = spec.model;
  metadata.created_utc = "2026-01-01T00:00:00Z";
  return GravityMap(grid, std::move(vertices), metadata);
}

using autograv::testing::ExploredFixtureSpec;
using autograv::testing::makeExploredFixtureMap;

}  // namespace autograv::viz::testing

/// First statement of every test that renders: fails at once with the reason and the fix when
/// no X display can be opened (run the tests under `xvfb-run -a ctest -L xvfb`).
#define AUTOGRAV_REQUIRE_DISPLAY()                                    \
  do {                                                                \
    std::string autograv_display_reason;                              \
    if (!::autograv::viz::displayAvailable(&autograv_display_reason)) \
      GTEST_FAIL() << autograv_display_reason;                        \
  } while (false)
