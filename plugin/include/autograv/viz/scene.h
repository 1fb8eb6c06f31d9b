#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "autograv/map/gravity_map.h"
#include "autograv/viz/common.h"
#include "autograv/viz/image.h"

namespace autograv::viz {

/// Camera presets, in CHAI3D's frame (x toward the operator, y right, z up).
enum class CameraView : std::uint8_t {
  kIso,    ///< From the operator's front-right, above.
  kFront,  ///< From the operator's side, looking along -x, z up.
  kTop,    ///< From above, looking along -z, the operator at the bottom of the picture.
};

/// "iso", "front", "top". Real-time safe.
const char* toString(CameraView view) noexcept;
/// Inverse of toString; false for an unknown name. Real-time safe.
bool parseCameraView(const std::string& name, CameraView& view) noexcept;

/// What the scene shows and how.
struct SceneOptions {
  /// Size of the picture. Unit: [px]. Text is sized for legibility at 1280x960.
  int width_px = 1280;
  /// Height of the picture. Unit: [px]
  int height_px = 960;
  /// Preset camera direction.
  CameraView view = CameraView::kIso;
  /// Turns the preset camera about the vertical axis through the scene centre. Unit: [deg]
  double camera_azimuth_deg = 0.0;
  /// Raises the preset camera (clamped to straight above or below). Unit: [deg]
  double camera_elevation_deg = 0.0;
  /// White (print) or dark (screen) background.
  Background background = Background::kWhite;
  /// Colour map of the gravity magnitude on the arrows.
  ColorMap color_map = ColorMap::kViridis;
  /// Draw the workspace explored before the calibration (MapMetadata::workspace) as a translucent
  /// surface through the probes' stops, in place of the sphere or box below. Maps made without
  /// an exploration have none and show the sphere or box.
  bool show_explored_workspace = true;
  /// Radius of the device's reachable workspace, drawn as a translucent sphere around the grid
  /// centre (or workspace_center_m) when the map has no explored workspace; 0 draws the grid's
  /// box instead. Unit: [m]
  double workspace_radius_m = 0.0;
  /// Centre of that sphere; unset = the grid's centre. Unit: [m]
  std::optional<Eigen::Vector3d> workspace_center_m;
  /// Current end-effector position, drawn as a small sphere when set. Unit: [m]
  std::optional<Eigen::Vector3d> device_position_m;
  /// When set, the residual |G_hat(X) - G_true(X)| of the interpolated map is drawn as a colour
  /// field on the faces of the grid's box, with its own scalar bar. Unit: [N]
  GroundTruth ground_truth;
  /// Where the ground truth exists: the residual is left blank ("no data") elsewhere, e.g. at
  /// the corners of a box fitted to the workspace. Unset = everywhere in the grid.
  Reachability reachable;
  /// Overlay title; empty makes one from the map (device model, grid, converged vertices).
  std::string title;
};

/// Numbers the scene shows, for captions, reports and tests.
struct SceneSummary {
  /// Vertices of the grid.
  int vertices = 0;
  /// Vertices that converged.
  int converged = 0;
  int failed = 0;  ///< Visited, not converged and not solved (iteration cap, no steady state...).
  int not_visited = 0;  ///< Outcome kPending.
  /// Converged where the vertex is: its value is that measurement.
  int measured_at_vertex = 0;
  /// Beyond the explored workspace, measured at a point just inside the stops
  /// (VertexEstimate::measuredOffVertex); the vertex's value is solved from every measurement.
  int measured_off_vertex = 0;
  /// Not measured (out of reach): the value is solved from the measurements around it.
  int solved = 0;
  /// Values not measured at the vertex itself (provenance kFilled): measured_off_vertex + solved.
  int filled = 0;
  /// Probe directions of the explored workspace; 0 when the map has none.
  int workspace_directions = 0;
  double min_gravity_n = 0.0;  ///< Smallest |G_hat| over vertices with an estimate. Unit: [N]
  double max_gravity_n = 0.0;  ///< Largest |G_hat|. Unit: [N]
  /// Largest |G_hat(X) - G_true(X)| over the sampled residual field; 0 without ground truth.
  /// Unit: [N]
  double max_residual_n = 0.0;
};

/// Counts and ranges of `map` as the scene shows them (residual sampled like the scene does).
/// Not real-time safe.
SceneSummary summarizeScene(const GravityMap& map, const GroundTruth& ground_truth = {},
                            const Reachability& reachable = {});

/// Renders the workspace (the explored one when the map has it), the grid lattice, one arrow per
/// vertex value (length and colour by magnitude, scalar bar in N), axes in mm, the points
/// measured off their vertex (inside the stops) with their measured arrows and a line to their
/// vertex, marked solved, failed and unvisited vertices with a legend that names each kind, and,
/// optionally, the device position and the residual against ground truth. Renders offscreen;
/// needs an X display (see requireDisplay). Throws autograv::Error on a bad size (16..8192 px),
/// a non-finite option or when no display can be opened. Not real-time safe.
RgbImage renderScene(const GravityMap& map, const SceneOptions& options = {});

}  // namespace autograv::viz
