#pragma once

#include <Eigen/Core>

#include "autograv/map/workspace_grid.h"

namespace autograv::gl {

/// A camera orbiting a target point, z up (the device frame: x toward the operator, y right).
/// Azimuth 0 puts the camera on the +x axis, looking back at the device as the operator does.
struct OrbitCamera {
  Eigen::Vector3d target_m = Eigen::Vector3d::Zero();  ///< Point looked at. Unit: [m]
  double distance_m = 0.5;                             ///< Eye to target. Unit: [m]
  double azimuth_rad = 0.0;    ///< Rotation about +z from the +x axis. Unit: [rad]
  double elevation_rad = 0.4;  ///< Angle above the xy plane. Unit: [rad]
  double fov_y_rad = 0.7;      ///< Vertical field of view. Unit: [rad]

  /// A view of the whole grid from the operator's side, a little from above and to the right.
  static OrbitCamera framing(const WorkspaceGrid& grid);

  /// Eye position. Unit: [m]
  Eigen::Vector3d eye_m() const;
  /// World-to-camera transform.
  Eigen::Matrix4d view() const;
  /// Perspective projection for a viewport of aspect width / height.
  Eigen::Matrix4d projection(double aspect) const;
  /// The world displacement, in the plane facing the camera through `through_m`, that follows the
  /// mouse moving by (dx, dy) pixels (y down) in a viewport `viewport_height_px` tall. Unit: [m]
  Eigen::Vector3d dragDelta_m(double dx_px, double dy_px, const Eigen::Vector3d& through_m,
                              int viewport_height_px) const;
  /// Turns the camera by a mouse drag of (dx, dy) pixels; elevation stays within +-85 degrees.
  void orbit(double dx_px, double dy_px);
  /// Moves the eye closer (notches > 0) or farther, keeping the target.
  void zoom(double notches);
};

}  // namespace autograv::gl
