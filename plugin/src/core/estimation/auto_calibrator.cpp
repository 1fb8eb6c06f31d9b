#include "autograv/estimation/auto_calibrator.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>

#include <Eigen/Cholesky>

#include "autograv/error.h"
#include "autograv/estimation/impedance_hold.h"
#include "autograv/map/vertex_fill.h"
#include "core/compensation/thermal_load_observer.h"
#include "core/estimation/minimum_jerk_move.h"
#include "core/estimation/vertex_estimator.h"

namespace autograv {

namespace {

bool isDone(const VertexEstimate& vertex) noexcept {
  return vertex.outcome == VertexOutcome::kConverged;
}

/// A vertex a resumed run need not visit again: converged, or found unreachable.
bool isSettled(const VertexEstimate& vertex) noexcept {
  return isDone(vertex) || vertex.outcome == VertexOutcome::kUnreachable;
}

/// Largest departure of a fitted initial estimate from the nearest measurement, as a fraction of
/// that measurement's magnitude.
constexpr double kMaxFitDeparture = 0.5;
}  // namespace

/// Everything an AutoCalibrator keeps, allocated whole by its constructor.
struct AutoCalibrator::Impl {
  Impl(const WorkspaceGrid& grid, const EstimationParameters& parameters, double max_force_n,
       const Options& options);

  void restore(const std::vector<VertexEstimate>& vertices);
  void visitOnly(const std::vector<int>& indices, const std::vector<int>& last);
  void visitInOrder(const std::vector<int>& indices);
  void setPlan(const MeasurementPlan& plan);
  void start(const Eigen::Vector3d& position_m, const Eigen::Vector3d& initial_gravity_n) noexcept;
  Status step(const ServoSample& sample, Eigen::Vector3d& force_n) noexcept;
  void pause() noexcept;
  void resume() noexcept;
  void abort() noexcept;
  GravityMap makeMap(const MapMetadata& metadata) const;

  void beginMove(const Eigen::Vector3d& from_m) noexcept;
  void beginNextVertex(const Eigen::Vector3d& from_m) noexcept;
  Eigen::Vector3d initialEstimateFor(int vertex) const noexcept;
  // The affine fit of initialEstimateFor; false when too few measurements are near or the fit
  // is not to be trusted.
  bool fittedEstimate(int vertex, Eigen::Vector3d& gravity_n) const noexcept;
  void recordFinished() noexcept;
  Eigen::Vector3d holdForce(const ServoSample& sample) const noexcept;

  WorkspaceGrid grid_;
  std::vector<Eigen::Vector3d> targets_;  // per vertex: where it is measured
  ExploredWorkspace workspace_;           // where the plan's points lie; empty: unknown
  std::vector<bool> met_stop_;            // per vertex: its point was moved back from a stop
  EstimationParameters parameters_;
  double max_force_n_;
  Options options_;
  ImpedanceHold hold_;  // the moves' and holds' law, with the estimator's floor
  double max_invalid_periods_;
  VertexEstimator estimator_;
  int stop_retreats_ = 0;
  MinimumJerkMove move_;
  std::vector<VertexEstimate> vertices_;
  std::vector<int> order_;
  std::size_t next_in_order_ = 0;
  Status state_ = Status::kIdle;
  Status state_before_pause_ = Status::kIdle;
  bool active_ = false;  // a vertex of order_ is being approached or estimated
  int current_vertex_ = -1;
  int previous_vertex_ = -1;
  int last_finished_vertex_ = -1;
  double elapsed_periods_ = 0.0;  // servo time since start(), in nominal periods
  double move_periods_ = 0.0;     // servo time since the current move began
  Eigen::Vector3d gravity_n_ = Eigen::Vector3d::Zero();  // feedforward carried between vertices
  Eigen::Vector3d hold_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d last_force_n_ = Eigen::Vector3d::Zero();
  double invalid_periods_ = 0.0;  // servo time of consecutive bad samples
  double lipschitz_n_per_m_ = 0.0;
  double peak_force_n_ = 0.0;
  ThermalLoadObserver thermal_;  // the motors' load from the forces sent (thermalLoad)
  int stop_retreats_here_ = 0;   // the current vertex's retreats (kMaxStopRetreats)
  Eigen::Vector3d outward_ = Eigen::Vector3d::Zero();  // boundary's outward normal at the point
  bool watched_ = false;            // the point lies within kBoundaryWatchDepth_m of the boundary
  double iteration_periods_ = 0.0;  // servo time since the hold's last update (or its start)
  int last_iterations_ = 0;
  // The direction of the estimator's push test at a watched point: toward every part of the
  // boundary within kBoundaryWatchDepth_m (VertexEstimator::setOutward). Real-time safe.
  Eigen::Vector3d pushDirection(const Eigen::Vector3d& point_m) const noexcept;
  // Moves the current point back by kStopRetreat_m along -`direction` from `from_m` and starts
  // the move there.
  void retreat(const Eigen::Vector3d& from_m, const Eigen::Vector3d& direction,
               const Eigen::Vector3d& feedforward_n, const Eigen::Vector3d& position_m) noexcept;
};

void AutoCalibrator::Impl::retreat(const Eigen::Vector3d& from_m, const Eigen::Vector3d& direction,
                                   const Eigen::Vector3d& feedforward_n,
                                   const Eigen::Vector3d& position_m) noexcept {
  met_stop_[static_cast<std::size_t>(current_vertex_)] = true;
  ++stop_retreats_;
  ++stop_retreats_here_;
  targets_[static_cast<std::size_t>(current_vertex_)] = from_m - kStopRetreat_m * direction;
  gravity_n_ = feedforward_n;
  beginMove(position_m);
}

Eigen::Vector3d AutoCalibrator::Impl::pushDirection(const Eigen::Vector3d& point_m) const noexcept {
  // The 26 directions to a cube's faces, edges and corners, each weighted by how near the
  // boundary lies along it (1 at the point, 0 at kBoundaryWatchDepth_m or beyond). Next to one
  // face the weights are symmetric about its normal and the sum is the normal; next to an edge
  // or a corner it leans toward each face within reach, so that the push presses into a floor
  // even where the nearest face, whose normal outward_ is, is a wall.
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if (dx == 0 && dy == 0 && dz == 0) continue;
        const Eigen::Vector3d direction = Eigen::Vector3d(dx, dy, dz).normalized();
        const double clearance_m =
            workspace_.clearanceAlong_m(point_m, direction, kBoundaryWatchDepth_m);
        sum += std::max(0.0, 1.0 - clearance_m / kBoundaryWatchDepth_m) * direction;
      }
    }
  }
  // Where the boundary lies beyond reach along every cube direction, the normal alone.
  return sum.norm() > 0.0 ? Eigen::Vector3d(sum.normalized()) : outward_;
}

AutoCalibrator::Impl::Impl(const WorkspaceGrid& grid, const EstimationParameters& parameters,
                           double max_force_n, const Options& options)
    : grid_(grid),
      parameters_(parameters),
      max_force_n_(max_force_n),
      options_(options),
      hold_(ImpedanceHold::from(parameters, VertexEstimator::kMinGravityN)),
      max_invalid_periods_(maxInvalidPeriods(parameters.servo_period_s)),
      estimator_(parameters, max_force_n, options.continuous_force_n),
      vertices_(static_cast<std::size_t>(grid.vertexCount())),
      order_(grid.visitOrder(grid.center_m())) {
  if (!(options.max_move_acceleration_m_per_s2 > 0.0) ||
      !(options.deep_move_acceleration_m_per_s2 > 0.0) || !(options.min_move_duration_s > 0.0)) {
    throw Error(
        "auto-calibrator: AutoCalibrator::Options::max_move_acceleration_m_per_s2, "
        "deep_move_acceleration_m_per_s2 and min_move_duration_s must be positive");
  }
  if (!options.initial_estimates_n.empty() &&
      options.initial_estimates_n.size() != vertices_.size()) {
    throw Error("auto-calibrator: AutoCalibrator::Options::initial_estimates_n has " +
                std::to_string(options.initial_estimates_n.size()) + " entries for a grid of " +
                std::to_string(vertices_.size()) + " vertices");
  }
  if (!(options.motor_time_constant_s > 0.0) || !std::isfinite(options.motor_time_constant_s)) {
    throw Error(
        "auto-calibrator: AutoCalibrator::Options::motor_time_constant_s must be a "
        "positive time in seconds");
  }
  thermal_.configure(options.continuous_force_n > 0.0
                         ? options.continuous_force_n
                         : kDefaultContinuousForceFraction * max_force_n,
                     options.motor_time_constant_s);
  met_stop_.assign(vertices_.size(), false);
  targets_.reserve(vertices_.size());
  for (int i = 0; i < grid.vertexCount(); ++i) targets_.push_back(grid.vertexPosition(i));
  // Reserve every history now so that finishing a vertex in the servo loop never allocates.
  for (auto& vertex : vertices_) {
    vertex.history.reserve(static_cast<std::size_t>(parameters.max_iterations));
  }
}

void AutoCalibrator::Impl::restore(const std::vector<VertexEstimate>& vertices) {
  if (vertices.size() != vertices_.size()) {
    std::ostringstream message;
    message << "auto-calibrator: checkpoint has " << vertices.size() << " vertices, the grid "
            << vertices_.size();
    throw Error(message.str());
  }
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    vertices_[i] = vertices[i];
    vertices_[i].history.reserve(static_cast<std::size_t>(parameters_.max_iterations));
    // Measured by another run, whose motors' load this one never saw: neither a drift reference
    // nor corrected (VertexEstimate::thermal_load).
    vertices_[i].thermal_load = 0.0;
  }
  std::vector<int> pending;
  for (int index : grid_.visitOrder(grid_.center_m())) {
    if (!isSettled(vertices_[static_cast<std::size_t>(index)])) pending.push_back(index);
  }
  order_ = std::move(pending);
  next_in_order_ = 0;
}

void AutoCalibrator::Impl::visitInOrder(const std::vector<int>& indices) {
  for (int index : indices) {
    if (index < 0 || index >= grid_.vertexCount()) {
      std::ostringstream message;
      message << "auto-calibrator: vertex " << index << " is not in the grid (0.."
              << grid_.vertexCount() - 1 << ")";
      throw Error(message.str());
    }
  }
  order_ = indices;
  next_in_order_ = 0;
}

void AutoCalibrator::Impl::visitOnly(const std::vector<int>& indices,
                                     const std::vector<int>& last) {
  visitInOrder(last);     // checks every index
  visitInOrder(indices);  // likewise
  std::vector<bool> wanted(vertices_.size(), false);
  for (int index : indices) wanted[static_cast<std::size_t>(index)] = true;
  std::vector<int> order;
  for (int index : grid_.visitOrder(grid_.center_m())) {
    if (wanted[static_cast<std::size_t>(index)]) order.push_back(index);
  }
  for (int index : last) {
    if (!wanted[static_cast<std::size_t>(index)]) order.push_back(index);
    wanted[static_cast<std::size_t>(index)] = true;
  }
  order_ = std::move(order);
  next_in_order_ = 0;
}

void AutoCalibrator::Impl::setPlan(const MeasurementPlan& plan) {
  if (static_cast<int>(plan.points_m.size()) != grid_.vertexCount() ||
      plan.measure.size() != plan.points_m.size()) {
    std::ostringstream message;
    message << "auto-calibrator: the measurement plan has " << plan.points_m.size()
            << " points for a grid of " << grid_.vertexCount() << " vertices";
    throw Error(message.str());
  }
  targets_ = plan.points_m;
  workspace_ = plan.workspace;
  std::vector<int> order;
  for (int index : order_) {
    const auto i = static_cast<std::size_t>(index);
    if (plan.measure[i]) {
      order.push_back(index);
    } else {
      vertices_[i].outcome = VertexOutcome::kUnreachable;  // beyond the explored workspace
      vertices_[i].iterations = 0;
      vertices_[i].seconds = 0.0;
      vertices_[i].history.clear();
    }
  }
  order_ = std::move(order);
  next_in_order_ = 0;
}

void AutoCalibrator::Impl::start(const Eigen::Vector3d& position_m,
                                 const Eigen::Vector3d& initial_gravity_n) noexcept {
  gravity_n_ = initial_gravity_n;
  elapsed_periods_ = 0.0;
  invalid_periods_ = 0.0;
  previous_vertex_ = -1;
  last_finished_vertex_ = -1;
  next_in_order_ = 0;
  active_ = false;
  hold_m_ = position_m;
  beginNextVertex(position_m);
}

void AutoCalibrator::Impl::beginNextVertex(const Eigen::Vector3d& from_m) noexcept {
  if (next_in_order_ >= order_.size()) {
    active_ = false;
    current_vertex_ = -1;
    state_ = Status::kFinished;
    return;
  }
  current_vertex_ = order_[next_in_order_++];
  active_ = true;
  stop_retreats_here_ = 0;
  beginMove(from_m);
}

void AutoCalibrator::Impl::beginMove(const Eigen::Vector3d& from_m) noexcept {
  const Eigen::Vector3d target_m = targets_[static_cast<std::size_t>(current_vertex_)];
  const double distance_m = (target_m - from_m).norm();
  // Without an explored workspace nothing says where the stops are, and a point moved back from
  // a stop has one a millimetre away: those moves keep the gentle acceleration.
  double clearance_m = 0.0;
  if (!workspace_.empty() && !met_stop_[static_cast<std::size_t>(current_vertex_)] &&
      distance_m > 0.0) {
    clearance_m = workspace_.clearanceAlong_m(target_m, (target_m - from_m) / distance_m,
                                              deepMoveRoom_m(options_));
  }
  move_.start(
      from_m, target_m,
      MinimumJerkMove::durationFor(distance_m, moveAcceleration_m_per_s2(options_, clearance_m),
                                   options_.min_move_duration_s));
  move_periods_ = 0.0;
  state_ = Status::kMoving;
}

bool AutoCalibrator::Impl::fittedEstimate(int vertex, Eigen::Vector3d& gravity_n) const noexcept {
  // The converged measurements nearest the point, among the vertices within kFitReachCells
  // cells (a bounded search, whatever the grid's size), closest first.
  const Eigen::Vector3d& point_m = targets_[static_cast<std::size_t>(vertex)];
  const Eigen::Vector3i here = grid_.vertexCoordinates(vertex);
  // Per measurement kept: its offset from the point, and what was measured there.
  Eigen::Vector3d offsets_m[kFitMeasurements];
  Eigen::Vector3d measured_n[kFitMeasurements];
  double distances_m2[kFitMeasurements];
  int found = 0;
  for (int dz = -kFitReachCells; dz <= kFitReachCells; ++dz) {
    for (int dy = -kFitReachCells; dy <= kFitReachCells; ++dy) {
      for (int dx = -kFitReachCells; dx <= kFitReachCells; ++dx) {
        const Eigen::Vector3i other = here + Eigen::Vector3i(dx, dy, dz);
        if (!grid_.hasVertex(other)) continue;
        const int index = grid_.vertexIndex(other.x(), other.y(), other.z());
        const VertexEstimate& measured = vertices_[static_cast<std::size_t>(index)];
        if (index == vertex || !isDone(measured)) continue;
        const Eigen::Vector3d offset_m =
            measured.measuredAt_m(grid_.vertexPosition(index)) - point_m;
        const double distance_m2 = offset_m.squaredNorm();
        // Insertion into the sorted list; once it is full, the farthest falls off.
        if (found == kFitMeasurements && distances_m2[found - 1] <= distance_m2) continue;
        int slot = found < kFitMeasurements ? found++ : kFitMeasurements - 1;
        for (; slot > 0 && distances_m2[slot - 1] > distance_m2; --slot) {
          offsets_m[slot] = offsets_m[slot - 1];
          measured_n[slot] = measured_n[slot - 1];
          distances_m2[slot] = distances_m2[slot - 1];
        }
        offsets_m[slot] = offset_m;
        measured_n[slot] = measured.measuredGravity_n();
        distances_m2[slot] = distance_m2;
      }
    }
  }
  if (found < kMinFitMeasurements) return false;
  // G(x) = a + B (x - point), least squares over the measurements, offsets in units of their
  // RMS distance so that the 4 x 4 normal equations are well scaled; a light ridge on B keeps
  // coplanar measurements (a face of the grid) solvable.
  double mean_m2 = 0.0;
  for (int k = 0; k < found; ++k) mean_m2 += distances_m2[k];
  const double scale_m = std::sqrt(mean_m2 / found);
  if (!(scale_m > 0.0)) return false;
  Eigen::Matrix4d normal = Eigen::Matrix4d::Zero();
  Eigen::Matrix<double, 4, 3> right = Eigen::Matrix<double, 4, 3>::Zero();
  for (int k = 0; k < found; ++k) {
    Eigen::Vector4d row;
    row << 1.0, offsets_m[k] / scale_m;
    normal += row * row.transpose();
    right += row * measured_n[k].transpose();
  }
  constexpr double kRidge = 1e-3;
  for (int axis = 1; axis < 4; ++axis) normal(axis, axis) += kRidge * found;
  const Eigen::LDLT<Eigen::Matrix4d> solver(normal);
  if (solver.info() != Eigen::Success) return false;
  const Eigen::Matrix<double, 4, 3> coefficients = solver.solve(right);
  const Eigen::Vector3d predicted_n = coefficients.row(0).transpose();
  // A fit that moves far from the nearest measurement extrapolates more than it knows.
  const Eigen::Vector3d& closest_n = measured_n[0];
  if (!predicted_n.allFinite() ||
      (predicted_n - closest_n).norm() > kMaxFitDeparture * closest_n.norm()) {
    return false;
  }
  gravity_n = predicted_n;
  return true;
}

Eigen::Vector3d AutoCalibrator::Impl::initialEstimateFor(int vertex) const noexcept {
  const auto slot = static_cast<std::size_t>(vertex);
  if (slot < options_.initial_estimates_n.size() &&
      options_.initial_estimates_n[slot].allFinite()) {
    return options_.initial_estimates_n[slot];
  }
  // eq. (9): start from the estimate carried from the previous vertex.
  if (!options_.extrapolate_initial_estimate || previous_vertex_ < 0) return gravity_n_;
  Eigen::Vector3d fitted_n;
  if (fittedEstimate(vertex, fitted_n)) return fitted_n;
  const auto& previous = vertices_[static_cast<std::size_t>(previous_vertex_)];
  if (!isDone(previous)) return gravity_n_;
  // If the vertex behind the previous one (on the same line) converged too, extrapolate linearly.
  const Eigen::Vector3i step =
      grid_.vertexCoordinates(vertex) - grid_.vertexCoordinates(previous_vertex_);
  if (step.cwiseAbs().sum() != 1) return gravity_n_;
  const Eigen::Vector3i behind = grid_.vertexCoordinates(previous_vertex_) - step;
  if (!grid_.hasVertex(behind)) return gravity_n_;
  const auto& before =
      vertices_[static_cast<std::size_t>(grid_.vertexIndex(behind.x(), behind.y(), behind.z()))];
  if (!isDone(before)) return gravity_n_;
  return 2.0 * previous.gravity_n - before.gravity_n;
}

Eigen::Vector3d AutoCalibrator::Impl::holdForce(const ServoSample& sample) const noexcept {
  Eigen::Vector3d force_n =
      hold_.holdForce_n(hold_m_, sample, hold_.apparentMass_kg(gravity_n_), gravity_n_);
  clampForce(force_n, max_force_n_);
  return force_n;
}

void AutoCalibrator::Impl::recordFinished() noexcept {
  const int index = current_vertex_;
  auto& slot = vertices_[static_cast<std::size_t>(index)];
  const VertexEstimate& result = estimator_.estimate();
  slot.gravity_n = result.gravity_n;
  slot.iterations = result.iterations;
  slot.seconds = result.seconds;
  slot.thermal_load = thermal_.load();
  slot.outcome = result.outcome;
  const Eigen::Vector3d& point_m = targets_[static_cast<std::size_t>(index)];
  if ((point_m - grid_.vertexPosition(index)).norm() > 1e-9) {
    slot.measured_at_m = point_m;
    slot.measured_gravity_n = result.gravity_n;
  }
  slot.history.clear();
  for (const auto& record : result.history) {
    if (slot.history.size() < slot.history.capacity()) slot.history.push_back(record);
  }
  last_finished_vertex_ = index;
  if (isDone(slot)) {
    gravity_n_ = slot.gravity_n;  // eq. (9)
    const Eigen::Vector3i here = grid_.vertexCoordinates(index);
    for (int axis = 0; axis < 3; ++axis) {
      for (int sign : {-1, 1}) {
        Eigen::Vector3i other = here;
        other[axis] += sign;
        if (!grid_.hasVertex(other)) continue;
        const auto& neighbour =
            vertices_[static_cast<std::size_t>(grid_.vertexIndex(other.x(), other.y(), other.z()))];
        if (!isDone(neighbour)) continue;
        const double distance_m =
            (point_m -
             targets_[static_cast<std::size_t>(grid_.vertexIndex(other.x(), other.y(), other.z()))])
                .norm();
        if (distance_m < 1e-6) continue;
        lipschitz_n_per_m_ = std::max(lipschitz_n_per_m_,
                                      (slot.gravity_n - neighbour.gravity_n).norm() / distance_m);
      }
    }
    previous_vertex_ = index;
  } else {
    previous_vertex_ = -1;  // do not extrapolate from a failed vertex
  }
}

AutoCalibrator::Status AutoCalibrator::Impl::step(const ServoSample& sample,
                                                  Eigen::Vector3d& force_n) noexcept {
  const double periods = servoPeriodsOf(sample, parameters_.servo_period_s);
  elapsed_periods_ += periods;
  if (state_ == Status::kIdle || state_ == Status::kDeviceFault) {
    force_n.setZero();
    return state_;
  }
  if (!sample.valid) {
    force_n = last_force_n_;
    invalid_periods_ += periods;
    if (invalid_periods_ > max_invalid_periods_) {
      force_n.setZero();
      last_force_n_.setZero();
      if (active_ && state_ == Status::kEstimating) {
        vertices_[static_cast<std::size_t>(current_vertex_)].outcome = VertexOutcome::kDeviceFault;
      }
      state_ = Status::kDeviceFault;
    }
    return state_;
  }
  invalid_periods_ = 0.0;

  switch (state_) {
    case Status::kPaused:
    case Status::kFinished:
    case Status::kAborted:
      force_n = holdForce(sample);
      break;
    case Status::kMoving: {
      move_periods_ += periods;
      Eigen::Vector3d desired_m, desired_velocity, desired_acceleration;
      move_.sample(move_periods_ * parameters_.servo_period_s, desired_m, desired_velocity,
                   desired_acceleration);
      // eq. (10) tracking a moving target, with the path's acceleration fed forward.
      force_n = hold_.trackForce_n(desired_m, desired_velocity, desired_acceleration, sample,
                                   hold_.apparentMass_kg(gravity_n_), gravity_n_);
      clampForce(force_n, max_force_n_);
      hold_m_ = desired_m;
      if (move_periods_ * parameters_.servo_period_s >= move_.duration_s()) {
        const Eigen::Vector3d& point_m = targets_[static_cast<std::size_t>(current_vertex_)];
        estimator_.start(point_m, initialEstimateFor(current_vertex_));
        state_ = Status::kEstimating;
        iteration_periods_ = 0.0;
        last_iterations_ = 0;
        watched_ = !workspace_.empty() && workspace_.depth_m(point_m) < kBoundaryWatchDepth_m;
        outward_.setZero();
        if (watched_) {
          // The explored boundary's outward normal at the point: minus the gradient of its depth
          // (the nearest triangle's normal). Positions and the explored workspace only.
          constexpr double kStep_m = 2e-4;
          for (int axis = 0; axis < 3; ++axis) {
            Eigen::Vector3d step = Eigen::Vector3d::Zero();
            step[axis] = kStep_m;
            outward_[axis] =
                (workspace_.depth_m(point_m - step) - workspace_.depth_m(point_m + step)) /
                (2.0 * kStep_m);
          }
          if (outward_.norm() > 0.0) {
            outward_.normalize();
          } else {
            outward_ = point_m - grid_.center_m();
          }
          estimator_.setOutward(outward_, pushDirection(point_m));
        }
      }
      break;
    }
    case Status::kEstimating: {
      const VertexEstimator::Status inner = estimator_.step(sample, force_n);
      iteration_periods_ += periods;
      if (estimator_.iteration() != last_iterations_) {
        last_iterations_ = estimator_.iteration();
        iteration_periods_ = 0.0;
      }
      if (watched_ && !estimator_.finished() &&
          iteration_periods_ * parameters_.servo_period_s > kBoundarySettle_s &&
          stop_retreats_here_ < kMaxStopRetreats && outward_.squaredNorm() > 0.0) {
        // Next to the boundary and not settling (kBoundarySettle_s): back along the normal.
        retreat(targets_[static_cast<std::size_t>(current_vertex_)], outward_.normalized(),
                initialEstimateFor(current_vertex_), sample.position_m);
        break;
      }
      if (inner == VertexEstimator::Status::kSettling ||
          inner == VertexEstimator::Status::kUpdated) {
        break;
      }
      // A stop lies beyond the point, away from the workspace's middle: the pushing steps point
      // outward. Steps that point inward held still come from a steep field, not a stop, and
      // stepping "back" from them would walk out toward the real stops.
      // At a watched point, a contact found pushing toward the explored boundary (the push
      // test's, whose direction leans along outward_) is outward by construction, whether the
      // point lies above or below the grid's centre: a floor and a ceiling both retreat.
      const bool outward_contact =
          estimator_.contactDirection().dot(targets_[static_cast<std::size_t>(current_vertex_)] -
                                            grid_.center_m()) > 0.0 ||
          (watched_ && estimator_.contactDirection().dot(outward_) > 0.0);
      if (inner == VertexEstimator::Status::kUnreachable && estimator_.stopContact() &&
          outward_contact && stop_retreats_here_ < kMaxStopRetreats) {
        // A stop held the end-effector short of the point: measure it back from the stop.
        retreat(estimator_.contactPosition_m(), estimator_.contactDirection(),
                estimator_.gravityBeforeContact_n(), sample.position_m);
        break;
      }
      // The way the last step of eq. (12) pushed: against a stop, the stop's normal.
      const std::vector<IterationRecord>& steps = estimator_.estimate().history;
      const Eigen::Vector3d push_n =
          steps.size() >= 2 ? Eigen::Vector3d(steps[steps.size() - 1].gravity_estimate_n -
                                              steps[steps.size() - 2].gravity_estimate_n)
                            : Eigen::Vector3d::Zero();
      if (inner == VertexEstimator::Status::kUnreachable && watched_ &&
          push_n.dot(outward_) > 0.0 && stop_retreats_here_ < kMaxStopRetreats) {
        // Next to the boundary, a hold that stalls pushing outward may rest on a stop that no
        // rule confirmed (sim:omni at high friction, by its -x reach): try again inward along
        // the boundary's normal, a millimetre back against its push (at a box's corner the
        // normal is a diagonal, and a millimetre along it leaves the point on the face's stop).
        const Eigen::Vector3d normal = outward_.normalized();
        const double along_push = std::max(0.5, normal.dot(push_n.normalized()));
        retreat(targets_[static_cast<std::size_t>(current_vertex_)], normal / along_push,
                initialEstimateFor(current_vertex_), sample.position_m);
        break;
      }
      recordFinished();
      hold_m_ = targets_[static_cast<std::size_t>(current_vertex_)];
      if (inner == VertexEstimator::Status::kDeviceFault) {
        force_n.setZero();
        state_ = Status::kDeviceFault;
        break;
      }
      beginNextVertex(hold_m_);
      last_force_n_ = force_n;
      peak_force_n_ = std::max(peak_force_n_, force_n.norm());
      return Status::kVertexFinished;
    }
    case Status::kVertexFinished:
    case Status::kIdle:
    case Status::kDeviceFault:
      force_n.setZero();
      break;
  }
  last_force_n_ = force_n;
  peak_force_n_ = std::max(peak_force_n_, force_n.norm());
  return state_;
}

void AutoCalibrator::Impl::pause() noexcept {
  if (state_ != Status::kMoving && state_ != Status::kEstimating) return;
  state_before_pause_ = state_;
  state_ = Status::kPaused;
}

void AutoCalibrator::Impl::resume() noexcept {
  if (state_ != Status::kPaused) return;
  // Restart the interrupted move (or the approach to the interrupted vertex) from the hold point.
  beginMove(hold_m_);
}

void AutoCalibrator::Impl::abort() noexcept {
  if (state_ == Status::kIdle || state_ == Status::kDeviceFault) return;
  state_ = Status::kAborted;
}

GravityMap AutoCalibrator::Impl::makeMap(const MapMetadata& metadata) const {
  std::vector<VertexEstimate> vertices = vertices_;
  fillUnreachableVertices(grid_, vertices);
  return GravityMap(grid_, std::move(vertices), metadata);
}

// --- The public class: each call goes to the Impl ---------------------------------------------

AutoCalibrator::AutoCalibrator(const WorkspaceGrid& grid, const EstimationParameters& parameters,
                               double max_force_n, const Options& options)
    : impl_(std::make_unique<Impl>(grid, parameters, max_force_n, options)) {}

AutoCalibrator::~AutoCalibrator() = default;
AutoCalibrator::AutoCalibrator(AutoCalibrator&&) noexcept = default;
AutoCalibrator& AutoCalibrator::operator=(AutoCalibrator&&) noexcept = default;

void AutoCalibrator::restore(const std::vector<VertexEstimate>& vertices) {
  impl_->restore(vertices);
}

void AutoCalibrator::visitOnly(const std::vector<int>& indices, const std::vector<int>& last) {
  impl_->visitOnly(indices, last);
}

void AutoCalibrator::visitInOrder(const std::vector<int>& indices) { impl_->visitInOrder(indices); }

void AutoCalibrator::setPlan(const MeasurementPlan& plan) { impl_->setPlan(plan); }

void AutoCalibrator::remeasureAt(int index, const Eigen::Vector3d& point_m) {
  if (index < 0 || index >= impl_->grid_.vertexCount() || !point_m.allFinite()) {
    std::ostringstream message;
    message << "auto-calibrator: cannot measure vertex " << index << " again at ["
            << point_m.transpose() << "] m: the index must lie in 0.."
            << impl_->grid_.vertexCount() - 1 << " and the point be finite";
    throw Error(message.str());
  }
  const auto i = static_cast<std::size_t>(index);
  impl_->targets_[i] = point_m;
  impl_->met_stop_[i] = false;
  VertexEstimate& vertex = impl_->vertices_[i];
  vertex.outcome = VertexOutcome::kPending;
  vertex.provenance = VertexProvenance::kMeasured;
  vertex.iterations = 0;
  vertex.seconds = 0.0;
  vertex.history.clear();
  vertex.measured_at_m = VertexEstimate().measured_at_m;
  vertex.measured_gravity_n.setZero();
}

const Eigen::Vector3d& AutoCalibrator::measurementPoint_m(int index) const noexcept {
  return impl_->targets_[static_cast<std::size_t>(index)];
}

void AutoCalibrator::start(const Eigen::Vector3d& position_m,
                           const Eigen::Vector3d& initial_gravity_n) noexcept {
  impl_->start(position_m, initial_gravity_n);
}

AutoCalibrator::Status AutoCalibrator::step(const ServoSample& sample,
                                            Eigen::Vector3d& force_n) noexcept {
  Impl& s = *impl_;
  s.thermal_.advance(servoPeriodsOf(sample, s.parameters_.servo_period_s) *
                     s.parameters_.servo_period_s);
  const Status status = s.step(sample, force_n);
  s.thermal_.sent(force_n);
  return status;
}

void AutoCalibrator::pause() noexcept { impl_->pause(); }

void AutoCalibrator::resume() noexcept { impl_->resume(); }

void AutoCalibrator::abort() noexcept { impl_->abort(); }

int AutoCalibrator::stopRetreats() const noexcept { return impl_->stop_retreats_; }

AutoCalibrator::Status AutoCalibrator::state() const noexcept { return impl_->state_; }

int AutoCalibrator::vertexCount() const noexcept { return impl_->grid_.vertexCount(); }

int AutoCalibrator::toVisitCount() const noexcept { return static_cast<int>(impl_->order_.size()); }

int AutoCalibrator::visitedCount() const noexcept {
  return static_cast<int>(impl_->next_in_order_) - (impl_->active_ ? 1 : 0);
}

int AutoCalibrator::currentVertex() const noexcept { return impl_->current_vertex_; }

int AutoCalibrator::lastFinishedVertex() const noexcept { return impl_->last_finished_vertex_; }

int AutoCalibrator::iteration() const noexcept { return impl_->estimator_.iteration(); }

double AutoCalibrator::lastPositionError_m() const noexcept {
  return impl_->estimator_.lastPositionError_m();
}

const std::vector<VertexEstimate>& AutoCalibrator::vertices() const noexcept {
  return impl_->vertices_;
}

const WorkspaceGrid& AutoCalibrator::grid() const noexcept { return impl_->grid_; }

double AutoCalibrator::elapsed_s() const noexcept {
  return impl_->elapsed_periods_ * impl_->parameters_.servo_period_s;
}

double AutoCalibrator::lipschitzEstimate_n_per_m() const noexcept {
  return impl_->lipschitz_n_per_m_;
}

double AutoCalibrator::peakForce_n() const noexcept { return impl_->peak_force_n_; }

double AutoCalibrator::thermalLoad() const noexcept { return impl_->thermal_.load(); }

GravityMap AutoCalibrator::makeMap(const MapMetadata& metadata) const {
  return impl_->makeMap(metadata);
}

const char* toString(AutoCalibrator::Status status) noexcept {
  switch (status) {
    case AutoCalibrator::Status::kIdle:
      return "idle";
    case AutoCalibrator::Status::kMoving:
      return "moving";
    case AutoCalibrator::Status::kEstimating:
      return "estimating";
    case AutoCalibrator::Status::kVertexFinished:
      return "vertex_finished";
    case AutoCalibrator::Status::kPaused:
      return "paused";
    case AutoCalibrator::Status::kFinished:
      return "finished";
    case AutoCalibrator::Status::kAborted:
      return "aborted";
    case AutoCalibrator::Status::kDeviceFault:
      return "device_fault";
  }
  return "unknown";
}

}  // namespace autograv
