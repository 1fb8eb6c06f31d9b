#include "autograv/viz/scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <utility>
#include <vector>

#include <vtkActor.h>
#include <vtkArrowSource.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCubeSource.h>
#include <vtkDataSetSurfaceFilter.h>
#include <vtkDoubleArray.h>
#include <vtkGlyph3D.h>
#include <vtkImageData.h>
#include <vtkLegendBoxActor.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataNormals.h>
#include <vtkPolyLine.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkSphereSource.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <Eigen/Geometry>

#include "autograv/error.h"
#include "vtk_support.h"

namespace autograv::viz {

namespace {

constexpr double kMmPerM = 1000.0;
constexpr double kPi = 3.14159265358979323846;
// Longest arrow as a fraction of the grid spacing: neighbours never touch.
constexpr double kArrowFraction = 0.8;
// Residual samples per cell edge, and the most samples per axis (bounds the cost of ground truth).
constexpr int kResidualSubdivisions = 4;
constexpr int kResidualMaxSamples = 65;
// Layout in normalized window coordinates: the 3D scene on the left, a column for the scalar bar
// and the legend on the right, the title above, the residual bar below.
constexpr double kSceneRight = 0.80;
// A legend that names the kinds of value needs a wider column.
constexpr double kSceneRightWithKinds = 0.74;
constexpr double kSceneTop = 0.93;
constexpr double kResidualBarTop = 0.13;

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

// The three kinds of value a map holds, as the legend names them.
bool isMeasuredOffVertex(const VertexEstimate& vertex) noexcept {
  return vertex.measuredOffVertex();
}

bool isSolved(const VertexEstimate& vertex) noexcept {
  return vertex.provenance == VertexProvenance::kFilled && !vertex.measuredOffVertex();
}

bool isMeasuredAtVertex(const VertexEstimate& vertex) noexcept {
  return vertex.outcome == VertexOutcome::kConverged &&
         vertex.provenance == VertexProvenance::kMeasured && !vertex.measuredOffVertex();
}

bool isFailed(const VertexEstimate& vertex) noexcept {
  return vertex.outcome != VertexOutcome::kConverged && vertex.outcome != VertexOutcome::kPending &&
         vertex.provenance != VertexProvenance::kFilled;
}

int residualSubdivisions(const WorkspaceGrid& grid) noexcept {
  const int cells = grid.resolution().maxCoeff() - 1;
  return std::clamp((kResidualMaxSamples - 1) / cells, 1, kResidualSubdivisions);
}

Eigen::Vector3i residualSamplesPerAxis(const WorkspaceGrid& grid) noexcept {
  return (grid.resolution().array() - 1) * residualSubdivisions(grid) + 1;
}

// Calls visit(ix, iy, iz, residual_n) on a regular sampling of the grid's box. The residual is
// NaN ("no data") where the interpolation uses a vertex that was never visited: its zero estimate
// says nothing about the method and would swamp the colour range.
template <typename Visit>
void sampleResidual(const GravityMap& map, const GroundTruth& truth, const Reachability& reachable,
                    Visit visit) {
  const WorkspaceGrid& grid = map.grid();
  const int subdivisions = residualSubdivisions(grid);
  const Eigen::Vector3i samples = residualSamplesPerAxis(grid);
  const Eigen::Vector3d step_m =
      grid.size_m().cwiseQuotient((samples.array() - 1).cast<double>().matrix());
  const Eigen::Vector3d origin_m = grid.minCorner_m();
  // The vertex range [first, last] along one axis that a sample index interpolates from.
  const auto span = [&](int sample, int& first, int& last) {
    first = sample / subdivisions;
    last = sample % subdivisions == 0 ? first : first + 1;
  };
  for (int iz = 0; iz < samples.z(); ++iz) {
    for (int iy = 0; iy < samples.y(); ++iy) {
      for (int ix = 0; ix < samples.x(); ++ix) {
        int x0, x1, y0, y1, z0, z1;
        span(ix, x0, x1);
        span(iy, y0, y1);
        span(iz, z0, z1);
        bool visited = true;
        for (int vz = z0; vz <= z1 && visited; ++vz) {
          for (int vy = y0; vy <= y1 && visited; ++vy) {
            for (int vx = x0; vx <= x1 && visited; ++vx) {
              const auto index = static_cast<std::size_t>(grid.vertexIndex(vx, vy, vz));
              visited = map.vertices()[index].outcome != VertexOutcome::kPending;
            }
          }
        }
        if (!visited) {
          visit(ix, iy, iz, std::numeric_limits<double>::quiet_NaN());
          continue;
        }
        const Eigen::Vector3d position_m =
            origin_m + step_m.cwiseProduct(Eigen::Vector3d(ix, iy, iz));
        if (reachable && !reachable(position_m)) {
          // A box fitted to the workspace pokes out of it: no truth there, and no hand either.
          visit(ix, iy, iz, std::numeric_limits<double>::quiet_NaN());
          continue;
        }
        const Eigen::Vector3d truth_n = truth(position_m);
        if (!truth_n.allFinite()) {
          throw Error("scene: the ground-truth gravity is not finite at a point of the grid");
        }
        visit(ix, iy, iz, (map.gravityAt(position_m) - truth_n).norm());
      }
    }
  }
}

vtkSmartPointer<vtkActor> makeActor(vtkPolyData* data, const detail::Rgb& color) {
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(data);
  mapper->ScalarVisibilityOff();
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(color[0], color[1], color[2]);
  return actor;
}

// The lattice: one straight line per row of vertices along each axis.
vtkSmartPointer<vtkPolyData> latticeLines(const WorkspaceGrid& grid) {
  const Eigen::Vector3i n = grid.resolution();
  vtkNew<vtkPoints> points;
  for (int i = 0; i < grid.vertexCount(); ++i) {
    const Eigen::Vector3d p = grid.vertexPosition(i) * kMmPerM;
    points->InsertNextPoint(p.x(), p.y(), p.z());
  }
  vtkNew<vtkCellArray> lines;
  for (int iz = 0; iz < n.z(); ++iz) {
    for (int iy = 0; iy < n.y(); ++iy) {
      const vtkIdType along_x[2] = {grid.vertexIndex(0, iy, iz),
                                    grid.vertexIndex(n.x() - 1, iy, iz)};
      lines->InsertNextCell(2, along_x);
    }
  }
  for (int iz = 0; iz < n.z(); ++iz) {
    for (int ix = 0; ix < n.x(); ++ix) {
      const vtkIdType along_y[2] = {grid.vertexIndex(ix, 0, iz),
                                    grid.vertexIndex(ix, n.y() - 1, iz)};
      lines->InsertNextCell(2, along_y);
    }
  }
  for (int iy = 0; iy < n.y(); ++iy) {
    for (int ix = 0; ix < n.x(); ++ix) {
      const vtkIdType along_z[2] = {grid.vertexIndex(ix, iy, 0),
                                    grid.vertexIndex(ix, iy, n.z() - 1)};
      lines->InsertNextCell(2, along_z);
    }
  }
  auto data = vtkSmartPointer<vtkPolyData>::New();
  data->SetPoints(points);
  data->SetLines(lines);
  return data;
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

// What the steps of renderScene share: the map, the options, and what earlier steps made.
struct SceneBuild {
  SceneBuild(const GravityMap& m, const SceneOptions& o)
      : map(m),
        options(o),
        palette(detail::paletteFor(o.background)),
        summary(summarizeScene(m)),
        spacing_mm(m.grid().spacing_m().minCoeff() * kMmPerM),
        marker_mm(0.11 * spacing_mm),
        font_px(detail::baseFontPx(o.height_px)),
        right(summary.measured_off_vertex > 0 || summary.solved > 0 ? kSceneRightWithKinds
                                                                    : kSceneRight),
        // The box of the data (grid, arrows, workspace) carries the axes.
        data_bounds(m.grid().minCorner_m() * kMmPerM, m.grid().maxCorner_m() * kMmPerM) {}

  const GravityMap& map;
  const SceneOptions& options;
  const detail::Palette palette;
  const SceneSummary summary;
  const double spacing_mm;
  const double marker_mm;  ///< Size of the vertex markers. Unit: [mm]
  const int font_px;
  /// Right edge of the 3D scene's viewport; the scalar bar and the legend are right of it.
  const double right;
  Eigen::AlignedBox3d data_bounds;  ///< Unit: [mm]
  /// The device's sphere, framed too when drawn (radius 0: none). Unit: [mm]
  Eigen::Vector3d sphere_center_mm = Eigen::Vector3d::Zero();
  double sphere_radius_mm = 0.0;

  // Arrows: one length rule and one colour range for the vertex values and the measurements.
  double gravity_lo_n = 0.0;
  double gravity_hi_n = 0.0;
  double arrow_mm_per_n = 0.0;
  vtkSmartPointer<vtkLookupTable> gravity_table;

  // Two layers: `overlay` (full window: background, title, scalar bars, legend) below and
  // `renderer` (the 3D scene, in the area the annotations leave free) on top, so that text never
  // lands on the scene whatever the camera does.
  vtkNew<vtkRenderer> overlay;
  vtkNew<vtkRenderer> renderer;

  struct LegendEntry {
    vtkSmartPointer<vtkPolyData> symbol;
    std::string text;
    detail::Rgb color;
  };
  std::vector<LegendEntry> legend;
};

// Marker shapes, one per kind of vertex.
vtkSmartPointer<vtkPolyData> sphereShape(double radius_mm, int theta = 20, int phi = 14) {
  vtkNew<vtkSphereSource> sphere;
  sphere->SetRadius(radius_mm);
  sphere->SetThetaResolution(theta);
  sphere->SetPhiResolution(phi);
  sphere->Update();
  return sphere->GetOutput();
}

vtkSmartPointer<vtkPolyData> cubeShape(double side_mm) {
  vtkNew<vtkCubeSource> cube;
  cube->SetXLength(side_mm);
  cube->SetYLength(side_mm);
  cube->SetZLength(side_mm);
  cube->Update();
  return cube->GetOutput();
}

vtkSmartPointer<vtkActor> glyphActor(vtkPolyData* points, vtkPolyData* shape,
                                     const detail::Rgb& color) {
  vtkNew<vtkGlyph3D> glyphs;
  glyphs->SetInputData(points);
  glyphs->SetSourceData(shape);
  glyphs->ScalingOff();
  glyphs->OrientOff();
  glyphs->Update();
  auto data = vtkSmartPointer<vtkPolyData>::New();
  data->ShallowCopy(glyphs->GetOutput());
  return makeActor(data, color);
}

vtkSmartPointer<vtkPolyData> pointCloud(const std::vector<Eigen::Vector3d>& points_mm) {
  vtkNew<vtkPoints> points;
  for (const Eigen::Vector3d& p : points_mm) points->InsertNextPoint(p.data());
  auto data = vtkSmartPointer<vtkPolyData>::New();
  data->SetPoints(points);
  return data;
}

void setUpLayers(SceneBuild& scene) {
  const detail::Rgb& background = scene.palette.background;
  scene.overlay->SetBackground(background[0], background[1], background[2]);
  scene.overlay->SetLayer(0);
  scene.renderer->SetLayer(1);
  scene.renderer->SetViewport(0.0, scene.options.ground_truth ? kResidualBarTop : 0.0, scene.right,
                              kSceneTop);
}

void addLattice(SceneBuild& scene) {
  auto lattice = makeActor(latticeLines(scene.map.grid()), scene.palette.lattice);
  lattice->GetProperty()->SetLineWidth(scene.options.height_px >= 720 ? 1.5f : 1.0f);
  lattice->GetProperty()->LightingOff();
  scene.renderer->AddActor(lattice);
}

// The colour range and the length rule of every gravity arrow: the longest is kArrowFraction of
// the grid spacing, so neighbours never touch.
void chooseArrowScale(SceneBuild& scene) {
  double lo = scene.summary.min_gravity_n;
  double hi = scene.summary.max_gravity_n;
  for (const VertexEstimate& vertex : scene.map.vertices()) {
    if (!vertex.measuredOffVertex()) continue;
    const double magnitude = vertex.measured_gravity_n.norm();
    if (!(magnitude > 0.0)) continue;
    lo = hi > 0.0 ? std::min(lo, magnitude) : magnitude;
    hi = std::max(hi, magnitude);
  }
  if (hi > 0.0) scene.arrow_mm_per_n = kArrowFraction * scene.spacing_mm / hi;
  if (hi - lo < 1e-6) {
    const double pad = 0.05 * hi + 1e-3;
    lo = std::max(0.0, lo - pad);
    hi += pad;
  }
  scene.gravity_lo_n = lo;
  scene.gravity_hi_n = hi;
  scene.gravity_table = detail::makeLookupTable(scene.options.color_map, lo, hi);
}

// Arrows from `origins_mm` along `gravity_n`, scaled and coloured by |G| like every other.
void addGravityArrows(SceneBuild& scene, const std::vector<Eigen::Vector3d>& origins_mm,
                      const std::vector<Eigen::Vector3d>& gravity_n, double thickness) {
  if (origins_mm.empty()) return;
  vtkNew<vtkPoints> points;
  vtkNew<vtkDoubleArray> vectors;
  vectors->SetName("gravity_N");
  vectors->SetNumberOfComponents(3);
  vtkNew<vtkDoubleArray> magnitudes;
  magnitudes->SetName("gravity_magnitude_N");
  for (std::size_t i = 0; i < origins_mm.size(); ++i) {
    const Eigen::Vector3d& p = origins_mm[i];
    const Eigen::Vector3d& g = gravity_n[i];
    points->InsertNextPoint(p.x(), p.y(), p.z());
    vectors->InsertNextTuple3(g.x(), g.y(), g.z());
    magnitudes->InsertNextValue(g.norm());
    scene.data_bounds.extend(p + g * scene.arrow_mm_per_n);
  }
  vtkNew<vtkPolyData> arrows_input;
  arrows_input->SetPoints(points);
  arrows_input->GetPointData()->SetVectors(vectors);
  arrows_input->GetPointData()->SetScalars(magnitudes);
  vtkNew<vtkArrowSource> arrow;
  arrow->SetTipResolution(16);
  arrow->SetShaftResolution(12);
  arrow->SetTipLength(0.3);
  arrow->SetTipRadius(0.1 * thickness);
  arrow->SetShaftRadius(0.035 * thickness);
  vtkNew<vtkGlyph3D> glyphs;
  glyphs->SetInputData(arrows_input);
  glyphs->SetSourceConnection(arrow->GetOutputPort());
  glyphs->SetVectorModeToUseVector();
  glyphs->SetScaleModeToScaleByVector();
  glyphs->SetScaleFactor(scene.arrow_mm_per_n);
  glyphs->SetColorModeToColorByScalar();
  glyphs->OrientOn();
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(glyphs->GetOutputPort());
  mapper->SetLookupTable(scene.gravity_table);
  mapper->SetScalarRange(scene.gravity_lo_n, scene.gravity_hi_n);
  mapper->ScalarVisibilityOn();
  vtkNew<vtkActor> arrows;
  arrows->SetMapper(mapper);
  arrows->GetProperty()->SetAmbient(0.25);
  arrows->GetProperty()->SetDiffuse(0.8);
  scene.renderer->AddActor(arrows);
}

// One arrow per vertex value and the |G_hat| scalar bar; the legend's first entry names them.
void addVertexArrows(SceneBuild& scene) {
  if (scene.summary.max_gravity_n <= 0.0) return;
  const WorkspaceGrid& grid = scene.map.grid();
  std::vector<Eigen::Vector3d> origins_mm;
  std::vector<Eigen::Vector3d> gravity_n;
  for (int i = 0; i < grid.vertexCount(); ++i) {
    const Eigen::Vector3d& g = scene.map.vertices()[static_cast<std::size_t>(i)].gravity_n;
    if (g.norm() <= 0.0) continue;
    origins_mm.push_back(grid.vertexPosition(i) * kMmPerM);
    gravity_n.push_back(g);
  }
  addGravityArrows(scene, origins_mm, gravity_n, 1.0);
  addScalarBar(scene.overlay, scene.gravity_table, detail::pickText("|\u011c| [N]", "|G_hat| [N]"),
               scene.palette, scene.font_px, false, scene.right);
  vtkNew<vtkArrowSource> symbol;
  symbol->Update();
  double mid[3];
  scene.gravity_table->GetColor(0.5 * (scene.gravity_lo_n + scene.gravity_hi_n), mid);
  // One kind only (every value measured at its vertex): nothing to tell apart, one word says it.
  const SceneSummary& summary = scene.summary;
  const bool kinds = summary.measured_off_vertex > 0 || summary.solved > 0;
  const std::string text =
      kinds ? "measured at\nthe vertex: " + std::to_string(summary.measured_at_vertex) : "estimate";
  scene.legend.push_back({symbol->GetOutput(), text, {mid[0], mid[1], mid[2]}});
}

// Points measured inside the stops for vertices beyond them: a pink bead with the measured
// arrow, and a thin line to the vertex whose value they went into.
void addOffVertexMeasurements(SceneBuild& scene) {
  if (scene.summary.measured_off_vertex == 0) return;
  const WorkspaceGrid& grid = scene.map.grid();
  std::vector<Eigen::Vector3d> points_mm;
  std::vector<Eigen::Vector3d> arrow_points_mm;
  std::vector<Eigen::Vector3d> measured_n;
  vtkNew<vtkPoints> link_points;
  vtkNew<vtkCellArray> links;
  for (int i = 0; i < grid.vertexCount(); ++i) {
    const VertexEstimate& vertex = scene.map.vertices()[static_cast<std::size_t>(i)];
    if (!vertex.measuredOffVertex()) continue;
    const Eigen::Vector3d at_mm = vertex.measured_at_m * kMmPerM;
    const Eigen::Vector3d vertex_mm = grid.vertexPosition(i) * kMmPerM;
    points_mm.push_back(at_mm);
    scene.data_bounds.extend(at_mm);
    const vtkIdType ids[2] = {link_points->InsertNextPoint(at_mm.data()),
                              link_points->InsertNextPoint(vertex_mm.data())};
    links->InsertNextCell(2, ids);
    if (vertex.measured_gravity_n.norm() > 0.0) {
      arrow_points_mm.push_back(at_mm);
      measured_n.push_back(vertex.measured_gravity_n);
    }
  }
  addGravityArrows(scene, arrow_points_mm, measured_n, 0.75);
  vtkNew<vtkPolyData> link_data;
  link_data->SetPoints(link_points);
  link_data->SetLines(links);
  auto link_actor = makeActor(link_data, scene.palette.off_vertex);
  link_actor->GetProperty()->SetLineWidth(1.0f);
  link_actor->GetProperty()->LightingOff();
  scene.renderer->AddActor(link_actor);
  auto bead = sphereShape(0.7 * scene.marker_mm, 16, 10);
  scene.renderer->AddActor(glyphActor(pointCloud(points_mm), bead, scene.palette.off_vertex));
  scene.legend.push_back(
      {sphereShape(scene.marker_mm),
       "measured inside\nthe stops: " + std::to_string(scene.summary.measured_off_vertex),
       scene.palette.off_vertex});
}

// Points (in mm) of the vertices that satisfy `keep`.
template <typename Keep>
std::vector<Eigen::Vector3d> vertexPositions_mm(const GravityMap& map, Keep keep) {
  std::vector<Eigen::Vector3d> positions;
  for (int i = 0; i < map.grid().vertexCount(); ++i) {
    if (keep(map.vertices()[static_cast<std::size_t>(i)])) {
      positions.push_back(map.grid().vertexPosition(i) * kMmPerM);
    }
  }
  return positions;
}

// Solved vertices (purple diamonds), failed ones (red spheres), unvisited ones (grey cubes).
void addVertexMarkers(SceneBuild& scene) {
  const SceneSummary& summary = scene.summary;
  const detail::Palette& palette = scene.palette;
  const double marker_mm = scene.marker_mm;
  if (summary.solved > 0) {
    // A diamond, so that measured and solved values are told apart at a glance; their arrows are
    // drawn like the others.
    auto diamond = sphereShape(0.9 * marker_mm, 4, 3);
    scene.renderer->AddActor(
        glyphActor(pointCloud(vertexPositions_mm(scene.map, isSolved)), diamond, palette.filled));
    scene.legend.push_back({diamond,
                            "solved from the\nmeasurements: " + std::to_string(summary.solved),
                            palette.filled});
  }
  if (summary.failed > 0) {
    auto sphere = sphereShape(marker_mm);
    scene.renderer->AddActor(
        glyphActor(pointCloud(vertexPositions_mm(scene.map, isFailed)), sphere, palette.failed));
    scene.legend.push_back({sphere, "failed: " + std::to_string(summary.failed), palette.failed});
  }
  if (summary.not_visited > 0) {
    auto cube = cubeShape(1.4 * marker_mm);
    const auto pending = [](const VertexEstimate& v) {
      return v.outcome == VertexOutcome::kPending;
    };
    scene.renderer->AddActor(
        glyphActor(pointCloud(vertexPositions_mm(scene.map, pending)), cube, palette.not_visited));
    scene.legend.push_back(
        {cube, "unvisited: " + std::to_string(summary.not_visited), palette.not_visited});
  }
}

// `opacity` without ground truth; the residual field behind it asks for less.
void addTranslucentSurface(SceneBuild& scene, vtkAlgorithmOutput* surface, double opacity) {
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(surface);
  mapper->ScalarVisibilityOff();
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  const detail::Rgb& color = scene.palette.workspace;
  actor->GetProperty()->SetColor(color[0], color[1], color[2]);
  actor->GetProperty()->SetOpacity(scene.options.ground_truth ? 0.6 * opacity : opacity);
  actor->GetProperty()->BackfaceCullingOn();
  scene.renderer->AddActor(actor);
}

// The explored workspace: a translucent surface through the probes' stops (the boundary model
// the measurement plan uses, sampled over the sphere of directions), and a dot at each stop.
void addExploredWorkspace(SceneBuild& scene, const ExploredWorkspace& workspace) {
  constexpr int kLongitudes = 72;
  constexpr int kLatitudes = 36;
  vtkNew<vtkSphereSource> directions;
  directions->SetRadius(1.0);
  directions->SetThetaResolution(kLongitudes);
  directions->SetPhiResolution(kLatitudes);
  directions->Update();
  vtkNew<vtkPolyData> surface;
  surface->DeepCopy(directions->GetOutput());
  surface->GetPointData()->SetNormals(nullptr);
  vtkPoints* points = surface->GetPoints();
  const Eigen::Vector3d center_mm = workspace.center_m() * kMmPerM;
  for (vtkIdType i = 0; i < points->GetNumberOfPoints(); ++i) {
    double u[3];
    points->GetPoint(i, u);
    const Eigen::Vector3d direction(u[0], u[1], u[2]);
    const Eigen::Vector3d p =
        center_mm + direction * (workspace.boundaryDistance_m(direction) * kMmPerM);
    points->SetPoint(i, p.data());
    scene.data_bounds.extend(p);
  }
  vtkNew<vtkPolyDataNormals> normals;
  normals->SetInputData(surface);
  normals->SplittingOff();
  normals->ConsistencyOn();
  addTranslucentSurface(scene, normals->GetOutputPort(), 0.16);

  std::vector<Eigen::Vector3d> stops_mm;
  for (std::size_t i = 0; i < workspace.directions().size(); ++i) {
    stops_mm.push_back(center_mm + workspace.directions()[i] * (workspace.radii_m()[i] * kMmPerM));
  }
  auto dot = sphereShape(0.45 * scene.marker_mm, 12, 8);
  auto dots = glyphActor(pointCloud(stops_mm), dot, scene.palette.workspace);
  scene.renderer->AddActor(dots);
  scene.legend.push_back(
      {dot,
       "explored workspace:\n" + std::to_string(workspace.directions().size()) + " probe stops",
       scene.palette.workspace});
}

// The workspace: the explored one when the map has it, else the device's reachable sphere when
// known, else the grid's box.
void addWorkspace(SceneBuild& scene) {
  const SceneOptions& options = scene.options;
  const ExploredWorkspace& explored = scene.map.metadata().workspace;
  if (options.show_explored_workspace && !explored.empty()) {
    addExploredWorkspace(scene, explored);
    return;
  }
  const WorkspaceGrid& grid = scene.map.grid();
  const Eigen::Vector3d center_mm = grid.center_m() * kMmPerM;
  if (options.workspace_radius_m > 0.0) {
    scene.sphere_center_mm = options.workspace_center_m
                                 ? Eigen::Vector3d(*options.workspace_center_m * kMmPerM)
                                 : center_mm;
    scene.sphere_radius_mm = options.workspace_radius_m * kMmPerM;
    vtkNew<vtkSphereSource> workspace;
    workspace->SetCenter(scene.sphere_center_mm.data());
    workspace->SetRadius(scene.sphere_radius_mm);
    workspace->SetThetaResolution(64);
    workspace->SetPhiResolution(40);
    addTranslucentSurface(scene, workspace->GetOutputPort(), 0.10);
  } else {
    vtkNew<vtkCubeSource> workspace;
    workspace->SetCenter(center_mm.data());
    workspace->SetXLength(grid.size_m().x() * kMmPerM);
    workspace->SetYLength(grid.size_m().y() * kMmPerM);
    workspace->SetZLength(grid.size_m().z() * kMmPerM);
    addTranslucentSurface(scene, workspace->GetOutputPort(), 0.10);
  }
}

void addDevicePosition(SceneBuild& scene) {
  if (!scene.options.device_position_m) return;
  const Eigen::Vector3d p = *scene.options.device_position_m * kMmPerM;
  vtkNew<vtkSphereSource> device;
  device->SetCenter(p.data());
  device->SetRadius(0.16 * scene.spacing_mm);
  device->SetThetaResolution(24);
  device->SetPhiResolution(16);
  device->Update();
  scene.renderer->AddActor(makeActor(device->GetOutput(), scene.palette.device));
  scene.legend.push_back({sphereShape(scene.marker_mm), "device", scene.palette.device});
}

// The residual against ground truth, on the faces of the grid's box, with its own scalar bar.
void addResidualField(SceneBuild& scene) {
  const SceneOptions& options = scene.options;
  if (!options.ground_truth) return;
  const WorkspaceGrid& grid = scene.map.grid();
  const Eigen::Vector3i samples = residualSamplesPerAxis(grid);
  vtkNew<vtkImageData> field;
  field->SetDimensions(samples.x(), samples.y(), samples.z());
  const Eigen::Vector3d origin_mm = grid.minCorner_m() * kMmPerM;
  field->SetOrigin(origin_mm.data());
  const Eigen::Vector3d step_mm =
      (grid.size_m() * kMmPerM).cwiseQuotient((samples.array() - 1).cast<double>().matrix());
  field->SetSpacing(step_mm.x(), step_mm.y(), step_mm.z());
  vtkNew<vtkDoubleArray> residual;
  residual->SetName("residual_N");
  residual->SetNumberOfValues(static_cast<vtkIdType>(samples.x()) * samples.y() * samples.z());
  double max_residual_n = 0.0;
  sampleResidual(scene.map, options.ground_truth, options.reachable,
                 [&](int ix, int iy, int iz, double residual_n) {
                   residual->SetValue(
                       (static_cast<vtkIdType>(iz) * samples.y() + iy) * samples.x() + ix,
                       residual_n);
                   if (std::isfinite(residual_n))
                     max_residual_n = std::max(max_residual_n, residual_n);
                 });
  field->GetPointData()->SetScalars(residual);
  vtkNew<vtkDataSetSurfaceFilter> surface;
  surface->SetInputData(field);
  const double top = max_residual_n > 0.0 ? max_residual_n : 1e-3;
  auto residual_table = detail::makeResidualLookupTable(top);
  const detail::Rgb& no_data = scene.palette.not_visited;
  residual_table->SetNanColor(no_data[0], no_data[1], no_data[2], 1.0);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(surface->GetOutputPort());
  mapper->SetLookupTable(residual_table);
  mapper->SetScalarRange(0.0, top);
  mapper->ScalarVisibilityOn();
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  actor->GetProperty()->SetOpacity(0.35);
  actor->GetProperty()->SetAmbient(0.6);
  actor->GetProperty()->SetDiffuse(0.4);
  actor->GetProperty()->BackfaceCullingOn();
  scene.renderer->AddActor(actor);
  addScalarBar(scene.overlay, residual_table,
               detail::pickText("|\u011c \u2212 G_true| [N]", "|G_hat - G_true| [N]"),
               scene.palette, scene.font_px, true, scene.right);
}

// The camera's direction from the preset and the adjustments; `up` and `right` as on the screen.
struct CameraBasis {
  Eigen::Vector3d direction;
  Eigen::Vector3d up;
  Eigen::Vector3d right;
};

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

}  // namespace

const char* toString(CameraView view) noexcept {
  switch (view) {
    case CameraView::kFront:
      return "front";
    case CameraView::kTop:
      return "top";
    case CameraView::kIso:
      break;
  }
  return "iso";
}

bool parseCameraView(const std::string& name, CameraView& view) noexcept {
  for (const CameraView candidate : {CameraView::kIso, CameraView::kFront, CameraView::kTop}) {
    if (name == toString(candidate)) {
      view = candidate;
      return true;
    }
  }
  return false;
}

SceneSummary summarizeScene(const GravityMap& map, const GroundTruth& ground_truth,
                            const Reachability& reachable) {
  SceneSummary summary;
  summary.vertices = map.grid().vertexCount();
  summary.workspace_directions = static_cast<int>(map.metadata().workspace.directions().size());
  bool any_gravity = false;
  for (const VertexEstimate& vertex : map.vertices()) {
    if (vertex.outcome == VertexOutcome::kConverged) ++summary.converged;
    if (isFailed(vertex)) ++summary.failed;
    if (vertex.provenance == VertexProvenance::kFilled) ++summary.filled;
    if (isMeasuredAtVertex(vertex)) ++summary.measured_at_vertex;
    if (isMeasuredOffVertex(vertex)) ++summary.measured_off_vertex;
    if (isSolved(vertex)) ++summary.solved;
    if (vertex.outcome == VertexOutcome::kPending) ++summary.not_visited;
    const double magnitude = vertex.gravity_n.norm();
    if (magnitude <= 0.0) continue;
    summary.min_gravity_n = any_gravity ? std::min(summary.min_gravity_n, magnitude) : magnitude;
    summary.max_gravity_n = std::max(summary.max_gravity_n, magnitude);
    any_gravity = true;
  }
  if (ground_truth) {
    sampleResidual(map, ground_truth, reachable, [&](int, int, int, double residual_n) {
      if (std::isfinite(residual_n)) {
        summary.max_residual_n = std::max(summary.max_residual_n, residual_n);
      }
    });
  }
  return summary;
}

RgbImage renderScene(const GravityMap& map, const SceneOptions& options) {
  validate(options);
  requireDisplay();

  SceneBuild scene(map, options);
  setUpLayers(scene);
  addLattice(scene);
  chooseArrowScale(scene);
  addVertexArrows(scene);
  addOffVertexMeasurements(scene);
  addVertexMarkers(scene);
  addWorkspace(scene);
  addDevicePosition(scene);
  addResidualField(scene);
  // The axes go along the box of everything drawn, so they come after the scene's content.
  const CameraBasis basis = cameraBasis(options);
  std::vector<Eigen::Vector3d> label_anchors =
      addAxes(scene.renderer, scene.data_bounds, basis.direction, basis.up, basis.right,
              scene.palette, scene.font_px);
  addLegend(scene);
  addTitle(scene);
  placeCamera(scene, basis, std::move(label_anchors));

  detail::OffscreenWindow window(options.width_px, options.height_px);
  window.get()->SetNumberOfLayers(2);
  window.get()->AddRenderer(scene.overlay);
  window.get()->AddRenderer(scene.renderer);
  return detail::captureWindow(window.get());
}

}  // namespace autograv::viz
