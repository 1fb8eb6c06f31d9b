// The steps of renderScene that draw the map's content: lattice, arrows, where each value was
// measured, the workspace, the device and the residual field.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <vtkActor.h>
#include <vtkArrowSource.h>
#include <vtkCellArray.h>
#include <vtkCubeSource.h>
#include <vtkDataSetSurfaceFilter.h>
#include <vtkDoubleArray.h>
#include <vtkGlyph3D.h>
#include <vtkImageData.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataNormals.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkSphereSource.h>

#include "autograv/image/arrow_length.h"
#include "viz/scene_build.h"

namespace autograv::viz::detail {

namespace {

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

}  // namespace

vtkSmartPointer<vtkActor> makeActor(vtkPolyData* data, const detail::Rgb& color) {
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(data);
  mapper->ScalarVisibilityOff();
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(color[0], color[1], color[2]);
  return actor;
}

void addLattice(SceneBuild& scene) {
  auto lattice = makeActor(latticeLines(scene.map.grid()), scene.palette.lattice);
  lattice->GetProperty()->SetLineWidth(scene.options.height_px >= 720 ? 1.5f : 1.0f);
  lattice->GetProperty()->LightingOff();
  scene.renderer->AddActor(lattice);
}

// The colour range and the length of every gravity arrow (autograv/image/arrow_length.h: the
// longest is kLongestArrowFraction of the grid spacing).
void chooseArrowScale(SceneBuild& scene) {
  double lo = scene.summary.min_gravity_n;
  double hi = scene.summary.max_gravity_n;
  for (const VertexEstimate& vertex : scene.map.vertices()) {
    if (valueKind(vertex) != ValueKind::kOffVertex) continue;
    const double magnitude = vertex.measured_gravity_n.norm();
    if (!(magnitude > 0.0)) continue;
    lo = hi > 0.0 ? std::min(lo, magnitude) : magnitude;
    hi = std::max(hi, magnitude);
  }
  scene.arrow_mm_per_n = arrowLengthPerNewton(scene.spacing_mm, hi);
  if (hi - lo < 1e-6) {
    const double pad = 0.05 * hi + 1e-3;
    lo = std::max(0.0, lo - pad);
    hi += pad;
  }
  scene.gravity_lo_n = lo;
  scene.gravity_hi_n = hi;
  scene.gravity_table = detail::makeLookupTable(scene.options.color_map, lo, hi);
}

namespace {

// Arrows from `origins_mm` along `gravity_n`, scaled and coloured by |G| like every other, drawn
// at `opacity`.
void addGravityArrows(SceneBuild& scene, const std::vector<Eigen::Vector3d>& origins_mm,
                      const std::vector<Eigen::Vector3d>& gravity_n, double thickness,
                      double opacity = 1.0) {
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
  arrows->GetProperty()->SetOpacity(opacity);
  scene.renderer->AddActor(arrows);
}

// How much an arrow at a vertex whose value was not measured where it stands (beyond the
// explored stops, or out of reach) shows: the field there is the fit's extrapolation, where no
// hand can be, and must not look like a measurement.
constexpr double kExtrapolatedArrowOpacity = 0.3;
constexpr double kExtrapolatedArrowThickness = 0.6;

}  // namespace

// One arrow per vertex value and the |G_hat| scalar bar; the legend's first entry names them.
// The values measured at their vertex are drawn in full, those beyond the stops (extrapolated
// from the measurements) thin and faint.
void addVertexArrows(SceneBuild& scene) {
  if (scene.summary.max_gravity_n <= 0.0) return;
  const WorkspaceGrid& grid = scene.map.grid();
  std::vector<Eigen::Vector3d> measured_mm, extrapolated_mm;
  std::vector<Eigen::Vector3d> measured_n, extrapolated_n;
  for (int i = 0; i < grid.vertexCount(); ++i) {
    const VertexEstimate& vertex = scene.map.vertices()[static_cast<std::size_t>(i)];
    if (vertex.gravity_n.norm() <= 0.0) continue;
    const bool at_vertex = valueKind(vertex) == ValueKind::kAtVertex;
    (at_vertex ? measured_mm : extrapolated_mm).push_back(grid.vertexPosition(i) * kMmPerM);
    (at_vertex ? measured_n : extrapolated_n).push_back(vertex.gravity_n);
  }
  addGravityArrows(scene, measured_mm, measured_n, 1.0);
  addGravityArrows(scene, extrapolated_mm, extrapolated_n, kExtrapolatedArrowThickness,
                   kExtrapolatedArrowOpacity);
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
  if (!extrapolated_mm.empty()) {
    // The faint arrows' entry: the colour map's middle washed out toward the background, half
    // as far as the arrows are, so that its words stay legible on either background.
    constexpr double kLegendWash = 0.5 * (1.0 - kExtrapolatedArrowOpacity);
    const detail::Rgb& background = scene.palette.background;
    detail::Rgb faint{};
    for (std::size_t c = 0; c < faint.size(); ++c) {
      faint[c] = (1.0 - kLegendWash) * mid[c] + kLegendWash * background[c];
    }
    scene.legend.push_back(
        {symbol->GetOutput(),
         "beyond the stops,\nextrapolated: " + std::to_string(extrapolated_mm.size()), faint});
  }
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
    if (valueKind(vertex) != ValueKind::kOffVertex) continue;
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

namespace {

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

}  // namespace

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

namespace {

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

}  // namespace

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

}  // namespace autograv::viz::detail
