// CalibrationWizard: the public class, which hands every call to its Impl, and the Impl's
// construction: the configuration check and the buffers the servo half fills (so that it never
// allocates). The halves are wizard_servo.cpp and wizard_service.cpp.
#include "autograv/wizard/calibration_wizard.h"

#include <cmath>
#include <cstddef>
#include <iterator>
#include <optional>
#include <sstream>
#include <utility>

#include "autograv/error.h"
#include "autograv/estimation/impedance_hold.h"
#include "core/estimation/vertex_estimator.h"
#include "core/wizard/wizard_impl.h"

namespace autograv {

using wizard::eventBit;

bool wizard::sameExplorerOptions(const WorkspaceExplorer::Options& a,
                                 const WorkspaceExplorer::Options& b) noexcept {
  // A field added to the options must be compared here too.
  // Three ints, padded to a double's alignment, then the doubles and the vector.
  static_assert(sizeof(WorkspaceExplorer::Options) ==
                    2 * sizeof(double) + 9 * sizeof(double) + sizeof(std::vector<Eigen::Vector3d>),
                "compare every field of WorkspaceExplorer::Options");
  return a.directions == b.directions && a.radial_directions == b.radial_directions &&
         a.boundary_directions == b.boundary_directions &&
         a.boundary_candidates == b.boundary_candidates &&
         a.boundary_bulge_m == b.boundary_bulge_m &&
         a.boundary_clearance_m == b.boundary_clearance_m &&
         a.probe_speed_m_per_s == b.probe_speed_m_per_s && a.start_fraction == b.start_fraction &&
         a.max_reach_m == b.max_reach_m && a.back_off_m == b.back_off_m &&
         a.contact_force_n == b.contact_force_n && a.contact_lag_m == b.contact_lag_m &&
         a.max_move_acceleration_m_per_s2 == b.max_move_acceleration_m_per_s2;
}

namespace {

/// The extents of the box that only sizes the buffers of a run whose grid is fitted to the
/// explored workspace (replaced once the workspace is known). Unit: [m]
constexpr double kPlaceholderBox_m = 0.06;

void requirePositive(double value, const char* field, const char* unit) {
  if (std::isfinite(value) && value > 0.0) return;
  std::ostringstream message;
  message << "calibration wizard: WizardConfig::" << field << " must be a positive number in "
          << unit << ", got " << value;
  throw Error(message.str());
}

/// The run's grid, refused in the terms of WizardConfig (WorkspaceGrid speaks of its own): the box
/// advanced.box_size_m about centre_m, or a placeholder of the same resolution when the grid is
/// fitted to the explored workspace.
WorkspaceGrid wizardGrid(const WizardConfig& config) {
  if (!config.centre_m.allFinite()) {
    throw Error("calibration wizard: WizardConfig::centre_m must be finite (metres)");
  }
  const std::optional<Eigen::Vector3d>& box_m = config.advanced.box_size_m;
  if (box_m && !(box_m->allFinite() && box_m->minCoeff() > 0.0)) {
    std::ostringstream message;
    message << "calibration wizard: WizardConfig::advanced.box_size_m must have three positive "
               "extents in metres (e.g. 0.06 each), got "
            << box_m->transpose() << "; leave it empty to fit the grid to the explored workspace";
    throw Error(message.str());
  }
  try {
    return WorkspaceGrid(config.centre_m,
                         box_m ? *box_m : Eigen::Vector3d::Constant(kPlaceholderBox_m),
                         config.grid_resolution);
  } catch (const Error& error) {
    throw Error(std::string("calibration wizard: WizardConfig::grid_resolution: ") + error.what());
  }
}

/// Refuses a setting that `config` gives but this run would not use: a run that does not explore
/// judges no workspace, a run without release tests has none to time.
void refuseUnusedSettings(const WizardConfig& config) {
  const WizardConfig::Advanced defaults;
  const WizardConfig::Advanced& advanced = config.advanced;
  if (!advanced.explore) {
    if (!advanced.box_size_m) {
      throw Error(
          "calibration wizard: WizardConfig::advanced.explore = false needs "
          "WizardConfig::advanced.box_size_m: without the exploration there is no workspace to "
          "fit the grid to. Give the box to measure (well inside the workspace: every vertex is "
          "visited where it is), or leave advanced.explore on");
    }
    const auto unused = [](const char* field) {
      throw Error(std::string("calibration wizard: WizardConfig::advanced.") + field +
                  " is set, but WizardConfig::advanced.explore is false: nothing is explored, so "
                  "it would be ignored. Leave it at its default, or explore");
    };
    if (!(advanced.min_workspace_extent_m == defaults.min_workspace_extent_m)) {
      unused("min_workspace_extent_m");
    }
    if (!wizard::sameExplorerOptions(advanced.explorer, defaults.explorer)) unused("explorer");
  }
  if (config.verify_points == 0) {
    const auto unused = [](const char* field) {
      throw Error(std::string("calibration wizard: WizardConfig::advanced.") + field +
                  " is set, but WizardConfig::verify_points is 0: Verify is skipped, so it would "
                  "be ignored. Leave it at its default, or ask for release tests");
    };
    if (!(advanced.verify_settle_s == defaults.verify_settle_s)) unused("verify_settle_s");
    if (!(advanced.verify_release_s == defaults.verify_release_s)) unused("verify_release_s");
    if (!(advanced.verify_drift_limit_m == defaults.verify_drift_limit_m)) {
      unused("verify_drift_limit_m");
    }
  }
}

}  // namespace

const char* toString(WizardStep step) noexcept {
  // In the order of WizardStep.
  static constexpr const char* kNames[] = {
      "check",  "centre", "release", "explore", "auto_calibration", "review", "save",
      "verify", "done",   "aborted", "fault"};
  static_assert(std::size(kNames) == static_cast<std::size_t>(WizardStep::kFault) + 1,
                "one name per WizardStep");
  const auto index = static_cast<std::size_t>(step);
  return index < std::size(kNames) ? kNames[index] : "unknown";
}

CalibrationWizard::Impl::Impl(std::shared_ptr<HapticDevice> device, WizardConfig config)
    : config_(std::move(config)),
      grid_(wizardGrid(config_)),
      checkpoint_path_(config_.map_path + ".partial"),
      hold_law_(ImpedanceHold::from(config_.advanced.parameters, VertexEstimator::kMinGravityN)) {
  if (!device) throw Error("calibration wizard: the device is null");
  if (config_.map_path.empty()) {
    throw Error(
        "calibration wizard: no map path; say where the map should be saved "
        "(WizardConfig::map_path)");
  }
  const WizardConfig::Advanced& advanced = config_.advanced;
  requirePositive(advanced.centre_tolerance_m, "advanced.centre_tolerance_m", "m");
  requirePositive(advanced.release_patience_s, "advanced.release_patience_s", "s");
  requirePositive(advanced.verify_settle_s, "advanced.verify_settle_s", "s");
  requirePositive(advanced.verify_release_s, "advanced.verify_release_s", "s");
  requirePositive(advanced.verify_drift_limit_m, "advanced.verify_drift_limit_m", "m");
  requirePositive(advanced.min_workspace_extent_m, "advanced.min_workspace_extent_m", "m");
  if (advanced.lookup_refinement < 1) {
    throw Error(
        "calibration wizard: WizardConfig::advanced.lookup_refinement must be at least 1, got " +
        std::to_string(advanced.lookup_refinement));
  }
  requirePositive(advanced.parameters.servo_period_s,
                  "advanced.parameters.servo_period_s (EstimationParameters::servo_period_s)", "s");
  if (!(advanced.field_ramp_s >= 0.0)) {
    throw Error("calibration wizard: WizardConfig::advanced.field_ramp_s must be >= 0 s");
  }
  if (config_.verify_points < 0 || config_.verify_points > kMaxVerifyPoints) {
    throw Error("calibration wizard: WizardConfig::verify_points must be between 0 and " +
                std::to_string(kMaxVerifyPoints));
  }
  refuseUnusedSettings(config_);
  // The compensation reads the servo time servoTick() read from the run's clock on that tick
  // (without a clock: the readings of a clock that ticks exactly every servo period, so that it
  // and the wizard agree also on a simulated device that runs faster than real time). Its other
  // options are the decorator's defaults, those of an application that opens a map.
  CompensationOptions compensation;
  tick_clock_ = std::make_shared<wizard::TickClock>();
  compensation.clock = tick_clock_;
  compensation.enabled = false;  // the calibration itself must run uncompensated
  // Below the compensation, what reaches the driver is recorded: WizardStatus::force.
  sent_force_ = std::make_shared<wizard::SentForce>(std::move(device));
  device_ = std::make_shared<GravityCompensatedDevice>(sent_force_, compensation);

  const auto count = static_cast<std::size_t>(grid_.vertexCount());
  mirror_.resize(count);
  for (auto& vertex : mirror_) {
    vertex.history.reserve(static_cast<std::size_t>(advanced.parameters.max_iterations));
  }
  copy_pending_.assign(count, 0);
  restored_.assign(count, 0);
  verify_vertices_.reserve(kMaxVerifyPoints);
  verify_targets_m_.reserve(kMaxVerifyPoints);
  centre_m_ = config_.centre_m;
}

CalibrationWizard::Impl::~Impl() {
  if (opened_) device_->close();  // the inner device sends zero force first
}

// --- The public class: each call goes to the Impl ---------------------------------------------

CalibrationWizard::CalibrationWizard(std::shared_ptr<HapticDevice> device, WizardConfig config)
    : impl_(std::make_unique<Impl>(std::move(device), std::move(config))) {}

CalibrationWizard::~CalibrationWizard() = default;

void CalibrationWizard::post(WizardEvent event) noexcept {
  impl_->events_.fetch_or(eventBit(static_cast<int>(event)), std::memory_order_acq_rel);
}

WizardStep CalibrationWizard::servoTick() noexcept { return impl_->servoTick(); }

void CalibrationWizard::service() { impl_->service(); }

WizardStatus CalibrationWizard::status() const { return impl_->status(); }

WizardStep CalibrationWizard::step() const noexcept { return impl_->step(); }

bool CalibrationWizard::finished() const { return impl_->finished(); }

std::vector<VertexEstimate> CalibrationWizard::vertices() const {
  return impl_->mirrorCopy(nullptr);
}

std::shared_ptr<const GravityMap> CalibrationWizard::savedMap() const { return impl_->saved_map_; }

const WizardConfig& CalibrationWizard::config() const noexcept { return impl_->config_; }

const WorkspaceGrid& CalibrationWizard::grid() const noexcept { return impl_->grid_; }

const ExploredWorkspace& CalibrationWizard::workspace() const noexcept { return impl_->workspace_; }

GravityCompensatedDevice& CalibrationWizard::device() noexcept { return *impl_->device_; }

const std::string& CalibrationWizard::checkpointPath() const noexcept {
  return impl_->checkpoint_path_;
}

}  // namespace autograv
