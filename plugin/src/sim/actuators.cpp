#include "autograv/sim/actuators.h"

#include <array>
#include <string>

#include "autograv/error.h"
#include "autograv/sim/simulated_driver.h"
#include "sim/unit_seed.h"

namespace autograv::sim {

namespace {

/// The relative tolerances of the three links of one actuator chain, each a bound on a uniform
/// draw: the motor's torque constant, the amplifier's gain (current sense, DAC reference, or a
/// voltage drive's winding resistance) and the transmission's ratio (capstan and drum diameters).
struct ChainTolerances {
  double torque_constant = 0.0;
  double amplifier = 0.0;
  double transmission = 0.0;
};

/// The model whose motors a test device carries: "sim:falcon-can" is sim:falcon's delta with
/// other travel stops, so its unit N is sim:falcon's unit N, the same gains.
std::string actuatorModel(const std::string& model) {
  return model == "sim:falcon-can" ? std::string("sim:falcon") : model;
}

// Bounds of uniform draws, the published tolerances of each part (docs/simulator_sources.md):
// - Torque constant: motor makers publish their catalogue data within +/-10 % (Beckhoff AM8100
//   "Technical data"; HIWIN torque motors, assembly instructions section 8.1), and permanent
//   magnets hold their remanence, which the torque constant follows, within +/-5 % (MMPA
//   guideline, as quoted in Emetor's glossary "Permanent magnet tolerances"). Precision coreless
//   motors (the Omni's and the Omega's class) at the magnets' +/-5 %; the Falcon's low-cost brushed
//   motors at the catalogue's +/-10 %.
// - Amplifier: a discrete current loop's gain is its 1 % sense resistor and its reference
//   (+/-2 %); the integrated current sensing of low-cost drivers is specified within +/-5 % above
//   1.2 A and +/-20 % below (TI DRV8244-Q1 datasheet, AI_ERR), and a voltage drive's gain follows
//   the winding resistance, +/-10 % (NEMA MG-1): +/-5 % for the Falcon. The Omega's amplifiers
//   at +/-1 % (a calibrated current loop; Force Dimension publishes no figure).
// - Transmission: a capstan's ratio is set by its turned diameter and the cable's, a few tenths
//   of a percent (an estimate from machining tolerances; nothing is published): +/-0.5 %, and
//   +/-1 % for the Falcon's 14.25 mm capstan and thicker cable.
ChainTolerances typicalTolerances(const std::string& model) {
  if (model == "sim:omni") return {0.05, 0.02, 0.005};
  // sim:falcon-can: the same delta and motors.
  if (model == "sim:falcon" || model == "sim:falcon-can") return {0.10, 0.05, 0.01};
  // The test devices share the Omega-like mechanism and its actuators.
  if (model == "sim:omega" || model == "sim:swirl-cube" || model == "sim:swirl-ellipsoid") {
    return {0.05, 0.01, 0.005};
  }
  std::string valid;
  for (const char* known : {"sim:omega", "sim:omni", "sim:falcon"}) {
    valid += std::string(valid.empty() ? "" : ", ") + known;
  }
  throw Error("no actuator tolerances for '" + model + "'; known models: " + valid);
}

double levelScale(ActuatorTolerance tolerance) noexcept {
  switch (tolerance) {
    case ActuatorTolerance::kIdeal:
      return 0.0;
    case ActuatorTolerance::kTypical:
      return 1.0;
    case ActuatorTolerance::kHigh:
      return 2.0;
  }
  return 1.0;
}

}  // namespace

const char* toString(ActuatorTolerance tolerance) noexcept {
  switch (tolerance) {
    case ActuatorTolerance::kIdeal:
      return "ideal";
    case ActuatorTolerance::kTypical:
      return "typical";
    case ActuatorTolerance::kHigh:
      return "high";
  }
  return "typical";
}

std::vector<std::string> actuatorToleranceNames() { return {"ideal", "typical", "high"}; }

ActuatorTolerance parseActuatorTolerance(const std::string& name) {
  for (const ActuatorTolerance tolerance :
       {ActuatorTolerance::kIdeal, ActuatorTolerance::kTypical, ActuatorTolerance::kHigh}) {
    if (name == toString(tolerance)) return tolerance;
  }
  throw Error("unknown actuator tolerance '" + name + "'; valid: ideal, typical, high");
}

double actuatorGainBound(const std::string& model, ActuatorTolerance tolerance) {
  const ChainTolerances chain = typicalTolerances(model);
  const double scale = levelScale(tolerance);
  return (1.0 + scale * chain.torque_constant) * (1.0 + scale * chain.amplifier) *
             (1.0 + scale * chain.transmission) -
         1.0;
}

Eigen::Vector3d actuatorGains(const std::string& model, const SimulatedUnit& unit) {
  const ChainTolerances chain = typicalTolerances(model);
  if (unit.number < 1) {
    throw Error("simulated unit " + std::to_string(unit.number) + ": units are numbered from 1");
  }
  const double scale = levelScale(unit.actuators);
  Random random(unitSeed(actuatorModel(model), {unit.number}));
  Eigen::Vector3d gains;
  for (int motor = 0; motor < 3; ++motor) {
    double gain = 1.0;
    for (const double bound : {chain.torque_constant, chain.amplifier, chain.transmission}) {
      gain *= 1.0 + scale * bound * (2.0 * random.uniform() - 1.0);
    }
    gains[motor] = gain;
  }
  return gains;
}

}  // namespace autograv::sim
