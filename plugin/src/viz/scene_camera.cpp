#include "viz/scene_camera.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>

#include "viz/scene_build.h"

namespace autograv::viz::detail {

namespace {

struct CameraPreset {
  double azimuth_deg;
  double elevation_deg;
};

CameraPreset presetFor(CameraView view) noexcept {
  switch (view) {
    case CameraView::kFront:
      return {0.0, 0.0};
    case CameraView::kTop:
      return {0.0, 90.0};
    case CameraView::kIso:
      break;
  }
  return {40.0, 28.0};
}

// Round tick values covering [lo, hi], about `target` of them.
std::vector<double> niceTicks(double lo, double hi, int target, double& step) {
  const double raw = std::max(hi - lo, 1e-9) / target;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  const double normalized = raw / magnitude;
  step = (normalized < 1.5   ? 1.0
          : normalized < 3.0 ? 2.0
          : normalized < 7.0 ? 5.0
                             : 10.0) *
         magnitude;
  std::vector<double> ticks;
  for (double v = std::ceil(lo / step - 1e-9) * step; v <= hi + 1e-9 * step; v += step) {
    ticks.push_back(std::abs(v) < 1e-9 * step ? 0.0 : v);
  }
  return ticks;
}

}  // namespace

// Three axes with ticks and labels in mm along edges of `box`: horizontal axes on the bottom edge
// nearest the camera (the top edge when looking down), the vertical axis on the left silhouette
// edge. An axis seen end-on is left out. Labels are 2D text anchored at 3D points, so they stay
// upright and crisp whatever the camera.
// Returns the points where labels are anchored, for the camera to frame them too.
std::vector<Eigen::Vector3d> addAxes(vtkRenderer* renderer, const Eigen::AlignedBox3d& box,
                                     const Eigen::Vector3d& direction, const Eigen::Vector3d& up,
                                     const Eigen::Vector3d& right, const detail::Palette& palette,
                                     int font_px) {
  std::vector<Eigen::Vector3d> anchors;
  const Eigen::Vector3d center = box.center();
  const double size = box.diagonal().norm();
  const bool looking_down = direction.z() > 0.9;
  vtkNew<vtkPoints> points;
  vtkNew<vtkCellArray> lines;
  const auto addLine = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    const vtkIdType ids[2] = {points->InsertNextPoint(a.data()), points->InsertNextPoint(b.data())};
    lines->InsertNextCell(2, ids);
  };
  const auto addText = [&](const std::string& text, const Eigen::Vector3d& at, int px) {
    vtkNew<vtkTextActor> label;
    label->SetInput(text.c_str());
    detail::styleText(label->GetTextProperty(), palette.text, px);
    label->GetTextProperty()->SetJustificationToCentered();
    label->GetTextProperty()->SetVerticalJustificationToCentered();
    label->GetPositionCoordinate()->SetCoordinateSystemToWorld();
    label->GetPositionCoordinate()->SetValue(at.x(), at.y(), at.z());
    renderer->AddActor2D(label);
    anchors.push_back(at);
  };
  static const char* const kTitles[3] = {"x [mm]", "y [mm]", "z [mm]"};
  for (int axis = 0; axis < 3; ++axis) {
    if (std::abs(direction[axis]) >= 0.9) continue;
    // Pick the edge parallel to `axis`: fix the two other coordinates to min or max.
    Eigen::Vector3d best_offset = Eigen::Vector3d::Zero();
    double best_score = -1e300;
    for (int corner = 0; corner < 4; ++corner) {
      Eigen::Vector3d offset = Eigen::Vector3d::Zero();
      int bit = 0;
      for (int other = 0; other < 3; ++other) {
        if (other == axis) continue;
        const bool high = ((corner >> bit++) & 1) != 0;
        offset[other] = 0.5 * (high ? box.max()[other] - box.min()[other]
                                    : box.min()[other] - box.max()[other]);
      }
      double score = 0.0;
      if (axis == 2) {
        score = -offset.dot(right) + 0.01 * offset.dot(direction);
      } else {
        const bool bottom = offset.z() < 0.0;
        score = (bottom != looking_down ? 1000.0 : 0.0) + offset.dot(direction) -
                0.01 * offset.dot(up) - 1e-4 * offset.dot(right);
      }
      if (score > best_score) {
        best_score = score;
        best_offset = offset;
      }
    }
    Eigen::Vector3d start = center + best_offset;
    start[axis] = box.min()[axis];
    Eigen::Vector3d end = start;
    end[axis] = box.max()[axis];
    addLine(start, end);
    // Offsets go outward from the box, measured in the screen plane so that labels keep their
    // distance whatever the view.
    Eigen::Vector3d outward = best_offset - best_offset.dot(direction) * direction;
    outward = outward.norm() > 1e-6 * size ? outward.normalized() : best_offset.normalized();
    // A title beside a vertical axis must clear the width of the tick labels.
    const double title_offset = std::abs(outward.dot(right)) > 0.7 ? 0.22 : 0.15;
    double step = 1.0;
    const auto ticks = niceTicks(box.min()[axis], box.max()[axis], 4, step);
    const int decimals = std::clamp(static_cast<int>(std::ceil(-std::log10(step))), 0, 3);
    for (const double value : ticks) {
      Eigen::Vector3d at = start;
      at[axis] = value;
      addLine(at, at + outward * 0.02 * size);
      char text[32];
      std::snprintf(text, sizeof text, "%.*f", decimals, value);
      addText(text, at + outward * 0.075 * size, font_px - font_px / 5);
    }
    Eigen::Vector3d middle = 0.5 * (start + end);
    addText(kTitles[axis], middle + outward * title_offset * size, font_px);
  }
  vtkNew<vtkPolyData> data;
  data->SetPoints(points);
  data->SetLines(lines);
  auto actor = makeActor(data, palette.text);
  actor->GetProperty()->LightingOff();
  renderer->AddActor(actor);
  return anchors;
}

// Places the camera along `direction` so that every point of `points` and the sphere (when
// radius_mm > 0) is in view with a small margin, centred in a viewport of `aspect` (w / h).
// Tighter than vtkRenderer::ResetCamera, which frames the bounding sphere of the bounding box.
void frameCamera(vtkCamera* camera, const std::vector<Eigen::Vector3d>& points,
                 const Eigen::Vector3d& sphere_center, double radius_mm,
                 const Eigen::Vector3d& direction, const Eigen::Vector3d& up,
                 const Eigen::Vector3d& right, double aspect) {
  constexpr double kViewAngleDeg = 30.0;
  constexpr double kMargin = 1.06;
  Eigen::Vector3d origin = points.empty() ? sphere_center : points.front();
  double r_lo = 1e300, r_hi = -1e300, u_lo = 1e300, u_hi = -1e300, near = -1e300;
  const auto extend = [&](const Eigen::Vector3d& p, double radius) {
    const Eigen::Vector3d d = p - origin;
    r_lo = std::min(r_lo, d.dot(right) - radius);
    r_hi = std::max(r_hi, d.dot(right) + radius);
    u_lo = std::min(u_lo, d.dot(up) - radius);
    u_hi = std::max(u_hi, d.dot(up) + radius);
    near = std::max(near, d.dot(direction) + radius);
  };
  for (const auto& p : points) extend(p, 0.0);
  if (radius_mm > 0.0) extend(sphere_center, radius_mm);
  const Eigen::Vector3d focus = origin + right * 0.5 * (r_lo + r_hi) + up * 0.5 * (u_lo + u_hi);
  near -= (focus - origin).dot(direction);
  const double half_height = kMargin * std::max(0.5 * (u_hi - u_lo), 0.5 * (r_hi - r_lo) / aspect);
  const double distance = near + half_height / std::tan(0.5 * kViewAngleDeg * kPi / 180.0);
  const Eigen::Vector3d eye = focus + direction * distance;
  camera->SetViewAngle(kViewAngleDeg);
  camera->SetFocalPoint(focus.data());
  camera->SetPosition(eye.data());
  camera->SetViewUp(up.data());
}

CameraBasis cameraBasis(const SceneOptions& options) {
  const CameraPreset preset = presetFor(options.view);
  const double azimuth = (preset.azimuth_deg + options.camera_azimuth_deg) * kPi / 180.0;
  const double elevation =
      std::clamp(preset.elevation_deg + options.camera_elevation_deg, -90.0, 90.0) * kPi / 180.0;
  CameraBasis basis;
  basis.direction = Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                                    std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
  const Eigen::Vector3d z_up = Eigen::Vector3d::UnitZ();
  basis.up = z_up - z_up.dot(basis.direction) * basis.direction;
  if (basis.up.norm() < 1e-3) {
    // Straight above: the operator (+x) at the bottom of the picture, y to the right.
    basis.up = Eigen::Vector3d(-std::cos(azimuth), -std::sin(azimuth), 0.0);
  }
  basis.up.normalize();
  basis.right = (-basis.direction).cross(basis.up);
  return basis;
}

}  // namespace autograv::viz::detail
