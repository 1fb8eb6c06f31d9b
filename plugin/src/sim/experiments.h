#pragma once

// Private to the libraries and not installed: a research harness, not API. The command line and
// the tests include it from plugin/src.
//
// The experiments the figures of `autograv bench` and the integration tests come from: the tools'
// calibration of the default cube, the friction sweep over every simulated device and level with
// its seeds folded, and the speed of the simulators, the decorator and the map lookup.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "autograv/device/servo_loop_stats.h"
#include "autograv/estimation/estimation_parameters.h"
#include "autograv/map/gravity_map.h"
#include "autograv/sim/friction.h"
#include "autograv/sim/procedures.h"
#include "autograv/sim/servo_timing_model.h"
#include "autograv/sim/simulated_device.h"
#include "autograv/sim/verification.h"

namespace autograv::sim {

/// makeSimulatedDevice, then open() and calibrate(). Throws autograv::Error with the valid names
/// for an unknown one, or naming the call that failed. Not real-time safe.
std::unique_ptr<SimulatedDevice> openSimulatedDevice(
    const std::string& name, std::uint64_t seed, FrictionLevel friction = FrictionLevel::kTypical,
    const SimulatedUnit& unit = {});

/// What the tools use for `method`: the defaults (the dither method, which converges through dry
/// friction) or EstimationParameters::paper(), with the device-aware initialization stiffness
/// (defaultInitializationStiffness). Not real-time safe.
EstimationParameters toolParameters(const SimulatedDevice& device,
                                    EstimationMethod method = EstimationMethod::kDither);

/// The run `autograv calibrate --device D` makes (with --grid N): the workspace explored from
/// the device's centre, an N x N x N grid fitted around it, toolParameters. Not real-time safe.
CalibrationRunOptions defaultCalibrationOptions(const SimulatedDevice& device,
                                                int grid_resolution = 5);

/// How calibrateDefaultCube calibrates.
struct DefaultCubeOptions {
  int resolution = 3;                                   ///< Vertices per axis.
  EstimationMethod method = EstimationMethod::kDither;  ///< With toolParameters.
  /// Explore the workspace first (CalibrationRunOptions::explore); every vertex of the default
  /// cube is reachable, so false visits each one where it is.
  bool explore = true;
  /// AutoCalibrator::Options::extrapolate_initial_estimate: false starts each vertex from the
  /// previous estimate as eq. (9) says.
  bool extrapolate_initial_estimate = true;
  ServoTiming servo_timing = ServoTiming::kExact;  ///< How the servo ticks arrive.
  std::uint64_t servo_timing_seed = 1;             ///< Seed of the timing model's draws.
};

/// What calibrateDefaultCube made.
struct DefaultCubeCalibration {
  CalibrationRunResult run;  ///< runSimulatedCalibration's result.
  /// The map, labelled with the device's model and the parameters.
  std::shared_ptr<const GravityMap> map;
  double wall_s = 0.0;  ///< Wall time of the run, map and scoring excluded. Unit: [s]
};

/// Calibrates `device` (open) on the default cube (80 % of the cube inscribed in the workspace
/// sphere, defaultGridSide_m, around the workspace's centre: every vertex reachable, so that
/// figures compare estimators, not a fitted box's unreachable corners) with toolParameters.
/// Throws autograv::Error as runSimulatedCalibration does. Not real-time safe.
DefaultCubeCalibration calibrateDefaultCube(SimulatedDevice& device,
                                            const DefaultCubeOptions& options);

/// The figures of one default-cube calibration, or of several folded (foldSeeds).
struct CalibrationFigures {
  int vertices = 0;                    ///< Vertices of the grid.
  int converged = 0;                   ///< Of those, converged.
  double iterations_median = 0.0;      ///< Over every vertex.
  int iterations_max = 0;              ///< Over every vertex.
  double seconds_per_vertex = 0.0;     ///< Servo time at a vertex, on average. Unit: [s]
  double simulated_s = 0.0;            ///< Device time of the whole run. Unit: [s]
  double wall_s = 0.0;                 ///< Wall time of the run (a timing, not a result). Unit: [s]
  AccuracyReport accuracy;             ///< measureAccuracy at 1000 points, seed 1.
  ServoLoopStats::Summary servo_loop;  ///< What the servo loop did.
};

/// The figures of `calibration`, scored against `device`'s truth. Not real-time safe.
CalibrationFigures calibrationFigures(const DefaultCubeCalibration& calibration,
                                      const SimulatedDevice& device);

/// One cell of the friction sweep: a default-cube calibration and a verify on one device at one
/// friction level, with one method and one seed.
struct SweepRow {
  std::string device;                                   ///< Its simulatedDeviceNames() name.
  FrictionLevel friction = FrictionLevel::kTypical;     ///< The device's friction level.
  EstimationMethod method = EstimationMethod::kDither;  ///< The calibration's method.
  int seed = 1;                                         ///< The device's and the timing's seed.
  CalibrationFigures calibration;                       ///< The calibration's figures.
  Percentiles residual_n;  ///< Verify's measured residual force. Unit: [N]
  /// Why the calibration or verify could not run (the library's message); empty when they ran.
  std::string failure;
};

/// Settings of runFrictionSweep.
struct FrictionSweepOptions {
  int grid = 4;                                    ///< Vertices per axis of each calibration.
  int points = 12;                                 ///< Verify points of each cell.
  ServoTiming servo_timing = ServoTiming::kExact;  ///< How the servo ticks arrive.
  /// The methods each device and level is calibrated with, in this order.
  std::vector<EstimationMethod> methods = {EstimationMethod::kDither};
  int seeds = 1;  ///< Seeds 1..seeds of every cell.
  /// Called before each cell with the cells done, their total and the cell's name, and once at
  /// the end with (total, total, "done").
  std::function<void(int done, int total, const std::string& cell)> on_progress;
};

/// Every simulated device at every friction level, for each method and seed, in that nesting
/// (device outermost). A cell that throws autograv::Error is a row with its failure: a level the
/// calibration cannot handle is a result too. Not real-time safe.
std::vector<SweepRow> runFrictionSweep(const FrictionSweepOptions& options);

/// The rows of one device, friction level and method over its seeds, folded into one: vertices
/// and convergence add up, iterations and residuals take the median of the seeds' medians and the
/// largest maximum, errors the worst vertex and the mean RMS, time the mean. A failed seed names
/// itself in the failure ("seed N: ..."), which stays only when no seed ran. Not real-time safe.
SweepRow foldSeeds(const std::vector<const SweepRow*>& seeds);

/// Consecutive rows of the same device, friction level and method folded (foldSeeds), in sweep
/// order. Not real-time safe.
std::vector<SweepRow> foldSweepSeeds(const std::vector<SweepRow>& rows);

/// Simulated seconds per wall second of the device `name` with zero commanded force (10 kHz
/// inside, 1 kHz servo), held off its end stops by the hand, over `simulated_s`. A timing.
/// Not real-time safe.
double measureRealTimeFactor(const std::string& name, double simulated_s);

/// Wall time of one servo tick (read the position, send a force).
struct DecoratorCost {
  double raw_ns = 0.0;        ///< On the raw device. Unit: [ns]
  double decorated_ns = 0.0;  ///< Through GravityCompensatedDevice with `map`. Unit: [ns]
};

/// The raw device `name` against the decorator over it, `ticks` each, interleaved in rounds so
/// both see the same machine load. A timing. Not real-time safe.
DecoratorCost measureDecoratorCost(const std::string& name, const GravityMap& map, int ticks);

/// Wall time of GravityMap::gravityAt over `queries` points around the grid's centre.
struct MapQueryCost {
  double query_ns = 0.0;    ///< Per query (a timing). Unit: [ns]
  double checksum_n = 0.0;  ///< Sum of every component returned, so the lookups are not elided.
};

/// Times `queries` lookups of `map`. Not real-time safe.
MapQueryCost measureMapQueryCost(const GravityMap& map, int queries);

}  // namespace autograv::sim
