// Simulated seconds per wall second of each preset at its 10 kHz internal rate, driven like a
// 1 kHz servo loop (read position and velocity, command a force, advance 1 ms). The target is at
// least 1000x real time on one core, so that a full grid calibration runs in seconds.
#include <memory>
#include <string>

#include <benchmark/benchmark.h>

#include "autograv/sim/simulated_device.h"

namespace {

void runServoLoop(benchmark::State& state, const std::string& name, bool hand) {
  auto device = autograv::sim::makeSimulatedDevice(name, 1);
  device->open();
  device->calibrate();
  if (hand) {
    device->hand().grab(device->truePosition_m());
    device->hand().moveTo(device->truePosition_m() + Eigen::Vector3d(0.02, -0.02, 0.01), 0.02);
  }
  const Eigen::Vector3d hold = device->trueGravity(device->truePosition_m());
  Eigen::Vector3d position, velocity;
  constexpr double kServo_s = 0.001;
  long long ticks = 0;
  for (auto _ : state) {
    device->getPosition(position);
    device->getLinearVelocity(velocity);
    device->setForce(hold - 0.2 * velocity);
    device->advance(kServo_s);
    ++ticks;
    benchmark::DoNotOptimize(position);
  }
  const double simulated_s = static_cast<double>(ticks) * kServo_s;
  // Simulated seconds per wall second (the benchmark's time is wall time per iteration).
  state.counters["realtime_factor"] = benchmark::Counter(simulated_s, benchmark::Counter::kIsRate);
  state.counters["internal_steps_per_tick"] = kServo_s / device->internalStep_s();
}

void BM_SimOmegaServoLoop(benchmark::State& state) { runServoLoop(state, "sim:omega", false); }
void BM_SimOmniServoLoop(benchmark::State& state) { runServoLoop(state, "sim:omni", false); }
void BM_SimOmegaServoLoopWithHand(benchmark::State& state) {
  runServoLoop(state, "sim:omega", true);
}
void BM_SimOmniServoLoopWithHand(benchmark::State& state) { runServoLoop(state, "sim:omni", true); }
void BM_SimFalconServoLoop(benchmark::State& state) { runServoLoop(state, "sim:falcon", false); }
void BM_SimFalconServoLoopWithHand(benchmark::State& state) {
  runServoLoop(state, "sim:falcon", true);
}

// advance() alone: the physics cost, without the driver's sampling.
void runPhysicsOnly(benchmark::State& state, const std::string& name) {
  auto device = autograv::sim::makeSimulatedDevice(name, 1);
  device->open();
  device->setForce(device->trueGravity(device->truePosition_m()) + Eigen::Vector3d(0.0, 0.0, 1e-3));
  long long ticks = 0;
  for (auto _ : state) {
    device->advance(0.001);
    ++ticks;
    if (device->endStopHit()) {
      state.PauseTiming();
      device->resetState(device->workspaceCenter_m());
      state.ResumeTiming();
    }
  }
  state.counters["realtime_factor"] =
      benchmark::Counter(static_cast<double>(ticks) * 0.001, benchmark::Counter::kIsRate);
}

void BM_SimOmegaPhysicsOnly(benchmark::State& state) { runPhysicsOnly(state, "sim:omega"); }
void BM_SimOmniPhysicsOnly(benchmark::State& state) { runPhysicsOnly(state, "sim:omni"); }
void BM_SimFalconPhysicsOnly(benchmark::State& state) { runPhysicsOnly(state, "sim:falcon"); }

BENCHMARK(BM_SimOmegaServoLoop);
BENCHMARK(BM_SimOmniServoLoop);
BENCHMARK(BM_SimOmegaServoLoopWithHand);
BENCHMARK(BM_SimOmniServoLoopWithHand);
BENCHMARK(BM_SimFalconServoLoop);
BENCHMARK(BM_SimFalconServoLoopWithHand);
BENCHMARK(BM_SimOmegaPhysicsOnly);
BENCHMARK(BM_SimOmniPhysicsOnly);
BENCHMARK(BM_SimFalconPhysicsOnly);

}  // namespace

BENCHMARK_MAIN();
