#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "autograv/device/device_specifications.h"
#include "autograv/device/servo_sample.h"
#include "autograv/estimation/estimation_parameters.h"
#include "autograv/map/gravity_map.h"
#include "autograv/map/measurement_plan.h"
#include "autograv/map/workspace_grid.h"

namespace autograv {

/// The outer loop of the off-line autocalibration (paper Sections I and III, eqs. 9 and 13): visit
/// every grid vertex on a smooth path, run the inner loop (eqs. 10-12) there, carry the estimate on
/// to the next vertex. Stepped once per servo tick; never blocks. Failed vertices are marked and
/// skipped.
///
/// Its state lives in a private Impl that the constructor allocates whole (the inner loop at one
/// vertex, the moves, every vertex's history), so that nothing on the servo path allocates.
class AutoCalibrator {
 public:
  /// What step() did on this tick.
  enum class Status : std::uint8_t {
    kIdle,            ///< start() not called yet.
    kMoving,          ///< Travelling to the next vertex.
    kEstimating,      ///< Inner loop running at the current vertex.
    kVertexFinished,  ///< This tick finished a vertex (read lastFinishedVertex()).
    kPaused,          ///< Holding position until resume().
    kFinished,        ///< Every vertex to visit is done; holding the last one.
    kAborted,         ///< abort() was called; holding position.
    kDeviceFault,     ///< The device stopped answering; sending zero force.
  };

  /// How the device travels between vertices and where each vertex starts.
  struct Options {
    /// Peak acceleration of a move into a point next to the stops: a 50 mm move takes 0.62 s,
    /// and the gap it may leave for the PD, 3.2 mm with a mass three times the estimate, ends at
    /// the speed of a minimum-jerk path's last millimetres: a point kBoundaryMargin_m inside
    /// the boundary may touch a stop's rubber then, never strike it, and a hold that meets it is
    /// moved back (kStopRetreat_m). Unit: [m/s^2]
    double max_move_acceleration_m_per_s2 = 0.75;
    /// Peak acceleration of a move whose target lies far from the stops in the direction of
    /// travel. A move overshoots along its path: its acceleration grows with the room the
    /// explored workspace leaves beyond the target along the path (MeasurementPlan::workspace),
    /// from max_move_acceleration_m_per_s2 at kMoveRoom_m, so that the gap it may leave
    /// stays the same share of that room, up to this (from 6.7 mm of room on). Quicker moves
    /// leave more to settle: at 1.5 a desktop loop's settling took back most of what they saved.
    /// Unit: [m/s^2]
    double deep_move_acceleration_m_per_s2 = 1.25;
    /// Shortest move. Unit: [s]
    double min_move_duration_s = 0.25;
    /// Start each vertex from what the measurements so far predict for its point (an affine fit
    /// to the nearest converged ones: kFitMeasurements of them, at least kMinFitMeasurements, else
    /// the linear extrapolation of the two previous vertices on the same line) instead of
    /// eq. (9)'s plain copy; fewer and shorter iterations, same fixed point.
    bool extrapolate_initial_estimate = true;
    /// The device's continuous force rating (continuousForceRating_n), within which the
    /// automatic dither keeps G_hat plus its peaks; 0 takes kDefaultContinuousForceFraction of
    /// the maximum force. Unit: [N]
    double continuous_force_n = 0.0;
    /// Thermal time constant of the device's motors, over which thermalLoad() averages the heat
    /// of the forces sent: as GravityCompensatedDevice counts it (CompensationOptions). Unit: [s]
    double motor_time_constant_s = kDefaultMotorTimeConstant_s;
    /// Per vertex, the estimate to start its inner loop from (a prior map's value, when a unit is
    /// corrected from another's map); empty, or a non-finite entry, means the rule above.
    /// Unit: [N]
    std::vector<Eigen::Vector3d> initial_estimates_n;
  };

  /// The largest gap between hold target and end-effector that the moves leave for the PD to
  /// close, the `cell_m` of checkCalibrationPlan: the paper's worst case is a step of a whole cell
  /// (Sec. VI), but the moves here are minimum-jerk paths with their acceleration fed forward on
  /// the estimated mass, so the gap is what a mass kMassUncertainty times the estimate lags at
  /// the peak acceleration of the quickest move. Unit: [m]. Real-time safe.
  static double largestHoldStep_m(const EstimationParameters& parameters,
                                  const Options& options) noexcept {
    return kMassUncertainty *
           std::max(options.max_move_acceleration_m_per_s2,
                    options.deep_move_acceleration_m_per_s2) /
           parameters.beta_per_s2;
  }
  /// The room beyond a target up to which a move keeps max_move_acceleration_m_per_s2: the 4 mm
  /// the measurement points used to keep from the boundary, whatever kBoundaryMargin_m is now, so
  /// that points closer to the stops never get quicker moves. Unit: [m]
  static constexpr double kMoveRoom_m = 0.004;
  /// The room beyond a target from which a move takes the deep acceleration: 6.7 mm with the
  /// default Options. Real-time safe. Unit: [m]
  static double deepMoveRoom_m(const Options& options) noexcept {
    return kMoveRoom_m * std::max(1.0, options.deep_move_acceleration_m_per_s2 /
                                           options.max_move_acceleration_m_per_s2);
  }
  /// Peak acceleration of a move that leaves `clearance_m` between its target and the stops
  /// along its path (0: unknown, or next to a stop). Real-time safe. Units: [m], [m/s^2]
  static double moveAcceleration_m_per_s2(const Options& options, double clearance_m) noexcept {
    return std::clamp(
        options.max_move_acceleration_m_per_s2 * clearance_m / kMoveRoom_m,
        options.max_move_acceleration_m_per_s2,
        std::max(options.max_move_acceleration_m_per_s2, options.deep_move_acceleration_m_per_s2));
  }
  /// Measurements the initial estimate of a vertex is fitted to (Options::
  /// extrapolate_initial_estimate): the nearest converged ones within kFitReachCells cells.
  static constexpr int kFitMeasurements = 8;
  /// Fewest measurements for the fit; fewer fall back to the extrapolation along a grid line.
  static constexpr int kMinFitMeasurements = 6;
  /// Cells, along each axis, within which the fit looks for measurements.
  static constexpr int kFitReachCells = 2;
  /// How far the true apparent mass may be from |G_hat|/g (the simulated arms: up to 2.5 times).
  static constexpr double kMassUncertainty = 3.0;
  /// When a stop holds the end-effector short of a measurement point (the force grows, the
  /// position does not follow: VertexEstimator's held-still and creep rules), the point moves
  /// this far back from where the stop held it, away from the stop, and the vertex is measured
  /// there; at most kMaxStopRetreats times per vertex. Unit: [m]
  static constexpr double kStopRetreat_m = 0.001;
  /// Most retreats from a stop (or from a hold next to the boundary that does not settle, or
  /// that stalls pushing outward) per vertex; a vertex still held after them ends unreachable
  /// and is solved from the others.
  static constexpr int kMaxStopRetreats = 3;
  /// Points closer than this to the explored boundary are watched for stops: the creep rule
  /// (VertexEstimator::setOutward) and kBoundarySettle_s. Unit: [m]
  static constexpr double kBoundaryWatchDepth_m = 0.005;
  /// A hold next to the boundary (kBoundaryWatchDepth_m) whose iteration has not settled after
  /// this much servo time moves back kStopRetreat_m along the boundary's outward normal: the
  /// dither rattling on a stop's rubber never settles (sim:falcon: the whole 10 s of
  /// max_step_duration_s, twice with the redo pass). Free holds settle within 1-2 s, the slow
  /// ones near sim:falcon's singular pose within 4. Unit: [s]
  static constexpr double kBoundarySettle_s = 4.0;
  /// Measurement points moved back from a stop so far in this run. Real-time safe.
  int stopRetreats() const noexcept;

  /// Allocates everything the run needs. Throws autograv::Error on bad parameters.
  /// Not real-time safe.
  AutoCalibrator(const WorkspaceGrid& grid, const EstimationParameters& parameters,
                 double max_force_n, const Options& options);
  /// The same with the default Options.
  AutoCalibrator(const WorkspaceGrid& grid, const EstimationParameters& parameters,
                 double max_force_n)
      : AutoCalibrator(grid, parameters, max_force_n, Options()) {}
  ~AutoCalibrator();
  /// Moves the run; the moved-from calibrator may only be destroyed or assigned to.
  AutoCalibrator(AutoCalibrator&&) noexcept;
  /// Moves the run; the moved-from calibrator may only be destroyed or assigned to.
  AutoCalibrator& operator=(AutoCalibrator&&) noexcept;

  /// Keeps the finished vertices of an earlier run (a checkpoint: converged or unreachable) and
  /// visits only the others.
  /// Throws autograv::Error when the count does not match the grid. Not real-time safe.
  void restore(const std::vector<VertexEstimate>& vertices);
  /// Visits only `indices` (e.g. the vertices that did not converge), in a short-move order, and
  /// then `last` in the order given (the points measured again to see the motors' drift, as late
  /// and as warm as the run gets), skipping those already in `indices`.
  /// Throws autograv::Error on an index out of range. Not real-time safe.
  void visitOnly(const std::vector<int>& indices, const std::vector<int>& last = {});
  /// Visits only `indices`, in the order given (a tour planned by the caller). Throws
  /// autograv::Error on an index out of range. Not real-time safe.
  void visitInOrder(const std::vector<int>& indices);
  /// Measures each vertex where `plan` says (planMeasurements: at the vertex, or at a point just
  /// inside the explored workspace), and marks the vertices it skips kUnreachable without
  /// visiting them, so that no move or hold targets a point outside the explored workspace.
  /// Call after restore() and before start(). Throws autograv::Error when the plan does not
  /// match the grid. Not real-time safe.
  void setPlan(const MeasurementPlan& plan);
  /// Measures vertex `index` again at `point_m` (a point inside the explored workspace, e.g.
  /// where it was measured: planReview) on the next visit: its estimate is set back to pending.
  /// Visit it with visitOnly() or visitInOrder(). Throws autograv::Error on an index out of range
  /// or a non-finite point. Not real-time safe. Unit: [m]
  void remeasureAt(int index, const Eigen::Vector3d& point_m);
  /// Where vertex `index` is measured: the vertex, or the plan's point. Real-time safe. Unit: [m]
  const Eigen::Vector3d& measurementPoint_m(int index) const noexcept;

  /// Starts from the end-effector at `position_m` with the estimate `initial_gravity_n` (G_hat_0
  /// from the manual initialization, eq. 7). Real-time safe.
  void start(const Eigen::Vector3d& position_m, const Eigen::Vector3d& initial_gravity_n) noexcept;
  /// One servo tick: writes the force to send. Real-time safe.
  Status step(const ServoSample& sample, Eigen::Vector3d& force_n) noexcept;

  /// Holds the end-effector where it is; resume() restarts the current move or vertex.
  /// Real-time safe.
  void pause() noexcept;
  /// Continues after pause(). Real-time safe.
  void resume() noexcept;
  /// Stops the run; keeps holding the end-effector where it is. Real-time safe.
  void abort() noexcept;

  /// What the calibrator is doing now (never kVertexFinished, which step() reports once).
  /// Real-time safe.
  Status state() const noexcept;
  /// Vertices of the grid. Real-time safe.
  int vertexCount() const noexcept;
  /// Vertices this run has to visit. Real-time safe.
  int toVisitCount() const noexcept;
  /// Vertices visited so far (the one in progress not counted). Real-time safe.
  int visitedCount() const noexcept;
  /// Grid index of the vertex being approached or estimated; -1 when none. Real-time safe.
  int currentVertex() const noexcept;
  /// Grid index of the vertex finished most recently; -1 before the first. Real-time safe.
  int lastFinishedVertex() const noexcept;
  /// Iteration in progress at the current vertex (0-based), i.e. the updates of eq. (12) made
  /// there so far. Real-time safe.
  int iteration() const noexcept;
  /// Most recent ||Delta_j|| at the current vertex (eq. 12's position error), NaN before its
  /// first update. Real-time safe. Unit: [m]
  double lastPositionError_m() const noexcept;
  /// Every vertex's estimate so far, by grid index. Real-time safe.
  const std::vector<VertexEstimate>& vertices() const noexcept;
  /// The grid being calibrated. Real-time safe.
  const WorkspaceGrid& grid() const noexcept;
  /// Servo time since start(). Real-time safe. Unit: [s]
  double elapsed_s() const noexcept;
  /// Largest |G_hat(X_a) - G_hat(X_b)| / |X_a - X_b| over converged neighbours so far: the
  /// paper's constant c measured on the data. Real-time safe. Unit: [N/m]
  double lipschitzEstimate_n_per_m() const noexcept;
  /// Largest commanded force so far, after clamping. Real-time safe. Unit: [N]
  double peakForce_n() const noexcept;
  /// How hard the forces sent so far work the motors, as GravityCompensatedDevice::thermalLoad
  /// counts it (from 0 at construction, over the continuous rating of Options): each finished
  /// vertex records it (VertexEstimate::thermal_load). Real-time safe.
  double thermalLoad() const noexcept;

  /// The map of everything estimated so far, unreachable vertices filled from the converged ones
  /// (fillUnreachableVertices). Not real-time safe.
  GravityMap makeMap(const MapMetadata& metadata) const;

 private:
  struct Impl;  // the run's state (plugin/src/core/estimation/auto_calibrator.cpp)
  std::unique_ptr<Impl> impl_;
};

const char* toString(AutoCalibrator::Status status) noexcept;

}  // namespace autograv
