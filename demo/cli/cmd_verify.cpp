// autograv verify: does a map hold a released end-effector still? Drift with the decorator on,
// next to the same test with compensation off, on a simulated device.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "autograv/device/gravity_compensated_device.h"
#include "autograv/error.h"
#include "autograv/map/map_io.h"
#include "autograv/sim/simulated_driver.h"
#include "cli_support.h"
#include "commands.h"
#include "friction_option.h"

namespace autograv::cli {

namespace {

struct VerifyOptions {
  std::string map_path;
  std::string device = "sim:omni";
  std::uint64_t seed = 1;
  sim::FrictionLevel friction = sim::FrictionLevel::kTypical;
  int points = 100;
  double duration_s = 1.0;
  double max_drift_ratio = 0.1;
  std::string report_path;
  bool allow_model_mismatch = false;
};

/// Sits between whoever commands forces and the device, and remembers the largest force that
/// actually went to the device: the check "never above the device's maximum" is made on what
/// was sent, not on what the decorator meant to send.
class ForceMeter final : public HapticDevice {
 public:
  explicit ForceMeter(std::shared_ptr<HapticDevice> inner) : inner_(std::move(inner)) {}
  bool open() override { return inner_->open(); }
  bool close() override { return inner_->close(); }
  bool calibrate(bool force) override { return inner_->calibrate(force); }
  bool getPosition(Eigen::Vector3d& position_m) override { return inner_->getPosition(position_m); }
  bool getLinearVelocity(Eigen::Vector3d& velocity_m_per_s) override {
    return inner_->getLinearVelocity(velocity_m_per_s);
  }
  bool getUserSwitch(int index, bool& pressed) override {
    return inner_->getUserSwitch(index, pressed);
  }
  bool setForce(const Eigen::Vector3d& force_n) override {
    max_force_n_ = std::max(max_force_n_, force_n.norm());
    return inner_->setForce(force_n);
  }
  const DeviceSpecifications& specifications() const override { return inner_->specifications(); }
  /// Unit: [N]
  double maxForce_n() const { return max_force_n_; }

 private:
  std::shared_ptr<HapticDevice> inner_;
  double max_force_n_ = 0.0;
};

struct Stats {
  double median = 0.0;
  double p90 = 0.0;
  double max = 0.0;
};

Stats statistics(std::vector<double> values) {
  Stats stats;
  if (values.empty()) return stats;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  stats.median = n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
  stats.p90 = values[std::min(n - 1, static_cast<std::size_t>(std::ceil(0.9 * n)) - 1)];
  stats.max = values.back();
  return stats;
}

/// Puts the end-effector at rest at `start_m`, lets go of it (no hand, zero application force)
/// and runs the servo loop through `device` for `ticks` periods. Returns the drift [m].
double releaseAndMeasure(sim::SimulatedDevice& simulated, HapticDevice& device,
                         const Eigen::Vector3d& start_m, int ticks, double period_s) {
  simulated.resetState(start_m);
  simulated.hand().release();
  const Eigen::Vector3d released_at = simulated.truePosition_m();
  Eigen::Vector3d position_m;
  for (int k = 0; k < ticks; ++k) {
    device.getPosition(position_m);  // what an application does each tick
    device.setForce(Eigen::Vector3d::Zero());
    simulated.advance(period_s);
  }
  return (simulated.truePosition_m() - released_at).norm();
}

void runVerifyCommand(const VerifyOptions& options) {
  const DeviceHandle handle = openDevice(options.device, options.seed, options.friction);
  if (!handle.simulation) {
    throw Error(
        "verify places the end-effector at its test points by simulation, so it needs a "
        "simulated device; on " +
        options.device + " run `autograv check`, which measures the map against the device itself");
  }
  const std::shared_ptr<sim::SimulatedDevice>& simulated = handle.simulation;
  const DeviceSpecifications& specs = handle.device->specifications();
  MapLoadOptions load;
  load.expected_device_model = specs.model_name;
  load.allow_model_mismatch = options.allow_model_mismatch;
  auto map = std::make_shared<const GravityMap>(loadMap(options.map_path, load));
  const WorkspaceGrid& grid = map->grid();
  const double period_s = map->metadata().parameters.servo_period_s;
  const int ticks = std::max(1, static_cast<int>(std::lround(options.duration_s / period_s)));

  auto meter = std::make_shared<ForceMeter>(handle.device);
  CompensationOptions compensation;
  compensation.servo_period_s = period_s;
  GravityCompensatedDevice decorated(meter, compensation);
  decorated.publishMap(map, options.allow_model_mismatch);

  // Seeded points inside the grid (sim::Random: the same points on every platform).
  sim::Random random(options.seed);
  std::vector<Eigen::Vector3d> points(static_cast<std::size_t>(options.points));
  for (auto& point : points) {
    for (int axis = 0; axis < 3; ++axis) {
      point[axis] = grid.minCorner_m()[axis] + random.uniform() * grid.side_m();
    }
  }

  std::printf(
      "verify %s on %s (friction %s): %d points inside the grid, released for %.2f s, seed %llu\n",
      options.map_path.c_str(), specs.model_name.c_str(), sim::toString(options.friction),
      options.points, ticks * period_s, static_cast<unsigned long long>(options.seed));
  std::fflush(stdout);

  // The decorator ramps compensation in, as it would in an application; hold the end-effector
  // by hand at the grid centre meanwhile, so that every release starts at full compensation.
  simulated->resetState(grid.center_m());
  simulated->hand().grab(grid.center_m());
  const int ramp_ticks =
      static_cast<int>(std::lround(compensation.ramp_duration_s / period_s)) + 10;
  Eigen::Vector3d position_m;
  for (int k = 0; k < ramp_ticks; ++k) {
    decorated.getPosition(position_m);
    decorated.setForce(Eigen::Vector3d::Zero());
    simulated->advance(period_s);
  }
  if (decorated.compensationLevel() != 1.0) {
    throw Error(std::string("verify: compensation did not ramp in (fault: ") +
                toString(decorated.lastFault()) + ")");
  }

  ProgressBar progress("release");
  std::vector<double> drift_on_m;
  std::vector<double> drift_off_m;
  const int total = 2 * options.points;
  for (const Eigen::Vector3d& point : points) {
    drift_on_m.push_back(releaseAndMeasure(*simulated, decorated, point, ticks, period_s));
    progress.update(static_cast<int>(drift_on_m.size()), total, "compensation on");
  }
  const double max_force_on_n = meter->maxForce_n();
  const std::uint64_t faults = decorated.faultCount();
  const std::uint64_t clamps = decorated.clampCount();
  for (const Eigen::Vector3d& point : points) {
    drift_off_m.push_back(releaseAndMeasure(*simulated, *meter, point, ticks, period_s));
    progress.update(options.points + static_cast<int>(drift_off_m.size()), total,
                    "compensation off");
  }
  progress.finish();

  const Stats on = statistics(drift_on_m);
  const Stats off = statistics(drift_off_m);
  const double ratio = off.median > 0.0 ? on.median / off.median : INFINITY;
  const bool force_ok = max_force_on_n <= specs.max_linear_force_n * (1.0 + 1e-12);
  const bool drift_ok = ratio <= options.max_drift_ratio;

  std::printf("\n%-26s %16s %17s\n", "", "compensation on", "compensation off");
  std::printf("%-26s %16.3f %17.3f\n", "drift median [mm]", on.median * 1e3, off.median * 1e3);
  std::printf("%-26s %16.3f %17.3f\n", "drift 90th percentile [mm]", on.p90 * 1e3, off.p90 * 1e3);
  std::printf("%-26s %16.3f %17.3f\n", "drift max [mm]", on.max * 1e3, off.max * 1e3);
  std::printf("%-26s %16.3f %17s\n", "max force sent [N]", max_force_on_n, "0 (by design)");
  std::printf("\n%-26s %.2f N  %s\n", "device force limit", specs.max_linear_force_n,
              force_ok ? "ok, never exceeded" : "EXCEEDED");
  std::printf("%-26s %.4f (limit %.3g)  %s\n", "drift median on / off", ratio,
              options.max_drift_ratio, drift_ok ? "ok" : "TOO HIGH");
  std::string fault_kinds;
  for (int kind = 1; kind < kServoFaultKinds; ++kind) {
    const auto fault = static_cast<ServoFault>(kind);
    if (decorated.faultCount(fault) == 0) continue;
    fault_kinds += std::string(fault_kinds.empty() ? " (" : ", ") + toString(fault) + " " +
                   std::to_string(decorated.faultCount(fault));
  }
  if (!fault_kinds.empty()) fault_kinds += ")";
  std::printf("%-26s %llu fault ticks%s, %llu clamps\n", "decorator",
              static_cast<unsigned long long>(faults), fault_kinds.c_str(),
              static_cast<unsigned long long>(clamps));

  nlohmann::json point_list = nlohmann::json::array();
  for (std::size_t i = 0; i < points.size(); ++i) {
    point_list.push_back({{"start_m", {points[i].x(), points[i].y(), points[i].z()}},
                          {"drift_mm", drift_on_m[i] * 1e3},
                          {"drift_off_mm", drift_off_m[i] * 1e3}});
  }
  nlohmann::json fault_counts = nlohmann::json::object();
  for (int kind = 1; kind < kServoFaultKinds; ++kind) {
    const auto fault = static_cast<ServoFault>(kind);
    fault_counts[toString(fault)] = decorated.faultCount(fault);
  }
  const nlohmann::json report = {{"map", options.map_path},
                                 {"device", specs.model_name},
                                 {"map_device", map->metadata().device_model},
                                 {"seed", options.seed},
                                 {"friction", sim::toString(options.friction)},
                                 {"points", options.points},
                                 {"duration_s", ticks * period_s},
                                 {"servo_period_s", period_s},
                                 {"ramp_duration_s", compensation.ramp_duration_s},
                                 {"drift_median_mm", on.median * 1e3},
                                 {"drift_p90_mm", on.p90 * 1e3},
                                 {"drift_max_mm", on.max * 1e3},
                                 {"drift_off_median_mm", off.median * 1e3},
                                 {"drift_off_p90_mm", off.p90 * 1e3},
                                 {"drift_off_max_mm", off.max * 1e3},
                                 {"drift_ratio", ratio},
                                 {"max_drift_ratio", options.max_drift_ratio},
                                 {"max_force_sent_n", max_force_on_n},
                                 {"max_linear_force_n", specs.max_linear_force_n},
                                 {"clamp_count", clamps},
                                 {"fault_count", faults},
                                 {"faults", fault_counts},
                                 {"force_within_limit", force_ok},
                                 {"drift_ratio_ok", drift_ok},
                                 {"pass", force_ok && drift_ok},
                                 {"releases", point_list}};
  writeJsonReport(options.report_path, report);
  if (!(force_ok && drift_ok)) {
    std::printf("\nFAIL\n");
    throw CLI::RuntimeError(1);
  }
  std::printf("\nPASS\n");
}

void addVerifyCommand(CLI::App& app) {
  auto options = std::make_shared<VerifyOptions>();
  CLI::App* command = app.add_subcommand(
      "verify",
      "Release the end-effector at seeded points with the map's compensation on, then off, and "
      "report the drift");
  command->add_option("map", options->map_path, "Map file (JSON)")->required();
  addDeviceOption(*command, options->device);
  command->add_option("--seed", options->seed, "Seed of the points and the device noise")
      ->capture_default_str();
  addFrictionOption(*command, options->friction);
  command->add_option("--points", options->points, "Release points")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  command->add_option("--duration-s", options->duration_s, "Time after each release [s]")
      ->check(CLI::Range(0.001, 60.0))
      ->capture_default_str();
  command
      ->add_option("--max-drift-ratio", options->max_drift_ratio,
                   "Fail when drift median on / off exceeds this")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command->add_option("--report", options->report_path, "Write a JSON report here");
  command->add_flag("--allow-model-mismatch", options->allow_model_mismatch,
                    "Use a map made for another device model");
  command->callback([options] { runVerifyCommand(*options); });
}

}  // namespace

AUTOGRAV_REGISTER_COMMAND(50, addVerifyCommand);

}  // namespace autograv::cli
