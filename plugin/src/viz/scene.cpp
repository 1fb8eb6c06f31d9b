#include "autograv/viz/scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <utility>
#include <vector>

#include <vtkLegendBoxActor.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <Eigen/Geometry>

#include "autograv/error.h"
#include "viz/enum_names.h"
#include "viz/scene_build.h"
#include "viz/scene_camera.h"

namespace autograv::viz {

namespace detail {

void addScalarBar(vtkRenderer* renderer, vtkLookupTable* table, const std::string& title,
                  const detail::Palette& palette, int font_px, bool horizontal,
                  double scene_right) {
  vtkNew<vtkScalarBarActor> bar;
  bar->SetLookupTable(table);
  bar->SetTitle(title.c_str());
  bar->SetNumberOfLabels(5);
  const double* range = table->GetRange();
  bar->SetLabelFormat(detail::labelFormat(range[0], range[1]).c_str());
  bar->UnconstrainedFontSizeOn();
  bar->DrawTickLabelsOn();
  detail::styleText(bar->GetTitleTextProperty(), palette.text, font_px, true);
  detail::styleText(bar->GetLabelTextProperty(), palette.text, font_px);
  bar->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  if (horizontal) {
    bar->SetOrientationToHorizontal();
    // Labels under the bar, the title above it: they cannot collide.
    bar->SetTextPositionToPrecedeScalarBar();
    bar->SetPosition(0.18, 0.01);
    bar->SetPosition2(0.50, kResidualBarTop - 0.015);
  } else {
    bar->SetOrientationToVertical();
    bar->SetPosition(scene_right + 0.03, 0.42);
    bar->SetPosition2(0.15, 0.48);
  }
  bar->SetBarRatio(0.25);
  renderer->AddActor2D(bar);
}

namespace {

void validate(const SceneOptions& options) {
  detail::checkImageSize(options.width_px, options.height_px, "scene");
  if (!std::isfinite(options.camera_azimuth_deg) || !std::isfinite(options.camera_elevation_deg)) {
    throw Error("scene: camera azimuth and elevation must be finite numbers of degrees");
  }
  if (!std::isfinite(options.workspace_radius_m) || options.workspace_radius_m < 0.0) {
    throw Error("scene: the workspace radius must be a finite number of metres >= 0 (0 = none)");
  }
  if (options.workspace_center_m && !options.workspace_center_m->allFinite()) {
    throw Error("scene: the workspace centre must be finite");
  }
  if (options.device_position_m && !options.device_position_m->allFinite()) {
    throw Error("scene: the device position must be finite");
  }
}

std::string defaultTitle(const GravityMap& map, const SceneSummary& summary) {
  std::ostringstream title;
  const std::string& model = map.metadata().device_model;
  const WorkspaceGrid& grid = map.grid();
  const Eigen::Vector3i& n = grid.resolution();
  title << (model.empty() ? std::string("gravity map") : model) << "   " << n.x() << "x" << n.y()
        << "x" << n.z() << " vertices, ";
  if (grid.isCube()) {
    title << std::lround(grid.maxSpacing_m() * kMmPerM) << " mm apart";
  } else {
    const Eigen::Vector3d size_mm = grid.size_m() * kMmPerM;
    title << std::lround(size_mm.x()) << "x" << std::lround(size_mm.y()) << "x"
          << std::lround(size_mm.z()) << " mm box";
  }
  title << "   " << summary.converged << "/" << summary.vertices << " converged";
  if (summary.solved > 0) title << ", " << summary.solved << " solved";
  return title.str();
}

void setUpLayers(SceneBuild& scene) {
  const detail::Rgb& background = scene.palette.background;
  scene.overlay->SetBackground(background[0], background[1], background[2]);
  scene.overlay->SetLayer(0);
  scene.renderer->SetLayer(1);
  scene.renderer->SetViewport(0.0, scene.options.ground_truth ? kResidualBarTop : 0.0, scene.right,
                              kSceneTop);
}

// Legend of the symbols actually present, in the right-hand column under the scalar bar.
void addLegend(SceneBuild& scene) {
  // Long entries are set on two lines (the column is narrow): the line after the break is an
  // entry of its own without a symbol, so that every symbol keeps the size of one line of text.
  struct Row {
    vtkPolyData* symbol;
    std::string text;
    detail::Rgb color;
  };
  std::vector<Row> rows;
  // A symbol of two points and no cells: drawn as nothing (VTK reports a null symbol, or one
  // without points, on stderr).
  vtkNew<vtkPolyData> no_symbol;
  vtkNew<vtkPoints> no_symbol_points;
  no_symbol_points->InsertNextPoint(0.0, 0.0, 0.0);
  no_symbol_points->InsertNextPoint(1.0, 1.0, 0.0);
  no_symbol->SetPoints(no_symbol_points);
  for (const auto& entry : scene.legend) {
    const auto line_break = entry.text.find('\n');
    rows.push_back({entry.symbol, entry.text.substr(0, line_break), entry.color});
    if (line_break != std::string::npos) {
      rows.push_back({no_symbol, entry.text.substr(line_break + 1), entry.color});
    }
  }
  vtkNew<vtkLegendBoxActor> legend;
  legend->SetNumberOfEntries(static_cast<int>(rows.size()));
  for (std::size_t i = 0; i < rows.size(); ++i) {
    legend->SetEntry(static_cast<int>(i), rows[i].symbol, rows[i].text.c_str(),
                     rows[i].color.data());
  }
  detail::styleText(legend->GetEntryTextProperty(), scene.palette.text, scene.font_px);
  legend->BorderOff();
  legend->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  const double legend_h = rows.size() * 1.6 * scene.font_px / scene.options.height_px;
  legend->SetPosition(scene.right + 0.01, 0.36 - legend_h);
  legend->SetPosition2(0.98 - scene.right - 0.01, legend_h);
  scene.overlay->AddActor2D(legend);
}

void addTitle(SceneBuild& scene) {
  vtkNew<vtkTextActor> title;
  const std::string& text = scene.options.title;
  title->SetInput((text.empty() ? defaultTitle(scene.map, scene.summary) : text).c_str());
  detail::styleText(title->GetTextProperty(), scene.palette.text, scene.font_px + scene.font_px / 4,
                    true);
  title->GetTextProperty()->SetVerticalJustificationToTop();
  title->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  title->SetPosition(0.015, 0.975);
  scene.overlay->AddActor2D(title);
}

// Axes along the box of the data, seen from `basis`; returns where their labels stand.
std::vector<Eigen::Vector3d> addSceneAxes(SceneBuild& scene, const CameraBasis& basis) {
  return addAxes(scene.renderer, scene.data_bounds, basis.direction, basis.up, basis.right,
                 scene.palette, scene.font_px);
}

// The preset direction, framed on the axes' labels (`frame_points`), the data, the workspace
// and the device.
void placeCamera(SceneBuild& scene, const CameraBasis& basis,
                 std::vector<Eigen::Vector3d> frame_points) {
  for (int corner = 0; corner < 8; ++corner) {
    frame_points.push_back(
        scene.data_bounds.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner)));
  }
  const SceneOptions& options = scene.options;
  if (options.device_position_m) frame_points.push_back(*options.device_position_m * kMmPerM);
  const double viewport_aspect =
      scene.right * options.width_px /
      ((kSceneTop - (options.ground_truth ? kResidualBarTop : 0.0)) * options.height_px);
  frameCamera(scene.renderer->GetActiveCamera(), frame_points, scene.sphere_center_mm,
              scene.sphere_radius_mm, basis.direction, basis.up, basis.right, viewport_aspect);
  scene.renderer->ResetCameraClippingRange();
}

// The two layers in an offscreen window of the picture's size, drawn and read back.
RgbImage renderOffscreen(SceneBuild& scene) {
  OffscreenWindow window(scene.options.width_px, scene.options.height_px);
  window.get()->SetNumberOfLayers(2);
  window.get()->AddRenderer(scene.overlay);
  window.get()->AddRenderer(scene.renderer);
  return captureWindow(window.get());
}

}  // namespace
}  // namespace detail

namespace {

constexpr std::pair<CameraView, const char*> kCameraViewNames[] = {
    {CameraView::kIso, "iso"}, {CameraView::kFront, "front"}, {CameraView::kTop, "top"}};

}  // namespace

const char* toString(CameraView view) noexcept { return detail::nameIn(kCameraViewNames, view); }

bool parseCameraView(const std::string& name, CameraView& view) noexcept {
  return detail::parseIn(kCameraViewNames, name, view);
}

SceneSummary summarizeScene(const GravityMap& map, const GroundTruth& ground_truth,
                            const Reachability& reachable) {
  SceneSummary summary;
  summary.vertices = map.grid().vertexCount();
  summary.workspace_directions = static_cast<int>(map.metadata().workspace.directions().size());
  bool any_gravity = false;
  for (const VertexEstimate& vertex : map.vertices()) {
    if (vertex.outcome == VertexOutcome::kConverged) ++summary.converged;
    if (detail::isFailed(vertex)) ++summary.failed;
    if (vertex.provenance == VertexProvenance::kFilled) ++summary.filled;
    if (detail::isMeasuredAtVertex(vertex)) ++summary.measured_at_vertex;
    if (detail::isMeasuredOffVertex(vertex)) ++summary.measured_off_vertex;
    if (detail::isSolved(vertex)) ++summary.solved;
    if (vertex.outcome == VertexOutcome::kPending) ++summary.not_visited;
    const double magnitude = vertex.gravity_n.norm();
    if (magnitude <= 0.0) continue;
    summary.min_gravity_n = any_gravity ? std::min(summary.min_gravity_n, magnitude) : magnitude;
    summary.max_gravity_n = std::max(summary.max_gravity_n, magnitude);
    any_gravity = true;
  }
  if (ground_truth) {
    detail::sampleResidual(map, ground_truth, reachable, [&](int, int, int, double residual_n) {
      if (std::isfinite(residual_n)) {
        summary.max_residual_n = std::max(summary.max_residual_n, residual_n);
      }
    });
  }
  return summary;
}

RgbImage renderScene(const GravityMap& map, const SceneOptions& options) {
  detail::validate(options);
  requireDisplay();

  detail::SceneBuild scene(map, options);
  detail::setUpLayers(scene);
  detail::addLattice(scene);
  detail::chooseArrowScale(scene);
  detail::addVertexArrows(scene);
  detail::addOffVertexMeasurements(scene);
  detail::addVertexMarkers(scene);
  detail::addWorkspace(scene);
  detail::addDevicePosition(scene);
  detail::addResidualField(scene);
  // The axes go along the box of everything drawn, so they come after the scene's content.
  const detail::CameraBasis basis = detail::cameraBasis(options);
  std::vector<Eigen::Vector3d> label_anchors = detail::addSceneAxes(scene, basis);
  detail::addLegend(scene);
  detail::addTitle(scene);
  detail::placeCamera(scene, basis, std::move(label_anchors));
  return detail::renderOffscreen(scene);
}

}  // namespace autograv::viz
