// The decorator's servo path: GravityCompensatedDevice over a fake device, driven by a script read
// from the input: positions (NaN and Inf included), application forces of any size, failed reads
// and writes, map publications (maps of any values) and removals, enable/disable, open/close and
// changes of the device's force limit. On every force the inner device receives: finite, and no
// larger than its max_linear_force_n (zero when the device gives no usable limit). setForce and
// getPosition allocate nothing. Policies (what counts as a fault, ramps) are not asserted here.
//
// Build with -DAUTOGRAV_FUZZ=ON (clang); run: build/fuzz/tests/fuzz/servo_fuzzer
// <scratch corpus> tests/fuzz/corpus/servo
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <fuzzer/FuzzedDataProvider.h>

#include "autograv/compensation/gravity_compensated_device.h"
#include "autograv/error.h"
#include "autograv/map/gravity_map.h"
#include "support/allocation_counter.h"
#include "support/recording_device.h"

namespace {

using autograv::GravityCompensatedDevice;
using autograv::GravityMap;
using Eigen::Vector3d;

[[noreturn]] void fail(const char* what) {
  std::fprintf(stderr, "servo_fuzzer: %s\n", what);
  std::abort();
}

/// The fake inner device, checking every force it is sent against its own limit.
class CheckedDevice final : public autograv::testing::RecordingDevice {
 public:
  bool setForce(const Vector3d& force_n) override {
    if (!force_n.allFinite()) fail("a non-finite force reached the device");
    const double max_n = specs.max_linear_force_n;
    const double limit_n = std::isfinite(max_n) && max_n > 0.0 ? max_n : 0.0;
    // Relative slack for the rounding of the clamp's scaling, nothing more.
    if (force_n.norm() > limit_n * (1.0 + 1e-12)) fail("a force above the device's limit");
    return RecordingDevice::setForce(force_n);
  }
};

/// Any double: raw bit patterns (NaN payloads, Inf, subnormals), awkward values, or values of a
/// plausible size, so that both the edges and the usual paths get exercised.
double anyDouble(FuzzedDataProvider& input, double plausible_scale) {
  static constexpr std::array<double, 10> kAwkward{0.0,
                                                   -0.0,
                                                   std::numeric_limits<double>::quiet_NaN(),
                                                   std::numeric_limits<double>::infinity(),
                                                   -std::numeric_limits<double>::infinity(),
                                                   std::numeric_limits<double>::max(),
                                                   -std::numeric_limits<double>::max(),
                                                   std::numeric_limits<double>::denorm_min(),
                                                   std::numeric_limits<double>::min(),
                                                   1e154};  // squares to about the largest double
  switch (input.ConsumeIntegralInRange<int>(0, 3)) {
    case 0: {
      const auto bits = input.ConsumeIntegral<std::uint64_t>();
      double value;
      std::memcpy(&value, &bits, sizeof value);
      return value;
    }
    case 1:
      return input.PickValueInArray(kAwkward);
    case 2:
      return input.ConsumeFloatingPoint<double>();
    default:
      return input.ConsumeFloatingPointInRange(-plausible_scale, plausible_scale);
  }
}

Vector3d anyVector(FuzzedDataProvider& input, double plausible_scale) {
  const double x = anyDouble(input, plausible_scale);
  const double y = anyDouble(input, plausible_scale);
  const double z = anyDouble(input, plausible_scale);
  return {x, y, z};
}

/// A map with a grid and gravity values from the input, or null when they make no valid map.
std::shared_ptr<const GravityMap> anyMap(FuzzedDataProvider& input, const std::string& model) {
  const int resolution = input.ConsumeIntegralInRange<int>(2, 3);
  const Vector3d center_m = anyVector(input, 0.05);
  const double side_m =
      input.ConsumeBool() ? input.ConsumeFloatingPointInRange(0.001, 0.3) : anyDouble(input, 0.3);
  try {
    const autograv::WorkspaceGrid grid(center_m, side_m, resolution);
    std::vector<autograv::VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
    for (autograv::VertexEstimate& vertex : vertices) {
      vertex.gravity_n = anyVector(input, 20.0);
      vertex.outcome = autograv::VertexOutcome::kConverged;
    }
    autograv::MapMetadata metadata;
    metadata.device_model = model;
    return std::make_shared<const GravityMap>(grid, std::move(vertices), std::move(metadata));
  } catch (const autograv::Error&) {
    return nullptr;  // a non-finite value or a degenerate grid: the constructors refuse it
  }
}

double anyForceLimit(FuzzedDataProvider& input) {
  static constexpr std::array<double, 8> kLimits{
      8.0, 3.3, 12.0, 0.001, 1000.0, 0.0, -1.0, std::numeric_limits<double>::quiet_NaN()};
  return input.ConsumeBool() ? input.PickValueInArray(kLimits)
                             : input.ConsumeFloatingPointInRange(0.001, 1000.0);
}

autograv::CompensationOptions anyOptions(FuzzedDataProvider& input) {
  autograv::CompensationOptions options;
  // A fixed-period clock: a run depends on its input alone, not on how fast it ran.
  options.clock = std::make_shared<autograv::FixedPeriodServoClock>(1e-3);
  options.ramp_duration_s = input.PickValueInArray({0.0, 0.001, 0.003, 0.02, 0.5});
  options.outside_margin_m = input.PickValueInArray({0.0, 0.01, 1.0});
  options.frozen_window_s = input.PickValueInArray({0.0, 0.001, 0.003, 0.2});
  options.frozen_force_floor_n = input.PickValueInArray({0.0, 0.5, 1e300});
  options.enabled = input.ConsumeBool();
  return options;
}

enum class Step : std::uint8_t {
  kTick,
  kTicks,
  kMove,
  kReadFails,
  kWriteFails,
  kPublishMap,
  kPublishNull,
  kEnable,
  kReclaim,
  kOpenClose,
  kForceLimit,
  kMaxValue = kForceLimit  // for FuzzedDataProvider::ConsumeEnum
};

/// One servo tick as an application makes it, optionally reading the position first.
void tick(GravityCompensatedDevice& device, bool read_first, const Vector3d& force_n) {
  const autograv::testing::AllocationCounter allocations;
  if (read_first) {
    Vector3d position_m;
    device.getPosition(position_m);
  }
  device.setForce(force_n);
  if (allocations.count() != 0) fail("the servo path allocated");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider input(data, size);
  auto inner = std::make_shared<CheckedDevice>();
  inner->specs.max_linear_force_n = anyForceLimit(input);
  GravityCompensatedDevice device(inner, anyOptions(input));
  device.open();

  constexpr int kMaxSteps = 2000;  // bounds the time of one input
  for (int step = 0; step < kMaxSteps && input.remaining_bytes() > 0; ++step) {
    switch (input.ConsumeEnum<Step>()) {
      case Step::kTick: {
        const bool read_first = input.ConsumeBool();
        tick(device, read_first, anyVector(input, 20.0));
        break;
      }
      case Step::kTicks: {  // long enough for ramps to finish and frozen positions to count
        const int count = input.ConsumeIntegralInRange<int>(1, 600);
        const bool read_first = input.ConsumeBool();
        const Vector3d force_n = anyVector(input, 20.0);
        for (int i = 0; i < count; ++i) tick(device, read_first, force_n);
        break;
      }
      case Step::kMove:
        inner->position = anyVector(input, 0.2);
        break;
      case Step::kReadFails:
        inner->position_result = !input.ConsumeBool();
        break;
      case Step::kWriteFails:
        inner->set_force_result = !input.ConsumeBool();
        break;
      case Step::kPublishMap: {
        const bool same_model = input.ConsumeBool();
        const auto map = anyMap(input, same_model ? inner->specs.model_name : "fake:other");
        try {
          device.publishMap(map, input.ConsumeBool());
        } catch (const autograv::Error&) {
          // a map for another model, not allowed: refused before it reaches the servo path
        }
        break;
      }
      case Step::kPublishNull:
        device.publishMap(nullptr);
        break;
      case Step::kEnable:
        device.setCompensationEnabled(input.ConsumeBool());
        break;
      case Step::kReclaim:
        device.reclaimRetiredMaps();
        break;
      case Step::kOpenClose:
        if (input.ConsumeBool()) {
          device.open();
        } else {
          device.close();
        }
        break;
      case Step::kForceLimit:
        inner->specs.max_linear_force_n = anyForceLimit(input);
        break;
    }
  }
  return 0;
}
