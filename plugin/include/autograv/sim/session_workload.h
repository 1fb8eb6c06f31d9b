#pragma once

// A session of application use on a simulated device, compensated by a map: how the map's field
// error moves while the motors warm.

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "autograv/map/gravity_map.h"
#include "autograv/sim/procedures.h"
#include "autograv/sim/servo_timing_model.h"
#include "autograv/sim/simulated_device.h"

namespace autograv::sim {

/// What the scripted application does and how often the field is scored.
struct SessionWorkloadOptions {
  /// Device time of the session. Unit: [min]
  double minutes = 60.0;
  /// Device time between two scores of the field (and a score at the start). Unit: [s]
  double sample_period_s = 60.0;
  /// Draws the hand's path, its pauses and the scene's contacts.
  std::uint64_t seed = 1;
  /// Points each score draws (measureFieldError).
  int field_samples = kFieldErrorSamples;
  /// Largest force the scene adds at a contact (a VR object pushed against). Unit: [N]
  double contact_force_n = 1.0;
  /// How fast the hand carries the stylus between places. Unit: [m/s]
  double hand_speed_m_per_s = 0.08;
  /// How the servo ticks arrive; the nominal period is `servo_period_s`.
  ServoTiming servo_timing = ServoTiming::kExact;
  /// Nominal servo period. Unit: [s]
  double servo_period_s = 0.001;
  /// Whether the decorator applies the map's thermal correction
  /// (CompensationOptions::correct_thermal_drift): off shows what the correction gains.
  bool thermal_correction = true;
  /// The decorator's thermal load at the start (CompensationOptions::initial_thermal_load): a
  /// session that starts right after the calibration on motors it warmed.
  double initial_thermal_load = 0.0;
};

/// One score of the map during the session.
struct SessionSample {
  double minute = 0.0;  ///< Device time since the session started. Unit: [min]
  /// The map as the decorator uses it now (times thermal_scale) against the device's field at
  /// this moment (its motors' temperatures included).
  FieldErrorReport field;
  /// The factor the decorator scales the map by now: the map's thermal correction at the
  /// thermal load (thermalScale; 1 for a map without one).
  double thermal_scale = 1.0;
  /// The one further factor that brings the map in use closest to the device's field now (least
  /// squares over the map's reachable vertices).
  double best_scale = 1.0;
  /// The field error of the map in use once scaled by best_scale as well: what a correction of
  /// the motors' common gain, known exactly, would leave.
  FieldErrorReport rescaled_field;
  /// 90th percentile of |G_hat - G| / |G| at the stylus, G_hat as the decorator uses it, every
  /// 10 ms since the last score: what the hand felt along its path (0 at the start).
  double path_p90_rel = 0.0;
  /// Hottest winding (22 C throughout when the motors do not warm). Unit: [degC]
  double hottest_winding_c = kReferenceAmbient_c;
  /// Hottest housing, where the magnets are. Unit: [degC]
  double hottest_housing_c = kReferenceAmbient_c;
  /// The motors' lowest torque per command against the reference temperature (1 there).
  double lowest_gain_factor = 1.0;
  /// The motors' highest torque per command against the reference temperature.
  double highest_gain_factor = 1.0;
  /// What the decorator reports of the motors' load (GravityCompensatedDevice::thermalLoad).
  double thermal_load = 0.0;
  /// Servo time above the device's continuous force rating so far. Unit: [s]
  double seconds_above_continuous_force = 0.0;
};

/// What a whole session did.
struct SessionWorkloadResult {
  std::vector<SessionSample> samples;   ///< At minute 0 and every sample period.
  std::uint64_t force_limit_ticks = 0;  ///< Ticks whose force the decorator or device clamped.
  double seconds_above_continuous_force = 0.0;  ///< Unit: [s]
  double peak_force_n = 0.0;                    ///< Largest force the motors delivered. Unit: [N]
  std::uint64_t releases = 0;                   ///< Times the hand let go of the stylus.
  std::uint64_t contacts = 0;                   ///< Contacts the scene rendered.
};

/// Runs a scripted application for `options.minutes` of device time on `device` (open, at rest),
/// compensated by `map` through a GravityCompensatedDevice: the hand carries the stylus between
/// reachable places, holds it still, pushes against the scene's objects (which send up to
/// contact_force_n) and lets go of it, in turns drawn from the seed. Scores the map against the
/// device's truth at the start and every sample period (on_sample is called with each). The
/// truth scores and scripts the hand only; nothing of it reaches the decorator. Throws
/// autograv::Error for unusable options or a device that stops answering. Not real-time safe.
SessionWorkloadResult runSessionWorkload(
    SimulatedDevice& device, std::shared_ptr<const GravityMap> map,
    const SessionWorkloadOptions& options = {},
    const std::function<void(const SessionSample&)>& on_sample = {});

}  // namespace autograv::sim
