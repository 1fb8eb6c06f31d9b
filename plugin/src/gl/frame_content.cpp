// The 3D content of one frame: map arrows, value markers, explored workspace, lattice, hand,
// cursor and force, as lists of lines and mesh instances.
#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "autograv/image/arrow_length.h"
#include "autograv/map/value_kind.h"
#include "gl/frame_lists.h"
#include "gl/meshes.h"

namespace autograv::gl::detail {

namespace {

// The colour of arrows coloured by the colour map (the shader takes the colour-map value).
constexpr Rgba kColormapArrow{0, 0, 0, 1};

void pushLine(std::vector<LineVertex>& lines, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
              Rgba ca, Rgba cb) {
  lines.push_back(
      {{static_cast<float>(a.x()), static_cast<float>(a.y()), static_cast<float>(a.z())},
       {ca.r, ca.g, ca.b, ca.a}});
  lines.push_back(
      {{static_cast<float>(b.x()), static_cast<float>(b.y()), static_cast<float>(b.z())},
       {cb.r, cb.g, cb.b, cb.a}});
}

MeshInstance makeInstance(const Eigen::Vector3d& origin, const Eigen::Vector3d& vector,
                          double radius, Rgba color, float colormap_value) {
  MeshInstance instance{};
  const double length = vector.norm();
  const Eigen::Vector3d direction =
      length > 0.0 ? Eigen::Vector3d(vector / length) : Eigen::Vector3d::UnitZ();
  const double head = std::min(static_cast<double>(kArrowHeadLength) * radius, 0.5 * length);
  for (int i = 0; i < 3; ++i) {
    instance.origin[i] = static_cast<float>(origin[i]);
    instance.direction[i] = static_cast<float>(direction[i]);
  }
  instance.direction[3] = static_cast<float>(length);
  instance.size[0] = static_cast<float>(radius);
  instance.size[1] = static_cast<float>(head);
  instance.color[0] = color.r;
  instance.color[1] = color.g;
  instance.color[2] = color.b;
  instance.color[3] = colormap_value;
  return instance;
}

MeshInstance makeBead(const Eigen::Vector3d& center, double radius, Rgba color) {
  return makeInstance(center, Eigen::Vector3d::Zero(), radius, color, 0.0f);
}

// The boundary model of an explored workspace (what the measurement plan keeps inside), drawn as
// meridians and parallels: a wire hull through the probes' stops.
void appendWorkspaceWire(const ExploredWorkspace& workspace, std::vector<LineVertex>& lines) {
  constexpr int kMeridians = 16;
  constexpr int kParallels = 7;
  constexpr int kSegments = 48;
  constexpr double kPi = 3.14159265358979323846;
  const auto boundary = [&](double polar, double azimuth) {
    const Eigen::Vector3d u(std::sin(polar) * std::cos(azimuth),
                            std::sin(polar) * std::sin(azimuth), std::cos(polar));
    return Eigen::Vector3d(workspace.center_m() + u * workspace.boundaryDistance_m(u));
  };
  for (int m = 0; m < kMeridians; ++m) {
    const double azimuth = 2.0 * kPi * m / kMeridians;
    Eigen::Vector3d previous = boundary(0.0, azimuth);
    for (int k = 1; k <= kSegments / 2; ++k) {
      const Eigen::Vector3d next = boundary(kPi * k / (kSegments / 2), azimuth);
      pushLine(lines, previous, next, kWorkspaceWireColor, kWorkspaceWireColor);
      previous = next;
    }
  }
  for (int p = 1; p <= kParallels; ++p) {
    const double polar = kPi * p / (kParallels + 1);
    Eigen::Vector3d previous = boundary(polar, 0.0);
    for (int k = 1; k <= kSegments; ++k) {
      const Eigen::Vector3d next = boundary(polar, 2.0 * kPi * k / kSegments);
      pushLine(lines, previous, next, kWorkspaceWireColor, kWorkspaceWireColor);
      previous = next;
    }
  }
}

// One arrow per vertex, coloured by where its |G| lies in the map's range; thin where the value
// was not measured at the vertex (beyond the stops, extrapolated from the measurements), so that
// it never looks like a measurement.
void addVertexArrows(const Scene& scene, const FrameMeasures& frame, FrameLists& lists) {
  if (!scene.show_arrows) return;
  const GravityMap& map = *frame.map;
  const WorkspaceGrid& grid = map.grid();
  const double span = frame.max_magnitude_n - frame.min_magnitude_n;
  for (int i = 0; i < grid.vertexCount(); ++i) {
    const VertexEstimate& vertex = map.vertices()[static_cast<std::size_t>(i)];
    const Eigen::Vector3d& g = vertex.gravity_n;
    const double radius =
        (valueKind(vertex) == ValueKind::kAtVertex ? 0.035 : 0.015) * frame.cell_m;
    const double value = span > 1e-12 ? (g.norm() - frame.min_magnitude_n) / span : 0.5;
    lists.colormap_arrows.push_back(makeInstance(grid.vertexPosition(i),
                                                 g * frame.map_arrow_m_per_n, radius,
                                                 kColormapArrow, static_cast<float>(value)));
  }
}

// Vertices out of reach, solved from the measurements: a purple bead, so that a solved value is
// never mistaken for a measured one.
void addSolvedVertices(const FrameMeasures& frame, FrameLists& lists) {
  const GravityMap& map = *frame.map;
  for (int i = 0; i < map.grid().vertexCount(); ++i) {
    if (valueKind(map.vertices()[static_cast<std::size_t>(i)]) != ValueKind::kSolved) continue;
    lists.spheres.push_back(
        makeBead(map.grid().vertexPosition(i), 0.06 * frame.cell_m, kSolvedVertexColor));
  }
}

// Points measured inside the stops for vertices beyond them: a pink bead with the measured arrow
// (thinner than the vertex arrows) and a line to the vertex.
void addOffVertexMeasurements(const Scene& scene, const FrameMeasures& frame, FrameLists& lists) {
  if (!scene.show_measurements) return;
  const GravityMap& map = *frame.map;
  const double span = frame.max_magnitude_n - frame.min_magnitude_n;
  for (int i = 0; i < map.grid().vertexCount(); ++i) {
    const VertexEstimate& vertex = map.vertices()[static_cast<std::size_t>(i)];
    if (valueKind(vertex) != ValueKind::kOffVertex) continue;
    lists.spheres.push_back(makeBead(vertex.measured_at_m, 0.05 * frame.cell_m, kOffVertexColor));
    pushLine(lists.lines, vertex.measured_at_m, map.grid().vertexPosition(i), kOffVertexLinkColor,
             kOffVertexLinkColor);
    if (!scene.show_arrows) continue;
    const Eigen::Vector3d& g = vertex.measured_gravity_n;
    const double value =
        span > 1e-12 ? std::clamp((g.norm() - frame.min_magnitude_n) / span, 0.0, 1.0) : 0.5;
    lists.colormap_arrows.push_back(makeInstance(vertex.measured_at_m, g * frame.map_arrow_m_per_n,
                                                 0.025 * frame.cell_m, kColormapArrow,
                                                 static_cast<float>(value)));
  }
}

// The explored workspace: its wire hull and a bead at each probe's stop.
void addExploredWorkspace(const Scene& scene, const FrameMeasures& frame, FrameLists& lists) {
  const ExploredWorkspace& workspace = frame.map->metadata().workspace;
  if (!scene.show_workspace || workspace.empty()) return;
  if (lists.wire_map != scene.map) {
    lists.wire_lines.clear();
    appendWorkspaceWire(workspace, lists.wire_lines);
    lists.wire_map = scene.map;
  }
  lists.lines.insert(lists.lines.end(), lists.wire_lines.begin(), lists.wire_lines.end());
  for (std::size_t i = 0; i < workspace.directions().size(); ++i) {
    const Eigen::Vector3d stop =
        workspace.center_m() + workspace.directions()[i] * workspace.radii_m()[i];
    lists.spheres.push_back(makeBead(stop, 0.035 * frame.cell_m, kWorkspaceStopColor));
  }
}

// The grid's lattice, its outer edges brighter, and an axis triad at its minimum corner.
void addLattice(const FrameMeasures& frame, FrameLists& lists) {
  const WorkspaceGrid& grid = *frame.lattice;
  const Eigen::Vector3i& n = grid.resolution();
  const Eigen::Vector3d spacing_m = grid.spacing_m();
  const Eigen::Vector3d lo = grid.minCorner_m();
  const Eigen::Vector3d hi = grid.maxCorner_m();
  for (int axis = 0; axis < 3; ++axis) {
    const int a1 = (axis + 1) % 3;
    const int a2 = (axis + 2) % 3;
    for (int j = 0; j < n[a1]; ++j) {
      for (int k = 0; k < n[a2]; ++k) {
        Eigen::Vector3d from = lo;
        from[a1] += j * spacing_m[a1];
        from[a2] += k * spacing_m[a2];
        Eigen::Vector3d to = from;
        to[axis] = hi[axis];
        const bool edge = (j == 0 || j == n[a1] - 1) && (k == 0 || k == n[a2] - 1);
        const Rgba color = edge ? kEdgeColor : kLatticeColor;
        pushLine(lists.lines, from, to, color, color);
      }
    }
  }
  // Axis triad: x red, y green, z blue.
  const double length = 0.6 * frame.cell_m;
  const Rgba colors[] = {{1.0f, 0.3f, 0.3f, 1}, {0.3f, 1.0f, 0.3f, 1}, {0.4f, 0.5f, 1.0f, 1}};
  for (int axis = 0; axis < 3; ++axis) {
    pushLine(lists.lines, lo, lo + length * Eigen::Vector3d::Unit(axis), colors[axis],
             colors[axis]);
  }
}

// The end-effector's trail (older segments fade out), the hand's target with its grip spring,
// the cursor and the force being sent.
void addHandAndCursor(const Scene& scene, const FrameMeasures& frame, FrameLists& lists) {
  const std::size_t trail_size = scene.trail_m.size();
  for (std::size_t i = 1; i < trail_size; ++i) {
    Rgba older = kTrailColor;
    Rgba newer = kTrailColor;
    older.a *= static_cast<float>(i - 1) / static_cast<float>(trail_size - 1);
    newer.a *= static_cast<float>(i) / static_cast<float>(trail_size - 1);
    pushLine(lists.lines, scene.trail_m[i - 1], scene.trail_m[i], older, newer);
  }
  if (scene.show_hand_target) {
    lists.spheres.push_back(makeBead(scene.hand_target_m, 0.07 * frame.cell_m, kSpringColor));
    if (scene.show_cursor) {
      pushLine(lists.lines, scene.hand_target_m, scene.cursor_m, kSpringColor, kSpringColor);
    }
  }
  if (!scene.show_cursor) return;
  lists.spheres.push_back(
      makeBead(scene.cursor_m, 0.22 * frame.cell_m, scene.cursor_held ? kCursorHeld : kCursorFree));
  if (scene.show_force && scene.force_n.norm() > 1e-9) {
    lists.plain_arrows.push_back(makeInstance(scene.cursor_m,
                                              scene.force_n * frame.force_arrow_m_per_n,
                                              0.05 * frame.cell_m, kForceColor, 0.0f));
  }
}

}  // namespace

FrameMeasures measureFrame(const Scene& scene) {
  FrameMeasures frame;
  frame.map = scene.map.get();
  frame.lattice = frame.map != nullptr ? &frame.map->grid() : scene.grid ? &*scene.grid : nullptr;
  frame.cell_m = 0.1 * scene.camera.distance_m;
  if (frame.lattice != nullptr) frame.cell_m = frame.lattice->spacing_m().minCoeff();
  double arrow_m_per_n = scene.arrow_scale_m_per_n;
  if (frame.map != nullptr) {
    frame.min_magnitude_n = std::numeric_limits<double>::infinity();
    for (const VertexEstimate& vertex : frame.map->vertices()) {
      const double magnitude = vertex.gravity_n.norm();
      frame.min_magnitude_n = std::min(frame.min_magnitude_n, magnitude);
      frame.max_magnitude_n = std::max(frame.max_magnitude_n, magnitude);
      const ValueKind kind = valueKind(vertex);
      frame.counts.at_vertex += kind == ValueKind::kAtVertex ? 1 : 0;
      frame.counts.off_vertex += kind == ValueKind::kOffVertex ? 1 : 0;
      frame.counts.solved += kind == ValueKind::kSolved ? 1 : 0;
    }
    frame.counts.workspace_stops =
        static_cast<int>(frame.map->metadata().workspace.directions().size());
    if (arrow_m_per_n <= 0.0) {
      arrow_m_per_n = arrowLengthPerNewton(frame.cell_m, frame.max_magnitude_n);
    }
  }
  frame.map_arrow_m_per_n = arrow_m_per_n;
  // Without a map (or with one of no force), the force is drawn as if 1 N were the longest arrow.
  frame.force_arrow_m_per_n =
      arrow_m_per_n <= 0.0 ? arrowLengthPerNewton(frame.cell_m, 1.0) : arrow_m_per_n;
  return frame;
}

void clearFrame(FrameLists& lists) {
  lists.colormap_arrows.clear();
  lists.plain_arrows.clear();
  lists.spheres.clear();
  lists.lines.clear();
  lists.overlay.clear();
}

void addSceneContent(const Scene& scene, const FrameMeasures& frame, FrameLists& lists) {
  if (frame.map != nullptr) {
    addVertexArrows(scene, frame, lists);
    addSolvedVertices(frame, lists);
    addOffVertexMeasurements(scene, frame, lists);
    addExploredWorkspace(scene, frame, lists);
  }
  if (frame.lattice != nullptr && scene.show_grid) addLattice(frame, lists);
  addHandAndCursor(scene, frame, lists);
}

}  // namespace autograv::gl::detail
