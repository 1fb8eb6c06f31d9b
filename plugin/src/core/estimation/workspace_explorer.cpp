#include "autograv/estimation/workspace_explorer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <utility>

#include <Eigen/Geometry>

#include "autograv/error.h"
#include "autograv/estimation/impedance_hold.h"
#include "core/estimation/minimum_jerk_move.h"

namespace autograv {

namespace {
/// Longest hold after a transfer for the end-effector to catch up with its end. Unit: [s]
constexpr double kTransferSettleMax_s = 0.3;
/// Floor on |G_hat| for the apparent mass of the probe's damping (eq. 6). Unit: [N]
constexpr double kProbeMinGravityN = 0.01;
/// Time constant of the gravity estimate following the probe effort. Unit: [s]
constexpr double kGravityFollow_s = 0.4;
/// Time constant of the velocity filter of the contact check. Unit: [s]
constexpr double kVelocityFilter_s = 0.01;
/// Damping ratio of the probe's spring on the estimated apparent mass.
constexpr double kProbeDampingRatio = 0.75;
/// Shortest back-off and transfer move. Unit: [s]
constexpr double kMinMove_s = 0.15;
/// Smallest reach recorded along a direction. Unit: [m]
constexpr double kMinReach_m = 1e-3;
/// Lag, in contact lags, beyond which the end-effector is taken to be held by a stop.
constexpr double kFarBehindLags = 3.0;
}  // namespace

/// Everything a WorkspaceExplorer keeps, allocated whole by its constructor.
struct WorkspaceExplorer::Impl {
  Impl(const EstimationParameters& parameters, const DeviceSpecifications& specifications,
       const Options& options);

  void start(const Eigen::Vector3d& center_m, const Eigen::Vector3d& gravity_n) noexcept;
  Status step(const ServoSample& sample, Eigen::Vector3d& force_n) noexcept;
  void abort() noexcept;
  ExploredWorkspace workspace() const;
  int directionCount() const noexcept { return static_cast<int>(directions_.size()); }

  /// Appends the boundary directions of a `count`-direction spread and their enclosures.
  void addBoundaryDirections(int count);
  /// Once the radial stops are known: marks the boundary directions whose radial triangle
  /// bulges less than Options::boundary_bulge_m as skipped.
  void chooseBoundaryProbes() noexcept;
  /// How far a smooth surface through the three radial stops around boundary direction `index`
  /// lies beyond their flat triangle along it (negative: inside). Unit: [m]
  double boundaryBulge_m(int index) const noexcept;
  /// The radial stop `index`, from the centre. Unit: [m]
  Eigen::Vector3d stopPoint_m(int index) const noexcept {
    return reach_m_[static_cast<std::size_t>(index)] * directions_[static_cast<std::size_t>(index)];
  }
  /// Moves current_ past the directions marked skipped, counting them as finished.
  void skipUnneededDirections() noexcept;
  void beginTransfer(const Eigen::Vector3d& from_m) noexcept;
  /// Where the probe along direction `index` starts, from the centre. Unit: [m]
  double probeStart_m(int index) const noexcept;
  void finishDirection(double reach_m, const Eigen::Vector3d& from_m) noexcept;
  /// Ends the current (boundary) direction without a reach: it is left out like a skipped one.
  void discardDirection(const Eigen::Vector3d& from_m) noexcept;
  /// Moves back from `from_m` to `back_m` before the next direction.
  void backOff(const Eigen::Vector3d& back_m, const Eigen::Vector3d& from_m) noexcept;
  Eigen::Vector3d impedanceForce(const ServoSample& sample, const Eigen::Vector3d& target_m,
                                 const Eigen::Vector3d& target_velocity, bool adapt) noexcept;

  EstimationParameters parameters_;
  double period_s_;
  double max_force_n_;
  Options options_;
  double contact_force_n_ = 0.0;
  double force_cap_n_ = 0.0;
  bool followed_since_start_ = false;  // the end-effector has kept up since this probe began
  std::vector<Eigen::Vector3d> directions_;
  std::vector<double> reach_m_;
  int radial_count_ = 0;
  /// Per boundary direction: the triangle of radial directions around it and its weights on
  /// their corners (direction = sum of weight times corner direction), so that the boundary the
  /// radial stops make along it is 1 / sum(weight / reach) without allocating.
  struct Enclosure {
    std::array<int, 3> corner{};
    Eigen::Vector3d weight = Eigen::Vector3d::Zero();
  };
  std::vector<Enclosure> enclosures_;
  /// The radial directions' triangles (corners counter-clockwise seen from outside), and per
  /// radial stop its outward normal once the stops are known (chooseBoundaryProbes).
  std::vector<std::array<int, 3>> radial_facets_;
  std::vector<Eigen::Vector3d> stop_normals_;
  std::vector<char> skipped_;     // per direction: a boundary direction left out
  std::vector<double> bulge_m_;   // per direction: boundaryBulge_m, once the radial stops are known
  std::vector<int> probe_order_;  // the boundary candidates, most bulging first (no allocation)
  int skipped_count_ = 0;
  Status state_ = Status::kIdle;
  MinimumJerkMove move_;
  double elapsed_s_ = 0.0;  // servo time since start(), from the samples' intervals
  double phase_s_ = 0.0;    // servo time since the current move or probe began
  double dt_s_ = 0.0;       // this tick's interval
  int current_ = 0;
  int probed_ = 0;
  int open_directions_ = 0;
  double invalid_s_ = 0.0;  // servo time the readings have been invalid
  Eigen::Vector3d center_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d gravity_n_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d target_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d probe_start_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d filtered_velocity_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d last_force_n_ = Eigen::Vector3d::Zero();
  double last_progress_s_ = 0.0;  // servo time of the last tick the end-effector kept up
  Eigen::Vector3d last_following_m_ = Eigen::Vector3d::Zero();  // and where it was then
  double contact_since_s_ = -1.0;
  double longest_recognition_s_ = 0.0;
};

WorkspaceExplorer::Impl::Impl(const EstimationParameters& parameters,
                              const DeviceSpecifications& specifications, const Options& options)
    : parameters_(parameters),
      period_s_(parameters.servo_period_s),
      max_force_n_(specifications.max_linear_force_n),
      options_(options) {
  const auto refuse = [](const std::string& what) { throw Error("workspace explorer: " + what); };
  validateSpecifications(specifications);
  const double max_force_n = specifications.max_linear_force_n;
  const double continuous_force_n = continuousForceRating_n(specifications);
  if (options_.max_reach_m == 0.0) {
    options_.max_reach_m = kReachFactor * specifications.workspace_radius_m;
  }
  if (!(max_force_n > 0.0) || !std::isfinite(max_force_n)) {
    refuse("the maximum force must be a positive force in N");
  }
  if (!(continuous_force_n > 0.0) || !(continuous_force_n <= max_force_n)) {
    refuse("the continuous force rating must be positive and at most the maximum force");
  }
  if (!(period_s_ > 0.0)) refuse("EstimationParameters::servo_period_s must be positive");
  if (options.directions < 6 ||
      (!options.radial_directions.empty() && options.radial_directions.size() < 6)) {
    refuse("WorkspaceExplorer::Options::directions must be at least 6");
  }
  for (const Eigen::Vector3d& u : options.radial_directions) {
    if (!u.allFinite() || !(u.norm() > 0.0)) {
      refuse("WorkspaceExplorer::Options::radial_directions must be finite and non-zero");
    }
  }
  if (!(options.probe_speed_m_per_s > 0.0) || !(options_.max_reach_m > 0.0) ||
      !(options.back_off_m > 0.0) || !(options.contact_lag_m > 0.0) ||
      !(options.max_move_acceleration_m_per_s2 > 0.0) || !(options.contact_force_n >= 0.0)) {
    refuse("WorkspaceExplorer::Options speeds, distances and accelerations must be positive");
  }
  if (!(options.start_fraction >= 0.0 && options.start_fraction < 1.0)) {
    refuse("WorkspaceExplorer::Options::start_fraction must lie in [0, 1)");
  }
  contact_force_n_ = options.contact_force_n > 0.0
                         ? options.contact_force_n
                         : std::min(kContactForceFraction * max_force_n, 0.5 * continuous_force_n);
  force_cap_n_ = 1.5 * contact_force_n_;
  if (options.boundary_directions < 0 || options.boundary_candidates < 0 ||
      !(options.boundary_clearance_m > 0.0) ||
      !(options.boundary_bulge_m >= 0.0 && std::isfinite(options.boundary_bulge_m))) {
    refuse(
        "WorkspaceExplorer::Options::boundary_directions, boundary_candidates and "
        "boundary_bulge_m must not be negative and boundary_clearance_m must be positive");
  }
  if (static_cast<std::size_t>(options.directions) +
          static_cast<std::size_t>(
              std::max(options.boundary_directions, options.boundary_candidates)) >
      ExploredWorkspace::kMaxDirections) {
    refuse(
        "WorkspaceExplorer::Options::directions plus boundary_directions (or "
        "boundary_candidates) must be at most " +
        std::to_string(ExploredWorkspace::kMaxDirections));
  }
  if (options.radial_directions.empty()) {
    directions_ = ExploredWorkspace::probeDirections(options.directions);
  } else {
    for (const Eigen::Vector3d& u : options.radial_directions)
      directions_.push_back(u.normalized());
  }
  radial_count_ = static_cast<int>(directions_.size());
  addBoundaryDirections(options.boundary_directions > 0
                            ? std::max(options.boundary_directions, options.boundary_candidates)
                            : 0);
  reach_m_.assign(directions_.size(), 0.0);
  skipped_.assign(directions_.size(), 0);
  bulge_m_.assign(directions_.size(), 0.0);
  probe_order_.assign(directions_.size(), 0);
}

void WorkspaceExplorer::Impl::addBoundaryDirections(int count) {
  enclosures_.assign(directions_.size(), Enclosure{});
  if (count < 6) return;
  // The radial directions' triangulation, the one their explored workspace will have.
  const std::vector<Eigen::Vector3d> radial = directions_;
  const ExploredWorkspace unit(Eigen::Vector3d::Zero(), radial,
                               std::vector<double>(radial.size(), 1.0));
  radial_facets_ = unit.facets();
  stop_normals_.assign(radial.size(), Eigen::Vector3d::Zero());
  const double same_dot = std::cos(kSameDirection_rad);
  for (const Eigen::Vector3d& u : ExploredWorkspace::probeDirections(count)) {
    const bool known = std::any_of(radial.begin(), radial.end(),
                                   [&](const Eigen::Vector3d& r) { return r.dot(u) > same_dot; });
    Enclosure around;
    if (known || !unit.enclosingFacet(u, around.corner, around.weight)) continue;
    directions_.push_back(u);
    enclosures_.push_back(around);
  }
}

double WorkspaceExplorer::Impl::probeStart_m(int index) const noexcept {
  if (index < radial_count_) {
    const double previous_reach_m = index > 0 ? reach_m_[static_cast<std::size_t>(index - 1)] : 0.0;
    return options_.start_fraction * previous_reach_m;
  }
  // The plane through the three radial stops around this direction, where the ray meets it.
  const Enclosure& around = enclosures_[static_cast<std::size_t>(index)];
  double inverse_reach_per_m = 0.0;
  for (int k = 0; k < 3; ++k) {
    inverse_reach_per_m += around.weight[k] / reach_m_[static_cast<std::size_t>(around.corner[k])];
  }
  const double boundary_m = 1.0 / inverse_reach_per_m;
  return std::max(options_.start_fraction * boundary_m, boundary_m - options_.boundary_clearance_m);
}

void WorkspaceExplorer::Impl::chooseBoundaryProbes() noexcept {
  // Each stop's normal: the area-weighted normals of the radial triangles around it.
  std::fill(stop_normals_.begin(), stop_normals_.end(), Eigen::Vector3d::Zero());
  for (const std::array<int, 3>& facet : radial_facets_) {
    const Eigen::Vector3d a = stopPoint_m(facet[0]);
    const Eigen::Vector3d normal = (stopPoint_m(facet[1]) - a).cross(stopPoint_m(facet[2]) - a);
    for (const int corner : facet) stop_normals_[static_cast<std::size_t>(corner)] += normal;
  }
  for (Eigen::Vector3d& normal : stop_normals_) {
    const double length = normal.norm();
    if (length > 0.0) normal /= length;
  }
  // The candidates that bulge most, and more than boundary_bulge_m; ties to the lower index.
  int eligible = 0;
  for (int i = radial_count_; i < directionCount(); ++i) {
    const double bulge_m = boundaryBulge_m(i);
    bulge_m_[static_cast<std::size_t>(i)] = bulge_m;
    if (bulge_m > options_.boundary_bulge_m) probe_order_[static_cast<std::size_t>(eligible++)] = i;
    skipped_[static_cast<std::size_t>(i)] = 1;
  }
  const auto first = probe_order_.begin();
  const auto last = first + eligible;
  const auto chosen = first + std::min(eligible, options_.boundary_directions);
  std::nth_element(first, chosen, last, [this](int a, int b) {
    const double bulge_a = bulge_m_[static_cast<std::size_t>(a)];
    const double bulge_b = bulge_m_[static_cast<std::size_t>(b)];
    return bulge_a > bulge_b || (bulge_a == bulge_b && a < b);
  });
  for (auto it = first; it != chosen; ++it) skipped_[static_cast<std::size_t>(*it)] = 0;
}

double WorkspaceExplorer::Impl::boundaryBulge_m(int index) const noexcept {
  const Enclosure& around = enclosures_[static_cast<std::size_t>(index)];
  double inverse_reach_per_m = 0.0;
  for (int k = 0; k < 3; ++k) {
    inverse_reach_per_m += around.weight[k] / reach_m_[static_cast<std::size_t>(around.corner[k])];
  }
  // Where the ray meets the flat triangle, and that point's barycentric weights on its corners.
  const Eigen::Vector3d flat_m = directions_[static_cast<std::size_t>(index)] / inverse_reach_per_m;
  const Eigen::Vector3d a = stopPoint_m(around.corner[0]);
  Eigen::Vector3d facet_normal =
      (stopPoint_m(around.corner[1]) - a).cross(stopPoint_m(around.corner[2]) - a);
  if (!(facet_normal.norm() > 0.0)) return 0.0;
  facet_normal.normalize();
  // Phong tessellation: the flat point projected onto each corner's tangent plane, blended with
  // the same weights. On a plane every projection is the point itself; on a sphere it bulges
  // out by about the cap's height.
  Eigen::Vector3d smooth_m = Eigen::Vector3d::Zero();
  for (int k = 0; k < 3; ++k) {
    const int corner = around.corner[k];
    const double barycentric =
        around.weight[k] / (reach_m_[static_cast<std::size_t>(corner)] * inverse_reach_per_m);
    const Eigen::Vector3d& normal = stop_normals_[static_cast<std::size_t>(corner)];
    smooth_m += barycentric * (flat_m - (flat_m - stopPoint_m(corner)).dot(normal) * normal);
  }
  return (smooth_m - flat_m).dot(facet_normal);
}

void WorkspaceExplorer::Impl::skipUnneededDirections() noexcept {
  while (current_ < directionCount() && skipped_[static_cast<std::size_t>(current_)] != 0) {
    ++current_;
    ++probed_;
    ++skipped_count_;
  }
}

void WorkspaceExplorer::Impl::start(const Eigen::Vector3d& center_m,
                                    const Eigen::Vector3d& gravity_n) noexcept {
  center_m_ = center_m;
  gravity_n_ = gravity_n;
  target_m_ = center_m;
  elapsed_s_ = 0.0;
  current_ = 0;
  probed_ = 0;
  open_directions_ = 0;
  invalid_s_ = 0.0;
  longest_recognition_s_ = 0.0;
  skipped_count_ = 0;
  filtered_velocity_.setZero();
  std::fill(reach_m_.begin(), reach_m_.end(), 0.0);
  std::fill(skipped_.begin(), skipped_.end(), 0);
  beginTransfer(center_m);
}

void WorkspaceExplorer::Impl::beginTransfer(const Eigen::Vector3d& from_m) noexcept {
  Eigen::Vector3d to_m = center_m_;
  if (current_ < directionCount()) {
    to_m = center_m_ + probeStart_m(current_) * directions_[static_cast<std::size_t>(current_)];
  }
  move_.start(from_m, to_m,
              MinimumJerkMove::durationFor((to_m - from_m).norm(),
                                           options_.max_move_acceleration_m_per_s2, kMinMove_s));
  phase_s_ = 0.0;
  state_ = Status::kTransfer;
}

void WorkspaceExplorer::Impl::finishDirection(double reach_m,
                                              const Eigen::Vector3d& from_m) noexcept {
  const Eigen::Vector3d& u = directions_[static_cast<std::size_t>(current_)];
  // A stop right at the centre still leaves a workspace, if a thin one.
  reach_m = std::max(reach_m, kMinReach_m);
  reach_m_[static_cast<std::size_t>(current_)] = reach_m;
  ++probed_;
  backOff(center_m_ + std::max(0.0, reach_m - options_.back_off_m) * u, from_m);
}

void WorkspaceExplorer::Impl::discardDirection(const Eigen::Vector3d& from_m) noexcept {
  skipped_[static_cast<std::size_t>(current_)] = 1;
  ++skipped_count_;
  ++probed_;
  backOff(probe_start_m_, from_m);
}

void WorkspaceExplorer::Impl::backOff(const Eigen::Vector3d& back_m,
                                      const Eigen::Vector3d& from_m) noexcept {
  move_.start(from_m, back_m,
              MinimumJerkMove::durationFor((back_m - from_m).norm(),
                                           options_.max_move_acceleration_m_per_s2, kMinMove_s));
  phase_s_ = 0.0;
  contact_since_s_ = -1.0;
  state_ = Status::kBackingOff;
}

Eigen::Vector3d WorkspaceExplorer::Impl::impedanceForce(const ServoSample& sample,
                                                        const Eigen::Vector3d& target_m,
                                                        const Eigen::Vector3d& target_velocity,
                                                        bool adapt) noexcept {
  const double stiffness_n_per_m = contact_force_n_ / options_.contact_lag_m;
  const double mass_kg = apparentMass_kg(gravity_n_, kProbeMinGravityN);
  const double damping_n_s_per_m =
      2.0 * kProbeDampingRatio * std::sqrt(stiffness_n_per_m * mass_kg);
  Eigen::Vector3d effort_n = stiffness_n_per_m * (target_m - sample.position_m) +
                             damping_n_s_per_m * (target_velocity - sample.velocity_m_per_s);
  clampForce(effort_n, force_cap_n_);
  // The estimate follows the end-effector, so that a field that changes along the way does not
  // build up probe effort that a stop check would take for a stop.
  if (adapt) gravity_n_ += effort_n * (dt_s_ / kGravityFollow_s);
  target_m_ = target_m;
  Eigen::Vector3d force_n = gravity_n_ + effort_n;
  clampForce(force_n, max_force_n_);
  return force_n;
}

WorkspaceExplorer::Status WorkspaceExplorer::Impl::step(const ServoSample& sample,
                                                        Eigen::Vector3d& force_n) noexcept {
  if (state_ == Status::kIdle || state_ == Status::kDeviceFault) {
    force_n.setZero();
    return state_;
  }
  // Servo time from the sample's interval: a late or early tick counts as long as it was.
  const double dt_s =
      sample.interval_s > 0.0 && sample.interval_s < 1.0 ? sample.interval_s : period_s_;
  elapsed_s_ += dt_s;
  if (!sample.valid) {
    force_n = last_force_n_;
    invalid_s_ += dt_s;
    if (invalid_s_ > kMaxInvalidReadings_s) {
      force_n.setZero();
      last_force_n_.setZero();
      state_ = Status::kDeviceFault;
    }
    return state_;
  }
  invalid_s_ = 0.0;
  phase_s_ += dt_s;
  dt_s_ = dt_s;
  const double now_s = elapsed_s_;
  const double phase_s = phase_s_;
  filtered_velocity_ +=
      (sample.velocity_m_per_s - filtered_velocity_) * std::min(1.0, dt_s / kVelocityFilter_s);

  switch (state_) {
    case Status::kTransfer:
    case Status::kBackingOff: {
      Eigen::Vector3d desired_m, desired_velocity, desired_acceleration;
      move_.sample(phase_s, desired_m, desired_velocity, desired_acceleration);
      force_n = impedanceForce(sample, desired_m, desired_velocity, state_ == Status::kTransfer);
      if (phase_s < move_.duration_s()) break;
      // A heavy arm may still lag the end of a quick transfer: a probe started then would read
      // that lag as effort against a stop. Hold until it has caught up (briefly at most).
      const bool caught_up = (desired_m - sample.position_m).norm() <= 0.5 * options_.contact_lag_m;
      if (state_ == Status::kTransfer && !caught_up &&
          phase_s < move_.duration_s() + kTransferSettleMax_s) {
        break;
      }
      if (state_ == Status::kBackingOff) {
        ++current_;
        if (current_ == radial_count_) chooseBoundaryProbes();
        skipUnneededDirections();
        beginTransfer(desired_m);
      } else if (current_ >= directionCount()) {
        state_ = Status::kFinished;
      } else {
        probe_start_m_ = desired_m;
        phase_s_ = 0.0;
        last_progress_s_ = now_s;
        last_following_m_ = sample.position_m;
        contact_since_s_ = -1.0;
        followed_since_start_ = false;
        state_ = Status::kProbing;
      }
      break;
    }
    case Status::kProbing: {
      const Eigen::Vector3d& u = directions_[static_cast<std::size_t>(current_)];
      const Eigen::Vector3d target_m = probe_start_m_ + options_.probe_speed_m_per_s * phase_s * u;
      const double target_reach_m = (target_m - center_m_).dot(u);
      if (target_reach_m >= options_.max_reach_m) {
        ++open_directions_;
        finishDirection((sample.position_m - center_m_).dot(u), sample.position_m);
        force_n = impedanceForce(sample, sample.position_m, Eigen::Vector3d::Zero(), false);
        break;
      }
      const double lag_m = (target_m - sample.position_m).dot(u);
      const bool lagging = lag_m > 0.5 * options_.contact_lag_m;
      force_n = impedanceForce(sample, target_m, options_.probe_speed_m_per_s * u, !lagging);
      const double effort_n = (force_n - gravity_n_).dot(u);
      const double speed_m_per_s = filtered_velocity_.dot(u);
      const bool following = speed_m_per_s >= kStalledSpeedFraction * options_.probe_speed_m_per_s;
      if (following) {
        last_progress_s_ = now_s;
        last_following_m_ = sample.position_m;
        followed_since_start_ = true;
      }
      // A stop: the effort is up and the end-effector no longer follows, or it has fallen so
      // far behind that only a stop can hold it (a soft stop still yields to the probe). An
      // end-effector that has not moved at all since the probe began may be held by static
      // friction and an initial G_hat that is off by the friction of the initialization
      // (high-friction Omni: 0.23 N breakaway plus 0.1 N, above contact_force_n): only the probe's
      // full effort, far behind, tells a stop from that.
      const bool far_behind = lag_m > kFarBehindLags * options_.contact_lag_m;
      const bool stalled = effort_n >= contact_force_n_ && !following && followed_since_start_;
      if (stalled || far_behind) {
        if (contact_since_s_ < 0.0) contact_since_s_ = now_s;
        if (now_s - contact_since_s_ >= kContactConfirm_s && current_ >= radial_count_ &&
            !followed_since_start_) {
          // A boundary probe starts inside the radial stops' boundary: one that never got going
          // was held by static friction, not by a stop (sim:omni at high friction). It tells
          // nothing, and the radial triangle stays the boundary there.
          discardDirection(sample.position_m);
          force_n = impedanceForce(sample, sample.position_m, Eigen::Vector3d::Zero(), false);
        } else if (now_s - contact_since_s_ >= kContactConfirm_s) {
          longest_recognition_s_ = std::max(longest_recognition_s_, now_s - last_progress_s_);
          // The stop begins where the end-effector last kept up, not where a soft stop has
          // let it sink in meanwhile.
          finishDirection((last_following_m_ - center_m_).dot(u), sample.position_m);
          force_n = impedanceForce(sample, sample.position_m, Eigen::Vector3d::Zero(), false);
        }
      } else {
        contact_since_s_ = -1.0;
      }
      break;
    }
    case Status::kFinished:
    case Status::kAborted:
      force_n = impedanceForce(sample, target_m_, Eigen::Vector3d::Zero(), false);
      break;
    case Status::kIdle:
    case Status::kDeviceFault:
      force_n.setZero();
      break;
  }
  last_force_n_ = force_n;
  return state_;
}

void WorkspaceExplorer::Impl::abort() noexcept {
  if (state_ == Status::kIdle || state_ == Status::kDeviceFault) return;
  state_ = Status::kAborted;
}

ExploredWorkspace WorkspaceExplorer::Impl::workspace() const {
  if (state_ != Status::kFinished) {
    throw Error(std::string("workspace explorer: the exploration is ") + toString(state_) +
                ", not finished; its workspace is not known yet");
  }
  return exploredWorkspaceOf(center_m_, directions_, reach_m_);
}

// --- The public class: each call goes to the Impl ---------------------------------------------

WorkspaceExplorer::WorkspaceExplorer(const EstimationParameters& parameters,
                                     const DeviceSpecifications& specifications,
                                     const Options& options)
    : impl_(std::make_unique<Impl>(parameters, specifications, options)) {}

WorkspaceExplorer::~WorkspaceExplorer() = default;
WorkspaceExplorer::WorkspaceExplorer(WorkspaceExplorer&&) noexcept = default;
WorkspaceExplorer& WorkspaceExplorer::operator=(WorkspaceExplorer&&) noexcept = default;

void WorkspaceExplorer::start(const Eigen::Vector3d& center_m,
                              const Eigen::Vector3d& gravity_n) noexcept {
  impl_->start(center_m, gravity_n);
}

WorkspaceExplorer::Status WorkspaceExplorer::step(const ServoSample& sample,
                                                  Eigen::Vector3d& force_n) noexcept {
  return impl_->step(sample, force_n);
}

void WorkspaceExplorer::abort() noexcept { impl_->abort(); }

WorkspaceExplorer::Status WorkspaceExplorer::state() const noexcept { return impl_->state_; }

int WorkspaceExplorer::directionCount() const noexcept { return impl_->directionCount(); }

const std::vector<Eigen::Vector3d>& WorkspaceExplorer::directions() const noexcept {
  return impl_->directions_;
}

int WorkspaceExplorer::radialDirectionCount() const noexcept { return impl_->radial_count_; }

int WorkspaceExplorer::probedCount() const noexcept { return impl_->probed_; }

int WorkspaceExplorer::skippedCount() const noexcept { return impl_->skipped_count_; }

double WorkspaceExplorer::elapsed_s() const noexcept { return impl_->elapsed_s_; }

const Eigen::Vector3d& WorkspaceExplorer::gravity_n() const noexcept { return impl_->gravity_n_; }

const Eigen::Vector3d& WorkspaceExplorer::target_m() const noexcept { return impl_->target_m_; }

double WorkspaceExplorer::probeForceCap_n() const noexcept { return impl_->force_cap_n_; }

double WorkspaceExplorer::contactForce_n() const noexcept { return impl_->contact_force_n_; }

const std::vector<double>& WorkspaceExplorer::reach_m() const noexcept { return impl_->reach_m_; }

double WorkspaceExplorer::longestRecognition_s() const noexcept {
  return impl_->longest_recognition_s_;
}

int WorkspaceExplorer::openDirections() const noexcept { return impl_->open_directions_; }

ExploredWorkspace WorkspaceExplorer::workspace() const { return impl_->workspace(); }

const char* toString(WorkspaceExplorer::Status status) noexcept {
  switch (status) {
    case WorkspaceExplorer::Status::kIdle:
      return "idle";
    case WorkspaceExplorer::Status::kTransfer:
      return "transfer";
    case WorkspaceExplorer::Status::kProbing:
      return "probing";
    case WorkspaceExplorer::Status::kBackingOff:
      return "backing_off";
    case WorkspaceExplorer::Status::kFinished:
      return "finished";
    case WorkspaceExplorer::Status::kAborted:
      return "aborted";
    case WorkspaceExplorer::Status::kDeviceFault:
      return "device_fault";
  }
  return "unknown";
}

ExploredWorkspace exploredWorkspaceOf(const Eigen::Vector3d& center_m,
                                      const std::vector<Eigen::Vector3d>& directions,
                                      const std::vector<double>& reach_m) {
  if (directions.size() != reach_m.size()) {
    throw Error("explored workspace: " + std::to_string(directions.size()) + " directions but " +
                std::to_string(reach_m.size()) + " reaches");
  }
  std::vector<Eigen::Vector3d> probed_directions;
  std::vector<double> probed_reach_m;
  for (std::size_t i = 0; i < directions.size(); ++i) {
    if (!(reach_m[i] > 0.0)) continue;
    probed_directions.push_back(directions[i]);
    probed_reach_m.push_back(reach_m[i]);
  }
  return ExploredWorkspace(center_m, std::move(probed_directions), std::move(probed_reach_m));
}

std::string initializationClearanceProblem(const ExploredWorkspace& workspace,
                                           const Eigen::Vector3d& settled_m) {
  if (workspace.empty()) return {};
  const double depth_m = workspace.depth_m(settled_m);
  if (depth_m >= kInitializationClearance_m) return {};
  std::ostringstream message;
  message.precision(1);
  message << std::fixed << "the initialization settled " << 1e3 * std::max(depth_m, 0.0)
          << " mm from a stop the exploration found (at least " << 1e3 * kInitializationClearance_m
          << " mm are needed): the end-effector may have rested on it, so G_hat_0 (eq. 7) is "
             "wrong; initialize again further inside the workspace";
  return message.str();
}

}  // namespace autograv
