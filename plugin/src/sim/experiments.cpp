#include "sim/experiments.h"

#include <algorithm>
#include <chrono>
#include <utility>

#include "autograv/compensation/gravity_compensated_device.h"
#include "autograv/error.h"
#include "autograv/estimation/pd_design.h"
#include "autograv/map/map_summary.h"
#include "autograv/map/workspace_grid.h"

namespace autograv::sim {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

SweepRow runSweepCell(const FrictionSweepOptions& options, const std::string& name,
                      FrictionLevel friction, EstimationMethod method, int seed) {
  SweepRow row;
  row.device = name;
  row.friction = friction;
  row.method = method;
  row.seed = seed;
  std::shared_ptr<SimulatedDevice> device =
      openSimulatedDevice(name, static_cast<std::uint64_t>(seed), friction);
  try {
    DefaultCubeOptions cube;
    cube.resolution = options.grid;
    cube.method = method;
    cube.servo_timing = options.servo_timing;
    cube.servo_timing_seed = static_cast<std::uint64_t>(seed);
    const DefaultCubeCalibration calibration = calibrateDefaultCube(*device, cube);
    row.calibration = calibrationFigures(calibration, *device);
    VerificationOptions verification;
    verification.points = options.points;
    verification.servo_timing = options.servo_timing;
    verification.servo_timing_seed = static_cast<std::uint64_t>(seed);
    verification.compare_uncompensated = false;
    row.residual_n =
        verifyMapOnSimulatedDevice(device, calibration.map, verification).residual_force_n;
  } catch (const Error& error) {
    row.failure = error.what();
  }
  return row;
}

}  // namespace

std::unique_ptr<SimulatedDevice> openSimulatedDevice(const std::string& name, std::uint64_t seed,
                                                     FrictionLevel friction,
                                                     const SimulatedUnit& unit) {
  auto device = makeSimulatedDevice(name, seed, friction, unit);
  if (!device->open()) throw Error("device " + name + ": open() failed");
  if (!device->calibrate()) throw Error("device " + name + ": calibrate() failed");
  return device;
}

EstimationParameters toolParameters(const SimulatedDevice& device, EstimationMethod method) {
  EstimationParameters parameters =
      method == EstimationMethod::kDither ? EstimationParameters{} : EstimationParameters::paper();
  parameters.k0_n_per_m = defaultInitializationStiffness(device.specifications());
  return parameters;
}

CalibrationRunOptions defaultCalibrationOptions(const SimulatedDevice& device,
                                                int grid_resolution) {
  CalibrationRunOptions run;
  run.grid_from_workspace = true;
  run.initialization_center_m = device.workspaceCenter_m();
  run.grid_resolution = Eigen::Vector3i::Constant(grid_resolution);
  run.parameters = toolParameters(device);
  return run;
}

DefaultCubeCalibration calibrateDefaultCube(SimulatedDevice& device,
                                            const DefaultCubeOptions& options) {
  const double side_m = defaultGridSide_m(device.specifications().workspace_radius_m);
  const WorkspaceGrid grid(device.workspaceCenter_m(), side_m, options.resolution);
  CalibrationRunOptions run;
  run.explore = options.explore;
  run.grid_center_m = grid.center_m();
  run.grid_size_m = grid.size_m();
  run.grid_resolution = grid.resolution();
  run.calibrator.extrapolate_initial_estimate = options.extrapolate_initial_estimate;
  run.parameters = toolParameters(device, options.method);
  run.servo_timing = options.servo_timing;
  run.servo_timing_seed = options.servo_timing_seed;
  const auto start = Clock::now();
  DefaultCubeCalibration calibration;
  calibration.run = runSimulatedCalibration(device, run);
  calibration.wall_s = secondsSince(start);
  MapMetadata metadata;
  metadata.device_model = device.specifications().model_name;
  metadata.parameters = run.parameters;
  metadata.lookup_refinement = lookupRefinementFor(grid, kDefaultLookupRefinement);
  metadata.field_model = kDefaultFieldModel;
  calibration.map = std::make_shared<const GravityMap>(grid, calibration.run.vertices, metadata);
  return calibration;
}

CalibrationFigures calibrationFigures(const DefaultCubeCalibration& calibration,
                                      const SimulatedDevice& device) {
  const MapSummary summary = summarizeVertices(calibration.run.vertices);
  CalibrationFigures figures;
  figures.wall_s = calibration.wall_s;
  figures.simulated_s = calibration.run.simulated_seconds;
  figures.servo_loop = calibration.run.servo_loop;
  figures.vertices = summary.vertices;
  figures.converged = summary.converged;
  figures.seconds_per_vertex = summary.secondsPerVertex();
  figures.iterations_median = summary.iterations.median;
  figures.iterations_max = summary.iterations.max;
  figures.accuracy = measureAccuracy(*calibration.map, device, 1000);
  return figures;
}

std::vector<SweepRow> runFrictionSweep(const FrictionSweepOptions& options) {
  const std::vector<std::string> devices = simulatedDeviceNames();
  const std::vector<std::string> levels = frictionLevelNames();
  const auto progress = [&](int done, int total, const std::string& cell) {
    if (options.on_progress) options.on_progress(done, total, cell);
  };
  std::vector<SweepRow> rows;
  const int total =
      static_cast<int>(devices.size() * levels.size() * options.methods.size()) * options.seeds;
  for (const std::string& name : devices) {
    for (const std::string& level : levels) {
      for (const EstimationMethod method : options.methods) {
        for (int seed = 1; seed <= options.seeds; ++seed) {
          progress(static_cast<int>(rows.size()), total,
                   name + " " + level + " " + toString(method) + " seed " + std::to_string(seed));
          rows.push_back(runSweepCell(options, name, parseFrictionLevel(level), method, seed));
        }
      }
    }
  }
  progress(total, total, "done");
  return rows;
}

SweepRow foldSeeds(const std::vector<const SweepRow*>& seeds) {
  SweepRow folded = *seeds.front();
  CalibrationFigures& f = folded.calibration;
  f = CalibrationFigures{};
  std::vector<double> iteration_medians, residual_medians;
  double rms_n = 0.0, rms_rel = 0.0;
  int ran = 0;
  for (const SweepRow* row : seeds) {
    if (!row->failure.empty()) {
      folded.failure = "seed " + std::to_string(row->seed) + ": " + row->failure;
      continue;
    }
    const CalibrationFigures& c = row->calibration;
    f.converged += c.converged;
    f.vertices += c.vertices;
    f.iterations_max = std::max(f.iterations_max, c.iterations_max);
    f.seconds_per_vertex += c.seconds_per_vertex;
    if (c.accuracy.max_error_rel >= f.accuracy.max_error_rel) {
      f.accuracy.max_error_rel = c.accuracy.max_error_rel;
      f.accuracy.max_error_n = c.accuracy.max_error_n;
    }
    rms_n += c.accuracy.rms_residual_n;
    rms_rel += c.accuracy.rms_residual_rel;
    iteration_medians.push_back(c.iterations_median);
    residual_medians.push_back(row->residual_n.median);
    folded.residual_n.max = std::max(folded.residual_n.max, row->residual_n.max);
    ++ran;
  }
  if (ran == 0) return folded;
  if (ran == static_cast<int>(seeds.size())) folded.failure.clear();
  f.seconds_per_vertex /= ran;
  f.accuracy.rms_residual_n = rms_n / ran;
  f.accuracy.rms_residual_rel = rms_rel / ran;
  f.iterations_median = median(iteration_medians);
  folded.residual_n.median = median(residual_medians);
  return folded;
}

std::vector<SweepRow> foldSweepSeeds(const std::vector<SweepRow>& rows) {
  std::vector<SweepRow> folded;
  for (std::size_t first = 0; first < rows.size();) {
    std::vector<const SweepRow*> group;
    std::size_t next = first;
    while (next < rows.size() && rows[next].device == rows[first].device &&
           rows[next].friction == rows[first].friction && rows[next].method == rows[first].method) {
      group.push_back(&rows[next++]);
    }
    folded.push_back(foldSeeds(group));
    first = next;
  }
  return folded;
}

double measureRealTimeFactor(const std::string& name, double simulated_s) {
  auto device = openSimulatedDevice(name, 1);
  device->resetState(device->workspaceCenter_m());
  device->hand().grab(device->workspaceCenter_m());  // keep it off the end stops
  const auto start = Clock::now();
  for (double t = 0.0; t < simulated_s; t += 1e-3) {
    device->setForce(Eigen::Vector3d::Zero());
    device->advance(1e-3);
  }
  return simulated_s / secondsSince(start);
}

DecoratorCost measureDecoratorCost(const std::string& name, const GravityMap& map, int ticks) {
  std::shared_ptr<SimulatedDevice> raw = openSimulatedDevice(name, 1);
  std::shared_ptr<SimulatedDevice> inner = openSimulatedDevice(name, 1);
  GravityCompensatedDevice decorated(inner);
  decorated.open();
  decorated.publishMap(std::make_shared<const GravityMap>(map));
  const Eigen::Vector3d force(0.1, 0.0, 0.0);
  Eigen::Vector3d position;
  double raw_s = 0.0, decorated_s = 0.0;
  const int rounds = 10;
  for (int round = 0; round < rounds; ++round) {
    auto start = Clock::now();
    for (int k = 0; k < ticks / rounds; ++k) {
      raw->getPosition(position);
      raw->setForce(force);
    }
    raw_s += secondsSince(start);
    start = Clock::now();
    for (int k = 0; k < ticks / rounds; ++k) {
      decorated.getPosition(position);
      decorated.setForce(force);
    }
    decorated_s += secondsSince(start);
  }
  return {raw_s / ticks * 1e9, decorated_s / ticks * 1e9};
}

MapQueryCost measureMapQueryCost(const GravityMap& map, int queries) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  const auto start = Clock::now();
  for (int k = 0; k < queries; ++k) {
    const double s = (k % 1000) * 1e-3 - 0.5;
    sum += map.gravityAt(map.grid().center_m() + 0.05 * Eigen::Vector3d(s, -s, s));
  }
  return {secondsSince(start) / queries * 1e9, sum.sum()};
}

}  // namespace autograv::sim
