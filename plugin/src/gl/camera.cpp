#include "autograv/gl/camera.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace autograv::gl {

namespace {
constexpr double kMaxElevationRad = 85.0 * M_PI / 180.0;
constexpr double kOrbitRadPerPx = 0.008;
constexpr double kZoomPerNotch = 0.9;
}  // namespace

OrbitCamera OrbitCamera::framing(const WorkspaceGrid& grid) {
  OrbitCamera camera;
  camera.target_m = grid.center_m();
  camera.azimuth_rad = 0.55;
  camera.elevation_rad = 0.42;
  camera.fov_y_rad = 0.7;
  // Far enough that the box's circumscribed sphere fits the vertical field of view (for a cube,
  // half its diagonal: sqrt(3) / 2 of its side, as before).
  const double radius_m = 0.5 * grid.size_m().norm();
  camera.distance_m = 1.08 * radius_m / std::sin(0.5 * camera.fov_y_rad);
  return camera;
}

Eigen::Vector3d OrbitCamera::eye_m() const {
  const Eigen::Vector3d offset(std::cos(elevation_rad) * std::cos(azimuth_rad),
                               std::cos(elevation_rad) * std::sin(azimuth_rad),
                               std::sin(elevation_rad));
  return target_m + distance_m * offset;
}

Eigen::Matrix4d OrbitCamera::view() const {
  const Eigen::Vector3d eye = eye_m();
  const Eigen::Vector3d forward = (target_m - eye).normalized();
  Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ());
  if (right.norm() < 1e-9) right = Eigen::Vector3d::UnitY();
  right.normalize();
  const Eigen::Vector3d up = right.cross(forward);
  Eigen::Matrix4d view = Eigen::Matrix4d::Identity();
  view.block<1, 3>(0, 0) = right.transpose();
  view.block<1, 3>(1, 0) = up.transpose();
  view.block<1, 3>(2, 0) = -forward.transpose();
  view(0, 3) = -right.dot(eye);
  view(1, 3) = -up.dot(eye);
  view(2, 3) = forward.dot(eye);
  return view;
}

Eigen::Matrix4d OrbitCamera::projection(double aspect) const {
  const double near_m = 0.02 * distance_m;
  const double far_m = 20.0 * distance_m;
  const double f = 1.0 / std::tan(0.5 * fov_y_rad);
  Eigen::Matrix4d projection = Eigen::Matrix4d::Zero();
  projection(0, 0) = f / aspect;
  projection(1, 1) = f;
  projection(2, 2) = (far_m + near_m) / (near_m - far_m);
  projection(2, 3) = 2.0 * far_m * near_m / (near_m - far_m);
  projection(3, 2) = -1.0;
  return projection;
}

Eigen::Vector3d OrbitCamera::dragDelta_m(double dx_px, double dy_px,
                                         const Eigen::Vector3d& through_m,
                                         int viewport_height_px) const {
  const Eigen::Matrix4d v = view();
  const Eigen::Vector3d right = v.block<1, 3>(0, 0).transpose();
  const Eigen::Vector3d up = v.block<1, 3>(1, 0).transpose();
  const Eigen::Vector3d forward = -v.block<1, 3>(2, 0).transpose();
  const double depth_m = std::max((through_m - eye_m()).dot(forward), 1e-6);
  const double metres_per_px =
      2.0 * depth_m * std::tan(0.5 * fov_y_rad) / std::max(viewport_height_px, 1);
  return metres_per_px * (dx_px * right - dy_px * up);
}

void OrbitCamera::orbit(double dx_px, double dy_px) {
  azimuth_rad -= dx_px * kOrbitRadPerPx;
  elevation_rad =
      std::clamp(elevation_rad + dy_px * kOrbitRadPerPx, -kMaxElevationRad, kMaxElevationRad);
}

void OrbitCamera::zoom(double notches) { distance_m *= std::pow(kZoomPerNotch, notches); }

}  // namespace autograv::gl
