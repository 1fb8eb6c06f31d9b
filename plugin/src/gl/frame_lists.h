#pragma once

// Private to autograv::gl: what one frame of the Renderer draws, built on the CPU from a Scene
// (frame_content.cpp: the 3D content, frame_overlay.cpp: the text and legend) and then uploaded
// and drawn by renderer.cpp.

#include <memory>
#include <vector>

#include <Eigen/Core>

#include "autograv/gl/frame_data.h"
#include "autograv/map/gravity_map.h"

namespace autograv::gl::detail {

/// Line vertex as lines.vert reads it.
struct LineVertex {
  float position[3];
  float color[4];
};

/// Mesh instance as mesh.vert reads it.
struct MeshInstance {
  float origin[3];
  float direction[4];  // unit direction, length [m]
  float size[2];       // radius [m], head length [m]
  float color[4];      // rgb, colour-map value
};

/// Overlay quad as overlay.vert reads it.
struct OverlayQuad {
  float rect[4];
  float color[4];
  float kind;
};

/// A colour with its opacity, 0..1 each.
struct Rgba {
  float r, g, b, a;
};

inline constexpr Rgba kLatticeColor{0.52f, 0.58f, 0.68f, 0.30f};
inline constexpr Rgba kEdgeColor{0.70f, 0.76f, 0.86f, 0.75f};
inline constexpr Rgba kTrailColor{1.00f, 0.86f, 0.35f, 0.95f};
inline constexpr Rgba kSpringColor{0.55f, 0.95f, 0.55f, 0.90f};
inline constexpr Rgba kSolvedVertexColor{0.78f, 0.45f, 0.98f, 1.0f};
inline constexpr Rgba kOffVertexColor{1.00f, 0.55f, 0.80f, 1.0f};
inline constexpr Rgba kOffVertexLinkColor{1.00f, 0.55f, 0.80f, 0.70f};
inline constexpr Rgba kWorkspaceWireColor{0.45f, 0.65f, 1.00f, 0.40f};
inline constexpr Rgba kWorkspaceStopColor{0.45f, 0.65f, 1.00f, 1.0f};
inline constexpr Rgba kCursorFree{1.00f, 0.84f, 0.25f, 1.0f};
inline constexpr Rgba kCursorHeld{0.40f, 0.95f, 0.45f, 1.0f};
inline constexpr Rgba kForceColor{0.95f, 0.35f, 0.95f, 1.0f};
inline constexpr Rgba kTextColor{0.92f, 0.94f, 0.97f, 1.0f};
inline constexpr Rgba kPanelColor{0.0f, 0.0f, 0.0f, 0.55f};

/// The lists one frame draws, in the order they are drawn. Kept between frames so that a steady
/// scene does not reallocate.
struct FrameLists {
  /// Map arrows, coloured by |G| through the colour map.
  std::vector<MeshInstance> colormap_arrows;
  /// Arrows in their own colour (the force being sent).
  std::vector<MeshInstance> plain_arrows;
  /// Beads: solved vertices, points measured off their vertex, workspace stops, hand, cursor.
  std::vector<MeshInstance> spheres;
  /// Translucent lines, drawn after the opaque meshes.
  std::vector<LineVertex> lines;
  /// Text and panels over everything.
  std::vector<OverlayQuad> overlay;

  /// The map whose workspace wire `wire_lines` holds: the boundary model costs a search per
  /// point, too much to redo every frame.
  std::shared_ptr<const GravityMap> wire_map;
  /// The workspace wire of `wire_map`.
  std::vector<LineVertex> wire_lines;
};

/// How many values of each kind the shown map holds, for the legend's key.
struct ValueCounts {
  int at_vertex = 0;
  int off_vertex = 0;
  int solved = 0;
  /// Directions in which the map's explored workspace was probed.
  int workspace_stops = 0;
};

/// The sizes every step of one frame draws with.
struct FrameMeasures {
  /// The map shown, or null.
  const GravityMap* map = nullptr;
  /// The grid drawn as a lattice: the map's, else the Scene's, else null.
  const WorkspaceGrid* lattice = nullptr;
  /// Sizes follow the grid's spacing when there is a grid, else the camera distance. Unit: [m]
  double cell_m = 0.0;
  /// The kinds of value of the map.
  ValueCounts counts;
  /// Smallest |G| of the map's vertices (0 without a map). Unit: [N]
  double min_magnitude_n = 0.0;
  /// Largest |G| of the map's vertices (0 without a map). Unit: [N]
  double max_magnitude_n = 0.0;
  /// Length per newton of the map's arrows. Unit: [m/N]
  double map_arrow_m_per_n = 0.0;
  /// Length per newton of the force arrow: the map's, else that of 1 N as the longest arrow.
  /// Unit: [m/N]
  double force_arrow_m_per_n = 0.0;
};

/// Sizes, arrow lengths and counts of `scene` (frame_content.cpp).
FrameMeasures measureFrame(const Scene& scene);

/// Empties the lists of the last frame, keeping their memory (frame_content.cpp).
void clearFrame(FrameLists& lists);

/// Adds the 3D content of `scene`: map arrows, value markers, explored workspace, lattice, hand,
/// cursor and force (frame_content.cpp).
void addSceneContent(const Scene& scene, const FrameMeasures& frame, FrameLists& lists);

/// Adds the overlay of `scene` over a `width_px` x `height_px` framebuffer: readout panel,
/// legend, status line and the axis letters next to the triad (frame_overlay.cpp).
void addOverlay(const Scene& scene, const FrameMeasures& frame,
                const Eigen::Matrix4d& view_projection, int width_px, int height_px,
                FrameLists& lists);

}  // namespace autograv::gl::detail
