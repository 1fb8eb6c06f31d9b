// Cost of GravityCompensatedDevice per servo tick against the raw device it wraps.
//
// One servo tick is what an application does each period: getPosition, then setForce. The
// DecoratedVsRaw benchmarks time both in the same run, interleaved in batches so that frequency
// scaling and cache state affect them alike. The counters use the thread's CPU time
// (CLOCK_THREAD_CPUTIME_ID), which other processes on a busy machine do not inflate:
//   raw_ns        mean time of a raw tick
//   decorated_ns  mean time of a decorated tick (map lookup, ramp, checks, clamp included)
//   overhead_ns   decorated_ns - raw_ns
//   ratio         decorated_ns / raw_ns
// Inner devices: a trivial driver (the decorator's own cost stands out) and sim:omni (a realistic
// driver call cost); and the trivial driver again, opened (so that the motors' load is counted)
// with a map that carries a thermal correction (the decorator then scales the map every tick).

#include <time.h>

#include <memory>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "autograv/compensation/gravity_compensated_device.h"
#include "autograv/map/gravity_map.h"
#include "autograv/sim/simulated_device.h"

namespace {

using autograv::GravityCompensatedDevice;
using autograv::GravityMap;

/// A driver that does nothing but hand out positions from a table (inside the map) and keep the
/// last force: the floor under which no real driver goes.
class TableDevice final : public autograv::HapticDevice {
 public:
  explicit TableDevice(std::vector<Eigen::Vector3d> positions) : positions_(std::move(positions)) {
    specifications_.model_name = "bench:table";
    specifications_.max_linear_force_n = 8.0;
    specifications_.max_linear_stiffness_n_per_m = 1000.0;
    specifications_.max_linear_damping_n_s_per_m = 10.0;
    specifications_.workspace_radius_m = 0.1;
  }
  bool open() override { return true; }
  bool close() override { return true; }
  bool calibrate(bool) override { return true; }
  bool getPosition(Eigen::Vector3d& position_m) override {
    position_m = positions_[next_];
    next_ = (next_ + 1) % positions_.size();
    return true;
  }
  bool getLinearVelocity(Eigen::Vector3d& velocity_m_per_s) override {
    velocity_m_per_s.setZero();
    return true;
  }
  bool getUserSwitch(int, bool& pressed) override {
    pressed = false;
    return true;
  }
  bool setForce(const Eigen::Vector3d& force_n) override {
    force_n_ = force_n;
    return true;
  }
  const autograv::DeviceSpecifications& specifications() const override { return specifications_; }

 private:
  std::vector<Eigen::Vector3d> positions_;
  std::size_t next_ = 0;
  Eigen::Vector3d force_n_ = Eigen::Vector3d::Zero();
  autograv::DeviceSpecifications specifications_;
};

/// A 5x5x5 map of `field` over a 6 cm cube at the origin, tagged with `model`.
template <typename Field>
std::shared_ptr<const GravityMap> makeMap(const std::string& model, Field field,
                                          int lookup_refinement = 1,
                                          double gain_loss_per_load = 0.0) {
  const autograv::WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.06, 5);
  std::vector<autograv::VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (int i = 0; i < grid.vertexCount(); ++i) {
    vertices[static_cast<std::size_t>(i)].gravity_n = field(grid.vertexPosition(i));
    vertices[static_cast<std::size_t>(i)].outcome = autograv::VertexOutcome::kConverged;
  }
  autograv::MapMetadata metadata;
  metadata.device_model = model;
  metadata.lookup_refinement = lookup_refinement;
  metadata.thermal_drift.gain_loss_per_load = gain_loss_per_load;
  metadata.thermal_drift.points = gain_loss_per_load > 0.0 ? 3 : 0;
  if (lookup_refinement > 1) metadata.field_model = autograv::kDefaultFieldModel;
  return std::make_shared<const GravityMap>(grid, std::move(vertices), metadata);
}

std::vector<Eigen::Vector3d> randomPositions(std::size_t count) {
  std::mt19937 random(42);
  std::uniform_real_distribution<double> coordinate(-0.03, 0.03);
  std::vector<Eigen::Vector3d> positions(count);
  for (auto& p : positions)
    p = Eigen::Vector3d(coordinate(random), coordinate(random), coordinate(random));
  return positions;
}

struct Setup {
  std::shared_ptr<autograv::HapticDevice> raw;
  std::unique_ptr<GravityCompensatedDevice> decorated;
};

Setup makeSetup(bool simulated, bool thermal_correction = false) {
  Setup setup;
  std::shared_ptr<const GravityMap> map;
  if (simulated) {
    std::shared_ptr<autograv::sim::SimulatedDevice> device =
        autograv::sim::makeSimulatedDevice("sim:omni", 1);
    device->open();
    device->calibrate();
    device->resetState(Eigen::Vector3d(0.004, -0.003, 0.002));
    const auto* sim = device.get();
    map = makeMap(device->specifications().model_name,
                  [sim](const Eigen::Vector3d& x) { return sim->trueGravity(x); });
    setup.raw = device;
  } else {
    setup.raw = std::make_shared<TableDevice>(randomPositions(4096));
    map = makeMap(
        "bench:table",
        [](const Eigen::Vector3d& x) {
          return Eigen::Vector3d(0.1 * x.y(), -0.2 * x.x(), -0.5 + 3.0 * x.z());
        },
        1, thermal_correction ? 0.1 : 0.0);
  }
  autograv::CompensationOptions options;
  options.ramp_duration_s = 0.0;
  setup.decorated = std::make_unique<GravityCompensatedDevice>(setup.raw, options);
  if (thermal_correction) setup.decorated->open();  // the motors' load is counted from open()
  setup.decorated->publishMap(map);
  return setup;
}

std::int64_t threadCpuTime_ns() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return static_cast<std::int64_t>(now.tv_sec) * 1000000000 + now.tv_nsec;
}

inline void tick(autograv::HapticDevice& device, const Eigen::Vector3d& force_n) {
  Eigen::Vector3d position_m;
  device.getPosition(position_m);
  benchmark::DoNotOptimize(position_m);
  benchmark::DoNotOptimize(device.setForce(force_n));
}

void BM_DecoratedVsRaw(benchmark::State& state) {
  const bool simulated = state.range(0) == 1;
  const bool thermal = state.range(0) == 2;
  state.SetLabel(simulated ? "inner=sim:omni"
                           : (thermal ? "inner=table, thermal correction" : "inner=table"));
  Setup setup = makeSetup(simulated, thermal);
  const Eigen::Vector3d force_n(0.1, -0.05, 0.2);
  constexpr int kBatch = 512;
  std::int64_t raw_time_ns = 0;
  std::int64_t decorated_time_ns = 0;
  std::int64_t ticks = 0;
  for (int k = 0; k < 1000; ++k) tick(*setup.decorated, force_n);  // warm-up, map taken
  for (auto _ : state) {
    const std::int64_t t0 = threadCpuTime_ns();
    for (int k = 0; k < kBatch; ++k) tick(*setup.raw, force_n);
    const std::int64_t t1 = threadCpuTime_ns();
    for (int k = 0; k < kBatch; ++k) tick(*setup.decorated, force_n);
    const std::int64_t t2 = threadCpuTime_ns();
    raw_time_ns += t1 - t0;
    decorated_time_ns += t2 - t1;
    ticks += kBatch;
  }
  const double raw_ns = static_cast<double>(raw_time_ns) / ticks;
  const double decorated_ns = static_cast<double>(decorated_time_ns) / ticks;
  state.counters["raw_ns"] = raw_ns;
  state.counters["decorated_ns"] = decorated_ns;
  state.counters["overhead_ns"] = decorated_ns - raw_ns;
  state.counters["ratio"] = decorated_ns / raw_ns;
  state.counters["faults"] = static_cast<double>(setup.decorated->faultCount());
  state.SetItemsProcessed(2 * ticks);
}
BENCHMARK(BM_DecoratedVsRaw)->Arg(0)->Arg(1)->Arg(2)->ArgName("inner");

// The same two loops as separate benchmarks, for the usual per-iteration view.
void BM_RawTick(benchmark::State& state) {
  Setup setup = makeSetup(false);
  const Eigen::Vector3d force_n(0.1, -0.05, 0.2);
  for (auto _ : state) tick(*setup.raw, force_n);
}
BENCHMARK(BM_RawTick);

void BM_DecoratedTick(benchmark::State& state) {
  Setup setup = makeSetup(false);
  const Eigen::Vector3d force_n(0.1, -0.05, 0.2);
  for (auto _ : state) tick(*setup.decorated, force_n);
}
BENCHMARK(BM_DecoratedTick);

// Where a decorated tick's time goes: the same tick with no map published (forwarding, clock,
// checks, ramp and clamp only), the clock read alone, and the servo path's map lookup alone on
// the same positions.
void BM_DecoratedTickWithoutMap(benchmark::State& state) {
  Setup setup = makeSetup(false);
  setup.decorated->publishMap(nullptr);
  const Eigen::Vector3d force_n(0.1, -0.05, 0.2);
  for (int k = 0; k < 1000; ++k) tick(*setup.decorated, force_n);  // the null map taken
  for (auto _ : state) tick(*setup.decorated, force_n);
}
BENCHMARK(BM_DecoratedTickWithoutMap);

// The decorator reads the servo clock once per tick to measure its duration: its share of the
// overhead.
void BM_ServoClockRead(benchmark::State& state) {
  autograv::SteadyServoClock clock;
  for (auto _ : state) benchmark::DoNotOptimize(clock.now_s());
}
BENCHMARK(BM_ServoClockRead);

// Argument: the lookup refinement. 1 is the paper's trilinear table of 125 vertices; the
// calibrations' maps (kDefaultLookupRefinement, the conservative fit sampled on it one cell
// beyond the box) read a table of 50653 (37^3, 1.6 MB), with the same arithmetic per lookup.
void BM_ServoMapLookup(benchmark::State& state) {
  const std::vector<Eigen::Vector3d> positions = randomPositions(4096);
  const auto map = makeMap(
      "bench:table",
      [](const Eigen::Vector3d& x) {
        return Eigen::Vector3d(0.1 * x.y(), -0.2 * x.x(), -0.5 + 3.0 * x.z());
      },
      static_cast<int>(state.range(0)));
  std::size_t next = 0;
  for (auto _ : state) {
    bool inside = false;
    benchmark::DoNotOptimize(map->gravityAt(positions[next], 0.01, inside));
    benchmark::DoNotOptimize(inside);
    next = (next + 1) % positions.size();
  }
}
BENCHMARK(BM_ServoMapLookup)
    ->Arg(1)
    ->Arg(autograv::kDefaultLookupRefinement)
    ->ArgName("refinement");

}  // namespace

BENCHMARK_MAIN();
