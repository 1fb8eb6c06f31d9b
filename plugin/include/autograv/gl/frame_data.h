#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "autograv/gl/camera.h"
#include "autograv/map/gravity_map.h"

namespace autograv::gl {

/// Everything one frame shows, in the device frame (SI units). Plain data: the application fills
/// it, the Renderer draws it.
struct Scene {
  /// The gravity map drawn as a grid lattice with one arrow per vertex; null draws neither.
  std::shared_ptr<const GravityMap> map;
  /// Lattice drawn when there is no map (e.g. the grid a calibration would visit).
  std::optional<WorkspaceGrid> grid;
  bool show_grid = true;    ///< Draw the lattice of the map's grid (or of `grid`).
  bool show_arrows = true;  ///< Draw the map's arrows (coloured by |G|).
  /// Draw the map's explored workspace (MapMetadata::workspace, when it has one) as a wire hull
  /// through the probes' stops, with a dot at each stop.
  bool show_workspace = true;
  /// Draw the points measured off their vertex, inside the stops (VertexEstimate::measured_at_m):
  /// a bead with the measured arrow and a thin line to the vertex their value went into.
  bool show_measurements = true;
  /// Arrow length per newton, shared by the map arrows and the force vector; 0 picks the one of
  /// every picture of a map (arrowLengthPerNewton of the grid spacing and the largest |G|, or of
  /// 1 N without a map). Unit: [m/N]
  double arrow_scale_m_per_n = 0.0;

  bool show_cursor = false;                            ///< Draw the end-effector.
  Eigen::Vector3d cursor_m = Eigen::Vector3d::Zero();  ///< End-effector position. Unit: [m]
  bool cursor_held = false;  ///< The hand holds the end-effector (drawn in another colour).
  /// Recent end-effector positions, oldest first, drawn as a fading line. Unit: [m]
  std::vector<Eigen::Vector3d> trail_m;

  bool show_hand_target = false;  ///< Draw the hand's target and the grip spring to the cursor.
  Eigen::Vector3d hand_target_m = Eigen::Vector3d::Zero();  ///< Unit: [m]

  bool show_force = false;  ///< Draw the force being sent to the device, from the cursor.
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();  ///< Unit: [N]

  /// Lines of text drawn top-left (upper case is drawn as is; lower case is drawn upper case).
  std::vector<std::string> readout;
  /// One line drawn at the bottom (key help, messages).
  std::string status_line;
  /// Draw the |G| colour bar under the readout when a map is shown, and under it a key of the
  /// kinds of value (measured at the vertex, inside the stops, solved) and the workspace.
  bool show_legend = true;

  /// Where the scene is seen from.
  OrbitCamera camera;
};

}  // namespace autograv::gl
