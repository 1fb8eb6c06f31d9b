#include "autograv/maintenance/spot_measurement.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "autograv/device/servo_sample.h"
#include "autograv/error.h"

namespace autograv {

bool isChangeOfWeight(const Eigen::Vector3d& change_n, const Eigen::Vector3d& up) noexcept {
  constexpr double kCosine = 0.9;  // about 25 degrees
  return std::abs(change_n.dot(up.normalized())) >= kCosine * change_n.norm();
}

std::vector<int> centralVertices(const WorkspaceGrid& grid, int count) {
  std::vector<int> order(static_cast<std::size_t>(grid.vertexCount()));
  std::iota(order.begin(), order.end(), 0);
  const Eigen::Vector3d center_m = grid.center_m();
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    // Compare in whole cells squared so that equal distances tie exactly.
    const auto cells = [&](int index) {
      const Eigen::Vector3d offset =
          (grid.vertexPosition(index) - center_m).cwiseQuotient(grid.spacing_m());
      return std::lround(4.0 * offset.squaredNorm());
    };
    return cells(a) < cells(b);
  });
  order.resize(static_cast<std::size_t>(std::clamp(count, 0, grid.vertexCount())));
  return order;
}

SpotMeasurement measureAtVertices(HapticDevice& device, TickSource& ticks, const GravityMap& map,
                                  const std::vector<int>& vertices,
                                  const SpotMeasurementOptions& options) {
  if (vertices.empty()) throw Error("spot measurement: no vertex to measure at");
  AutoCalibrator::Options calibrator_options;
  // Each vertex starts from its neighbour's result, not from an extrapolation across the map.
  calibrator_options.extrapolate_initial_estimate = false;
  AutoCalibrator calibrator(map.grid(), options.parameters,
                            device.specifications().max_linear_force_n, calibrator_options);
  calibrator.visitOnly(vertices);

  const ServoSample first = readServoSample(device);
  if (!first.valid) {
    throw Error("spot measurement: the device '" + device.specifications().model_name +
                "' gives no valid position (is it open and homed?)");
  }
  calibrator.start(first.position_m, map.gravityAt(first.position_m) + options.initial_offset_n);

  SpotMeasurement result;
  const double period_s = options.parameters.servo_period_s;
  const long max_ticks = static_cast<long>(std::ceil(options.timeout_s / period_s));
  const long progress_ticks =
      std::max(1L, static_cast<long>(std::lround(options.progress_period_s / period_s)));
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  AutoCalibrator::Status status = calibrator.state();
  long tick = 0;
  for (; tick < max_ticks; ++tick) {
    if (!ticks.waitForNextTick()) break;
    status = calibrator.step(readServoSample(device), force_n);
    device.setForce(force_n);
    if (options.on_progress &&
        (tick % progress_ticks == 0 || status == AutoCalibrator::Status::kVertexFinished)) {
      options.on_progress(calibrator);
    }
    if (status == AutoCalibrator::Status::kFinished ||
        status == AutoCalibrator::Status::kDeviceFault) {
      break;
    }
  }
  device.setForce(Eigen::Vector3d::Zero());
  result.status = calibrator.state();
  result.timed_out = tick >= max_ticks;
  result.seconds = calibrator.elapsed_s();
  for (int vertex : vertices) {
    result.vertices.push_back(vertex);
    result.estimates.push_back(calibrator.vertices()[static_cast<std::size_t>(vertex)]);
    result.map_gravity_n.push_back(map.vertices()[static_cast<std::size_t>(vertex)].gravity_n);
  }
  return result;
}

}  // namespace autograv
