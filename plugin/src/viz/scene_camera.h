#pragma once

// Private to autograv::viz: the camera of the scene and the axes it frames.

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "autograv/viz/scene.h"
#include "viz/vtk_support.h"

class vtkCamera;
class vtkRenderer;

namespace autograv::viz::detail {

// The camera's direction from the preset and the adjustments; `up` and `right` as on the screen.
struct CameraBasis {
  Eigen::Vector3d direction;
  Eigen::Vector3d up;
  Eigen::Vector3d right;
};

CameraBasis cameraBasis(const SceneOptions& options);

// Three axes with ticks and labels in mm along edges of `box`: horizontal axes on the bottom edge
// nearest the camera (the top edge when looking down), the vertical axis on the left silhouette
// edge. An axis seen end-on is left out. Labels are 2D text anchored at 3D points, so they stay
// upright and crisp whatever the camera.
// Returns the points where labels are anchored, for the camera to frame them too.
std::vector<Eigen::Vector3d> addAxes(vtkRenderer* renderer, const Eigen::AlignedBox3d& box,
                                     const Eigen::Vector3d& direction, const Eigen::Vector3d& up,
                                     const Eigen::Vector3d& right, const Palette& palette,
                                     int font_px);

// Places the camera along `direction` so that every point of `points` and the sphere (when
// radius_mm > 0) is in view with a small margin, centred in a viewport of `aspect` (w / h).
// Tighter than vtkRenderer::ResetCamera, which frames the bounding sphere of the bounding box.
void frameCamera(vtkCamera* camera, const std::vector<Eigen::Vector3d>& points,
                 const Eigen::Vector3d& sphere_center, double radius_mm,
                 const Eigen::Vector3d& direction, const Eigen::Vector3d& up,
                 const Eigen::Vector3d& right, double aspect);

}  // namespace autograv::viz::detail
