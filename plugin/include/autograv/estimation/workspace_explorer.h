#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "autograv/device/device_specifications.h"
#include "autograv/device/servo_sample.h"
#include "autograv/estimation/estimation_parameters.h"
#include "autograv/map/explored_workspace.h"

namespace autograv {

/// Finds how far the end-effector can go, from nothing but what a driver gives (positions,
/// velocities and the forces sent), before the grid run: a gentle automatic probe. From the
/// initialization's centre it pushes a soft impedance target outward along evenly spread
/// directions at a walking pace; where the end-effector stops following while the probe force
/// grows, a stop holds it (StopContact below), and the probe backs off at once, records the
/// distance and goes on with the next direction. The probe force beyond the gravity estimate is
/// capped far below the continuous rating, and the gravity estimate itself follows the
/// end-effector (a slow integral of the probe effort), so that nothing but a stop ever builds up
/// force. After these radial probes, a second set of directions refines the boundary between
/// their stops: each of those probes starts just inside the boundary the first ones found, so it
/// covers a centimetre or so instead of half the reach. Stepped once per servo tick; never blocks.
/// Its state lives in a private Impl that the constructor allocates whole.
class WorkspaceExplorer {
 public:
  /// What the explorer is doing.
  enum class Status : std::uint8_t {
    kIdle,         ///< start() not called yet.
    kTransfer,     ///< Moving to where the next probe starts.
    kProbing,      ///< Pushing outward along the current direction.
    kBackingOff,   ///< A stop was found; moving back inside.
    kFinished,     ///< Every direction probed; holding the last point (read workspace()).
    kAborted,      ///< abort() was called; holding position.
    kDeviceFault,  ///< The device stopped answering; sending zero force.
  };

  /// How the explorer probes.
  struct Options {
    /// Probe directions, spread evenly over the sphere, each probed outward from near the centre.
    int directions = 26;
    /// Boundary probes after the radial ones: up to this many directions of a second even spread
    /// (boundary_candidates of them, or this many if more, less those within kSameDirection_rad
    /// of a radial direction), each probed from boundary_clearance_m inside the boundary the
    /// radial stops make along it. They let the boundary follow the caps and edges between the
    /// radial stops, which the flat triangles between those stops cut off (on sim:omni 90 % of
    /// the field's worst 1 % lay more than 2 mm beyond the 26 radial stops' boundary). When the
    /// spread holds more candidates than this, the ones where the boundary bulges most beyond
    /// the radial triangles are probed (boundary_bulge_m). Each costs about 1 s of device time.
    /// 40 take sim:omni's field p99 from 2.9-3.0 % to 2.5-2.8 % and its maximum from 13 % to
    /// 8.2-8.4 % for 48 s (design notes, "Boundary probes"); on sim:falcon they sink into the
    /// stops' rubber, so its points end against them. 0, the default until the probes stop where
    /// the end-effector first meets a stop, probes the radial directions only.
    int boundary_directions = 0;
    /// Size of the even spread the boundary probes are chosen from (at least
    /// boundary_directions are always taken).
    int boundary_candidates = 100;
    /// Where the boundary probes go: a smooth surface through the three radial stops around a
    /// candidate, each stop's normal taken from the triangles around it (Phong tessellation),
    /// says how far the real boundary may bulge beyond their flat triangle there. A face whose
    /// stops all lie on it bulges not at all and a curved cap (an arm's reach) does, so the
    /// device's own stops decide where the time goes: the boundary_directions candidates that bulge
    /// most are probed, and none that bulges less than this. Unit: [m]
    double boundary_bulge_m = 0.0015;
    /// How far inside the first directions' boundary a boundary probe starts (at least
    /// start_fraction of that boundary's distance from the centre): it is reached by a transfer,
    /// whose force is capped as the probe's is. Unit: [m]
    double boundary_clearance_m = 0.010;
    /// Speed of the probe target along a direction: faster ends short of a stop where high
    /// friction sticks (its damping alone then nears contact_force_n) and sinks deeper into the
    /// soft arm limits of a parallel arm (sim:falcon's median reach error reaches 2 mm at
    /// 0.08 m/s). Unit: [m/s]
    double probe_speed_m_per_s = 0.06;
    /// Each probe starts this fraction of the previous direction's reach out from the centre.
    double start_fraction = 0.6;
    /// A direction with no stop within this distance of the centre ends there; 0 picks
    /// kReachFactor times the workspace radius the driver specifies (a cube's corner from its
    /// inscribed sphere). Unit: [m]
    double max_reach_m = 0.0;
    /// How far the probe backs off from a stop. Unit: [m]
    double back_off_m = 0.004;
    /// Probe effort (beyond the gravity estimate) that, with the end-effector no longer
    /// following, means a stop; 0 picks kContactForceFraction of the maximum force (the dither's
    /// amplitude, above the breakaway force of every device we model), at most half the
    /// continuous rating. Unit: [N]
    double contact_force_n = 0.0;
    /// Lag of the end-effector behind the target at which the probe effort reaches
    /// contact_force_n: sets the probe's stiffness. Unit: [m]
    double contact_lag_m = 0.002;
    /// Peak acceleration of the transfer moves, which start where the probe backed off and end
    /// well inside (start_fraction of the next reach): 0.15 N of inertia on sim:omega's 0.1 kg,
    /// a fifth of its headroom to the continuous rating. Unit: [m/s^2]
    double max_move_acceleration_m_per_s2 = 1.5;
    /// The probe directions themselves, in the order probed, used instead of `directions`' even
    /// spread when not empty (at least 6; normalized): a check of a known workspace probes along
    /// the directions it was explored in, where its boundary is exact.
    std::vector<Eigen::Vector3d> radial_directions;
  };

  /// A boundary direction closer than this to one of the first directions is not probed: it would
  /// repeat a stop already known. Unit: [rad]
  static constexpr double kSameDirection_rad = 0.15;
  /// Default contact force as a fraction of the maximum force.
  static constexpr double kContactForceFraction = 0.09;
  /// Default reach limit in specified workspace radii.
  static constexpr double kReachFactor = 1.75;
  /// The end-effector follows no more than this fraction of the probe's speed at a stop.
  static constexpr double kStalledSpeedFraction = 0.3;
  /// How long the contact condition must hold: short against the 100 ms in which a stop must be
  /// recognised, long against encoder noise. Unit: [s]
  static constexpr double kContactConfirm_s = 0.015;

  /// Allocates everything the run needs; reads the force limit, the continuous rating
  /// (continuousForceRating_n) and the workspace radius from `specifications`.
  /// Throws autograv::Error on bad options or specifications. Not real-time safe.
  WorkspaceExplorer(const EstimationParameters& parameters,
                    const DeviceSpecifications& specifications, const Options& options);
  /// With the default options.
  WorkspaceExplorer(const EstimationParameters& parameters,
                    const DeviceSpecifications& specifications)
      : WorkspaceExplorer(parameters, specifications, Options()) {}
  ~WorkspaceExplorer();
  /// Moves the exploration; the moved-from explorer may only be destroyed or assigned to.
  WorkspaceExplorer(WorkspaceExplorer&&) noexcept;
  /// Moves the exploration; the moved-from explorer may only be destroyed or assigned to.
  WorkspaceExplorer& operator=(WorkspaceExplorer&&) noexcept;

  /// Starts from the end-effector at rest at `center_m` (the initialization's X0), held with the
  /// estimate `gravity_n` (G_hat_0). Real-time safe.
  void start(const Eigen::Vector3d& center_m, const Eigen::Vector3d& gravity_n) noexcept;
  /// One servo tick: writes the force to send. Real-time safe.
  Status step(const ServoSample& sample, Eigen::Vector3d& force_n) noexcept;
  /// Stops probing; keeps holding the end-effector where it is. Real-time safe.
  void abort() noexcept;

  /// What the explorer is doing now. Real-time safe.
  Status state() const noexcept;
  /// Directions in all: the radial ones first, then the boundary candidates, of which only
  /// Options::boundary_directions are probed (skippedCount). Real-time safe.
  int directionCount() const noexcept;
  /// Every direction in the order probed (unit vectors), reach_m() in the same order.
  /// Real-time safe.
  const std::vector<Eigen::Vector3d>& directions() const noexcept;
  /// How many of directions() are probed from near the centre (Options::directions); the rest
  /// start near the boundary those found. Real-time safe.
  int radialDirectionCount() const noexcept;
  /// Directions finished so far, probed or skipped. Real-time safe.
  int probedCount() const noexcept;
  /// Boundary directions left out so far: not among those where the boundary bulges most
  /// (Options::boundary_directions, boundary_bulge_m), or a probe that static friction held at
  /// its start. Their reach_m() stays 0. Real-time safe.
  int skippedCount() const noexcept;
  /// Servo time since start(). Real-time safe. Unit: [s]
  double elapsed_s() const noexcept;
  /// The gravity estimate carried by the probe now (it follows the end-effector). Real-time
  /// safe. Unit: [N]
  const Eigen::Vector3d& gravity_n() const noexcept;
  /// Where the probe target is now. Real-time safe. Unit: [m]
  const Eigen::Vector3d& target_m() const noexcept;
  /// The probe force cap beyond the gravity estimate. Real-time safe. Unit: [N]
  double probeForceCap_n() const noexcept;
  /// The probe effort that, with the end-effector not following, means a stop. Real-time safe.
  /// Unit: [N]
  double contactForce_n() const noexcept;
  /// Reach found so far along each direction (0 for those not probed, yet or at all).
  /// Real-time safe.
  /// Unit: [m]
  const std::vector<double>& reach_m() const noexcept;
  /// Longest time from the end-effector's last forward progress to a recognised stop.
  /// Real-time safe. Unit: [s]
  double longestRecognition_s() const noexcept;
  /// Directions along which no stop was met within max_reach_m. Real-time safe.
  int openDirections() const noexcept;

  /// The explored workspace; valid once state() is kFinished. Throws autograv::Error before.
  /// Not real-time safe.
  ExploredWorkspace workspace() const;

 private:
  struct Impl;  // the exploration's state (plugin/src/core/estimation/workspace_explorer.cpp)
  std::unique_ptr<Impl> impl_;
};

const char* toString(WorkspaceExplorer::Status status) noexcept;

/// The workspace that probes along `directions` from `center_m` found, `reach_m[i]` along
/// `directions[i]`, leaving out the directions with no reach (0: not probed, such as a boundary
/// direction the explorer skipped). Throws autograv::Error for a count mismatch or fewer than 6
/// probed directions. Not real-time safe. Unit: [m]
ExploredWorkspace exploredWorkspaceOf(const Eigen::Vector3d& center_m,
                                      const std::vector<Eigen::Vector3d>& directions,
                                      const std::vector<double>& reach_m);

/// Closest a stop may be to where the manual initialization settled: nearer, the end-effector
/// may have rested on it, and eq. (7)'s G_hat_0 then carries the stop's reaction. Judged from the
/// explored workspace (driver data: where probes met a stop), so it holds on any device. Unit: [m]
inline constexpr double kInitializationClearance_m = 0.005;

/// Empty when `settled_m`, where the initialization settled, lies at least
/// kInitializationClearance_m inside `workspace` (ExploredWorkspace::depth_m); otherwise what to
/// tell the user. Not real-time safe. Unit: [m]
std::string initializationClearanceProblem(const ExploredWorkspace& workspace,
                                           const Eigen::Vector3d& settled_m);

}  // namespace autograv
