// CalibrationWizard: the public class, which hands every call to its Impl, and the Impl's
// construction: the configuration check and the buffers the servo half fills (so that it never
// allocates). The halves are wizard_servo.cpp and wizard_service.cpp.
#include "autograv/wizard/calibration_wizard.h"

#include <cmath>
#include <cstddef>
#include <iterator>
#include <sstream>
#include <utility>

#include "autograv/error.h"
#include "autograv/estimation/impedance_hold.h"
#include "autograv/estimation/vertex_estimator.h"
#include "core/wizard/wizard_impl.h"

namespace autograv {

using wizard::eventBit;

namespace {

void requirePositive(double value, const char* field, const char* unit) {
  if (std::isfinite(value) && value > 0.0) return;
  std::ostringstream message;
  message << "calibration wizard: WizardConfig::" << field << " must be a positive number in "
          << unit << ", got " << value;
  throw Error(message.str());
}

/// The run's grid, refused in the terms of WizardConfig (WorkspaceGrid speaks of its own).
WorkspaceGrid wizardGrid(const WizardConfig& config) {
  if (!config.grid_center_m.allFinite()) {
    throw Error("calibration wizard: WizardConfig::grid_center_m must be finite (metres)");
  }
  if (!(config.grid_size_m.allFinite() && config.grid_size_m.minCoeff() > 0.0)) {
    std::ostringstream message;
    message << "calibration wizard: WizardConfig::grid_size_m must have three positive extents in "
               "metres (e.g. 0.06 each), got "
            << config.grid_size_m.transpose();
    throw Error(message.str());
  }
  try {
    return WorkspaceGrid(config.grid_center_m, config.grid_size_m, config.grid_resolution);
  } catch (const Error& error) {
    throw Error(std::string("calibration wizard: WizardConfig::grid_resolution: ") + error.what());
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
      hold_law_(ImpedanceHold::from(config_.parameters, VertexEstimator::kMinGravityN)) {
  if (!device) throw Error("calibration wizard: the device is null");
  if (config_.map_path.empty()) {
    throw Error(
        "calibration wizard: no map path; say where the map should be saved "
        "(WizardConfig::map_path)");
  }
  requirePositive(config_.centre_tolerance_m, "centre_tolerance_m", "m");
  requirePositive(config_.release_patience_s, "release_patience_s", "s");
  requirePositive(config_.verify_settle_s, "verify_settle_s", "s");
  requirePositive(config_.verify_release_s, "verify_release_s", "s");
  requirePositive(config_.verify_drift_limit_m, "verify_drift_limit_m", "m");
  requirePositive(config_.min_workspace_extent_m, "min_workspace_extent_m", "m");
  if (config_.lookup_refinement < 1) {
    throw Error("calibration wizard: WizardConfig::lookup_refinement must be at least 1, got " +
                std::to_string(config_.lookup_refinement));
  }
  requirePositive(config_.parameters.servo_period_s,
                  "parameters.servo_period_s (EstimationParameters::servo_period_s)", "s");
  if (!(config_.field_ramp_s >= 0.0) || !(config_.compensation_ramp_s >= 0.0)) {
    throw Error(
        "calibration wizard: WizardConfig::field_ramp_s and WizardConfig::compensation_ramp_s "
        "must be >= 0 s");
  }
  if (config_.verify_points < 0 || config_.verify_points > kMaxVerifyPoints) {
    throw Error("calibration wizard: WizardConfig::verify_points must be between 0 and " +
                std::to_string(kMaxVerifyPoints));
  }
  CompensationOptions compensation;
  // Without a clock the wizard runs in servo ticks of exactly the calibration period, also on a
  // simulated device that runs faster than real time; with one, it and the compensation read the
  // loop's time from it.
  compensation.clock =
      config_.clock ? config_.clock
                    : std::make_shared<FixedPeriodServoClock>(config_.parameters.servo_period_s);
  compensation.ramp_duration_s = config_.compensation_ramp_s;
  compensation.enabled = false;  // the calibration itself must run uncompensated
  device_ = std::make_shared<GravityCompensatedDevice>(std::move(device), compensation);

  const auto count = static_cast<std::size_t>(grid_.vertexCount());
  mirror_.resize(count);
  for (auto& vertex : mirror_) {
    vertex.history.reserve(static_cast<std::size_t>(config_.parameters.max_iterations));
  }
  copy_pending_.assign(count, 0);
  restored_.assign(count, 0);
  verify_vertices_.reserve(kMaxVerifyPoints);
  verify_targets_m_.reserve(kMaxVerifyPoints);
  centre_m_ = config_.grid_center_m;
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
