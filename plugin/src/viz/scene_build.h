#pragma once

// Private to autograv::viz: what the steps of renderScene (scene.cpp, scene_content.cpp,
// scene_camera.cpp) share.

#include <limits>
#include <string>
#include <vector>

#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>
#include <Eigen/Geometry>

#include "autograv/error.h"
#include "autograv/map/map_summary.h"
#include "autograv/map/value_kind.h"
#include "autograv/viz/scene.h"
#include "viz/vtk_support.h"

class vtkActor;

namespace autograv::viz::detail {

inline constexpr double kMmPerM = 1000.0;
inline constexpr double kPi = 3.14159265358979323846;
// Residual samples per cell edge, and the most samples per axis (bounds the cost of ground truth).
inline constexpr int kResidualSubdivisions = 4;
inline constexpr int kResidualMaxSamples = 65;
// Layout in normalized window coordinates: the 3D scene on the left, a column for the scalar bar
// and the legend on the right, the title above, the residual bar below.
inline constexpr double kSceneRight = 0.80;
// A legend that names the kinds of value needs a wider column.
inline constexpr double kSceneRightWithKinds = 0.74;
inline constexpr double kSceneTop = 0.93;
inline constexpr double kResidualBarTop = 0.13;

// The three kinds of value a map holds (autograv/map/value_kind.h), as the legend names them.
inline bool isMeasuredOffVertex(const VertexEstimate& vertex) noexcept {
  return valueKind(vertex) == ValueKind::kOffVertex;
}

inline bool isSolved(const VertexEstimate& vertex) noexcept {
  return valueKind(vertex) == ValueKind::kSolved;
}

inline bool isMeasuredAtVertex(const VertexEstimate& vertex) noexcept {
  return valueKind(vertex) == ValueKind::kAtVertex;
}

// Marked red as "failed": visited, and the map holds no value there (autograv/map/map_summary.h).
inline bool isFailed(const VertexEstimate& vertex) noexcept { return holdsNoValue(vertex); }

inline int residualSubdivisions(const WorkspaceGrid& grid) noexcept {
  const int cells = grid.resolution().maxCoeff() - 1;
  return std::clamp((kResidualMaxSamples - 1) / cells, 1, kResidualSubdivisions);
}

inline Eigen::Vector3i residualSamplesPerAxis(const WorkspaceGrid& grid) noexcept {
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

// An actor of `data` in one colour. (scene_content.cpp)
vtkSmartPointer<vtkActor> makeActor(vtkPolyData* data, const Rgb& color);

// A scalar bar of `table` in the right-hand column (vertical) or under the scene. (scene.cpp)
void addScalarBar(vtkRenderer* renderer, vtkLookupTable* table, const std::string& title,
                  const Palette& palette, int font_px, bool horizontal, double scene_right);

// The steps that draw the map's content, in the order renderScene calls them.
// (scene_content.cpp)
void addLattice(SceneBuild& scene);
void chooseArrowScale(SceneBuild& scene);
void addVertexArrows(SceneBuild& scene);
void addOffVertexMeasurements(SceneBuild& scene);
void addVertexMarkers(SceneBuild& scene);
void addWorkspace(SceneBuild& scene);
void addDevicePosition(SceneBuild& scene);
void addResidualField(SceneBuild& scene);

}  // namespace autograv::viz::detail
