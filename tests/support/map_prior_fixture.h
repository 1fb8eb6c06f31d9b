#pragma once
// A MapPrior as transferMap writes one (an affine correction from 24 points, checked on 4), for
// the tests of the map file, the summary and `inspect`.
#include <Eigen/Core>

#include "autograv/map/gravity_map.h"

namespace autograv::testing {

inline MapPrior affinePriorFixture() {
  MapPrior prior;
  prior.source = "maps/omni-0017.json";
  prior.device_serial = "SN-0017";
  prior.created_utc = "2026-10-01T08:00:00Z";
  prior.correction_model = "affine";
  prior.gain.diagonal() = Eigen::Vector3d(1.012, 0.987, 1.003);
  prior.offset_n = Eigen::Vector3d(0.0012, -0.0304, 0.0);
  prior.points_m.assign(24, Eigen::Vector3d(0.01, 0.0, 0.0));
  prior.check_points = 4;
  prior.check_mean_rel = 0.0041;
  prior.check_max_rel = 0.0093;
  prior.workspace_difference_m = 0.0032;
  return prior;
}

}  // namespace autograv::testing
