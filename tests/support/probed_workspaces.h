#pragma once

#include <vector>

#include <Eigen/Core>

#include "autograv/map/explored_workspace.h"

namespace autograv::testing {

/// A sphere of `radius_m` around `center_m` probed along `count` directions. Unit: [m]
inline ExploredWorkspace probedSphere(const Eigen::Vector3d& center_m, double radius_m, int count) {
  const std::vector<Eigen::Vector3d> directions = ExploredWorkspace::probeDirections(count);
  return ExploredWorkspace(center_m, directions, std::vector<double>(directions.size(), radius_m));
}

/// A cube of `half_width_m` around `center_m` probed along the 26 directions to its faces, edges
/// and corners: every boundary point lies on a face. Unit: [m]
inline ExploredWorkspace probedCube(double half_width_m,
                                    const Eigen::Vector3d& center_m = Eigen::Vector3d::Zero()) {
  std::vector<Eigen::Vector3d> directions;
  std::vector<double> radii;
  for (int i = -1; i <= 1; ++i) {
    for (int j = -1; j <= 1; ++j) {
      for (int k = -1; k <= 1; ++k) {
        if (i == 0 && j == 0 && k == 0) continue;
        const Eigen::Vector3d u = Eigen::Vector3d(i, j, k).normalized();
        directions.push_back(u);
        radii.push_back(half_width_m / u.cwiseAbs().maxCoeff());
      }
    }
  }
  return ExploredWorkspace(center_m, directions, radii);
}

}  // namespace autograv::testing
