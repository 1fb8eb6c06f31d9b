#include "cli_support.h"

#include <sys/ioctl.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <sstream>

#include "autograv/error.h"
#include "autograv/map/map_io.h"
#include "autograv/sim/actuators.h"
#include "choice_option.h"

namespace autograv::cli {

nlohmann::json gridJson(const WorkspaceGrid& grid) {
  return {{"resolution", vectorJson(grid.resolution())},
          {"size_m", vectorJson(grid.size_m())},
          {"center_m", vectorJson(grid.center_m())}};
}

CLI::Option* addDeviceOption(CLI::App& command, std::string& device) {
  device = kDefaultDevice;
  std::string names;
  for (const std::string& name : sim::simulatedDeviceNames()) names += name + ", ";
  names += chai3dDevicesAvailable() ? "chai3d:N (CHAI3D's N-th device)"
                                    : "chai3d:N (in a build with CHAI3D)";
  return command
      .add_option("--device", device, "Device: " + names + "; `autograv devices` lists them")
      ->capture_default_str();
}

CLI::Option* addSimulatedDeviceOption(CLI::App& command, std::string& device) {
  device = kDefaultDevice;
  return command.add_option("--device", device, "Simulated device")
      ->check(CLI::IsMember(sim::simulatedDeviceNames()))
      ->capture_default_str();
}

CLI::Option* addReportOption(CLI::App& command, std::string& report_path) {
  return command.add_option("--report", report_path, "Write a JSON report here");
}

void addSimulatedLoadOptions(CLI::App& command, SimulatedLoad& load) {
  command
      .add_option("--payload-g", load.payload_g,
                  "Simulated devices: a point load on the end-effector (a heavier handle) [g]")
      ->check(CLI::NonNegativeNumber);
  command
      .add_option("--tilt-deg", load.tilt_deg,
                  "Simulated devices: the base tilted about y by this angle [deg]")
      ->check(CLI::Range(-45.0, 45.0));
}

void addSimulatedUnitOptions(CLI::App& command, sim::SimulatedUnit& unit) {
  command
      .add_option("--unit", unit.number,
                  "Simulated devices: which unit of the model (its own actuator gains, the same "
                  "whatever --seed)")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  addChoiceOption(
      command, "--actuators", unit.actuators, sim::parseActuatorTolerance,
      sim::actuatorToleranceNames(),
      "Simulated devices: how far each motor's gain strays from nominal: ideal, typical "
      "(published tolerances) or high (twice them)");
  command
      .add_option("--session", unit.session,
                  "Simulated devices: the session, each homed again within the model's "
                  "repeatability (1: the homing the published maps were made in)")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  CLI::Option* thermal = command.add_option_function<std::string>(
      "--thermal", [&unit](const std::string& on) { unit.thermal.enabled = on == "on"; },
      "Simulated devices: motors that warm as they hold forces (on), or never (off: the "
      "devices of 0.3, bit for bit)");
  thermal->check(CLI::IsMember({"on", "off"}))->default_str("off");
  CLI::Option* start =
      command
          .add_option("--motor-start-c", unit.thermal.start_c,
                      "Simulated devices with --thermal on: the motors' temperature at the start "
                      "(default: the room's) [C]")
          ->check(CLI::Range(-20.0, 100.0))
          ->needs(thermal);
  command
      .add_option_function<double>(
          "--ambient-c",
          [&unit, start](double ambient_c) {
            unit.thermal.ambient_c = ambient_c;
            if (start->count() == 0) unit.thermal.start_c = ambient_c;
          },
          "Simulated devices with --thermal on: the room's temperature [C]")
      ->check(CLI::Range(-20.0, 60.0))
      ->default_str("22")
      ->needs(thermal);
}

void applySimulatedLoad(const DeviceHandle& device, const SimulatedLoad& load) {
  if (load.payload_g == 0.0 && load.tilt_deg == 0.0) return;
  if (!device.simulation) {
    throw Error("--payload-g and --tilt-deg change a simulated device; " + device.name +
                " is real hardware (put the load on it, or tilt it, by hand)");
  }
  applySimulatedLoad(*device.simulation, load);
}

void applySimulatedLoad(sim::SimulatedDevice& device, const SimulatedLoad& load) {
  device.setPayload_kg(load.payload_g * 1e-3);
  device.setTilt_rad(load.tilt_deg * 3.14159265358979323846 / 180.0);
}

CLI::Validator simulatedOnly(const std::string& command) {
  return CLI::Validator(
      [command](std::string& name) -> std::string {
        for (const std::string& known : sim::simulatedDeviceNames()) {
          if (name == known) return {};
        }
        for (const std::string& known : sim::testDeviceNames()) {
          if (name == known) return {};
        }
        return "`autograv " + command + "` runs with no person in the loop, so it needs a " +
               "simulated device (" +
               [] {
                 std::string names;
                 for (const std::string& known : sim::simulatedDeviceNames()) {
                   names += (names.empty() ? "" : ", ") + known;
                 }
                 return names;
               }() +
               "); a real device such as " + name +
               " is calibrated with `autograv wizard`, since the manual step needs a hand";
      },
      "SIMULATED DEVICE");
}

void addMapsOption(CLI::App& command, std::string& maps_dir) {
  command.add_option("--maps", maps_dir,
                     "Folder of the map library (default: $XDG_DATA_HOME/autograv/maps, else "
                     "~/.local/share/autograv/maps)");
}

void writeJsonReport(const std::string& path, const nlohmann::json& report) {
  if (path.empty()) return;
  writeFileAtomically(path, report.dump(2) + "\n", "report");
}

bool stderrIsTerminal() { return ::isatty(STDERR_FILENO) == 1; }

int terminalColumns() {
  winsize size{};
  if (::ioctl(STDERR_FILENO, TIOCGWINSZ, &size) == 0 && size.ws_col > 0) return size.ws_col;
  return 80;
}

std::string formatDuration(double seconds) {
  char text[32];
  if (!std::isfinite(seconds) || seconds < 0.0) return "?";
  if (seconds < 10.0) {
    std::snprintf(text, sizeof text, "%.1fs", seconds);
  } else if (seconds < 60.0) {
    std::snprintf(text, sizeof text, "%.0fs", seconds);
  } else {
    const int whole = static_cast<int>(seconds);
    std::snprintf(text, sizeof text, "%dm %02ds", whole / 60, whole % 60);
  }
  return text;
}

ProgressBar::ProgressBar(std::string label)
    : label_(std::move(label)),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_),
      terminal_(stderrIsTerminal()) {}

void ProgressBar::update(int done, int total, const std::string& detail) {
  const auto now = std::chrono::steady_clock::now();
  const double since_draw = std::chrono::duration<double>(now - last_draw_).count();
  const bool last = done >= total;
  if (drawn_ && !last && since_draw < (terminal_ ? 0.1 : 5.0)) return;
  last_draw_ = now;
  drawn_ = true;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double fraction = total > 0 ? static_cast<double>(done) / total : 1.0;
  const double eta = fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : NAN;
  std::ostringstream line;
  line << label_ << ' ' << done << '/' << total;
  const int columns = terminal_ ? terminalColumns() : 80;
  const int bar_width = columns >= 100 ? 30 : (columns >= 70 ? 16 : 0);
  if (bar_width > 0) {
    const int filled = static_cast<int>(fraction * bar_width + 0.5);
    line << " [" << std::string(static_cast<std::size_t>(filled), '#')
         << std::string(static_cast<std::size_t>(bar_width - filled), '.') << ']';
  }
  line << ' ' << static_cast<int>(fraction * 100.0 + 0.5) << "%  " << detail;
  line << "  ETA " << (last ? "0s" : formatDuration(eta));
  std::string text = line.str();
  if (terminal_) {
    if (static_cast<int>(text.size()) > columns - 1)
      text.resize(static_cast<std::size_t>(columns - 1));
    std::fprintf(stderr, "\r\033[K%s", text.c_str());
  } else {
    std::fprintf(stderr, "%s\n", text.c_str());
  }
  std::fflush(stderr);
}

void ProgressBar::finish() {
  if (terminal_ && drawn_) std::fprintf(stderr, "\n");
  drawn_ = false;
}

void printFieldError(const sim::FieldErrorReport& field) {
  std::printf("%-34s p50 %.2f %%, p90 %.2f %%, p99 %.2f %%, max %.2f %% (%d points)\n",
              "field error over the workspace", 100.0 * field.p50_rel, 100.0 * field.p90_rel,
              100.0 * field.p99_rel, 100.0 * field.max_rel, field.samples);
  std::printf("%-34s p50 %.2f %%, p90 %.2f %%, p99 %.2f %%, max %.2f %% (%d points)\n",
              "  within 5 mm of the stops", 100.0 * field.shell_p50_rel,
              100.0 * field.shell_p90_rel, 100.0 * field.shell_p99_rel, 100.0 * field.shell_max_rel,
              field.shell_samples);
  if (field.breakaway_n > 0.0) {
    // Below the breakaway force a released stylus stays where it is put, whatever the error.
    std::printf("%-34s %.1f mN at most (breakaway %.1f mN); beats it in %.3f %% of the workspace\n",
                "where a released stylus drifts", field.max_n * 1e3, field.breakaway_n * 1e3,
                100.0 * field.above_breakaway_fraction);
  }
}

void addFieldErrorJson(nlohmann::json& report, const sim::FieldErrorReport& field) {
  report["field_samples"] = field.samples;
  report["field_error_p50_rel"] = field.p50_rel;
  report["field_error_p90_rel"] = field.p90_rel;
  report["field_error_p99_rel"] = field.p99_rel;
  report["field_error_max_rel"] = field.max_rel;
  report["shell_field_samples"] = field.shell_samples;
  report["shell_field_error_p50_rel"] = field.shell_p50_rel;
  report["shell_field_error_p90_rel"] = field.shell_p90_rel;
  report["shell_field_error_p99_rel"] = field.shell_p99_rel;
  report["shell_field_error_max_rel"] = field.shell_max_rel;
  report["field_error_max_n"] = field.max_n;
  if (field.breakaway_n > 0.0) {
    report["field_error_above_breakaway_fraction"] = field.above_breakaway_fraction;
  }
}

MapAgreement judgeAgreement(const GravityMap& map) {
  MapAgreement judged;
  try {
    // By the map's own model: what its lookup reads between the measurements.
    judged.agreement =
        measurementAgreement(map.grid(), map.vertices(), map.fieldModel(), map.curlWeight());
  } catch (const Error& error) {
    judged.unavailable = error.what();
  }
  return judged;
}

std::string describeFieldModel(const GravityMap& map) {
  const MapMetadata& metadata = map.metadata();
  std::string text = toString(map.fieldModel());
  if (map.fieldModel() == FieldModel::kCorrected) {
    char weight[64];
    std::snprintf(weight, sizeof weight, " (curl weight %.3g)", map.curlWeight());
    text += weight;
  }
  if (map.fieldModel() != metadata.field_model) {
    return text + " (the " + toString(metadata.field_model) +
           " model asked for cannot be fitted to these measurements)";
  }
  if (metadata.field_model_scores.size() > 1) {
    return text + ", chosen from the measurements: the smallest leave-one-out error";
  }
  if (metadata.field_model_scores.size() == 1) {
    return text + " (given; its curl weight chosen by the leave-one-out error)";
  }
  return text + " (given, not chosen)";
}

std::vector<std::string> describeFieldModelScores(const std::vector<FieldModelScore>& scores) {
  std::vector<std::string> lines;
  for (const FieldModelScore& score : scores) {
    char line[256];
    std::snprintf(line, sizeof line,
                  "%-13s leave-one-out median %.2f %%, 90th percentile %.2f %%, mean %.2f %%",
                  toString(score.model), 100.0 * score.median_rel, 100.0 * score.p90_rel,
                  100.0 * score.mean_rel);
    std::string text = line;
    if (score.model == FieldModel::kCorrected) {
      std::snprintf(line, sizeof line, " (curl weight %.3g)", score.curl_weight);
      text += line;
    }
    lines.push_back(text);
  }
  return lines;
}

void addFieldModelJson(nlohmann::json& report, const GravityMap& map) {
  report["field_model"] = toString(map.fieldModel());
  report["field_model_curl_weight"] = map.curlWeight();
  nlohmann::json scores = nlohmann::json::array();
  for (const FieldModelScore& score : map.metadata().field_model_scores) {
    scores.push_back({{"model", toString(score.model)},
                      {"curl_weight", score.curl_weight},
                      {"loo_median_rel", score.median_rel},
                      {"loo_p90_rel", score.p90_rel},
                      {"loo_mean_rel", score.mean_rel}});
  }
  report["field_model_scores"] = std::move(scores);
}

namespace {

const char* describe(ReviewVerdict verdict) {
  switch (verdict) {
    case ReviewVerdict::kConfirmed:
      return "confirmed (a steep field), the first kept";
    case ReviewVerdict::kReplaced:
      return "the first was wrong, the second kept";
    case ReviewVerdict::kLeftOut:
      return "both contradicted, left out of the fit";
    case ReviewVerdict::kNotMeasuredAgain:
      return "not measured again, the vertex kept as it was";
    case ReviewVerdict::kPending:
      break;
  }
  return "not concluded";
}

}  // namespace

std::vector<std::string> describeReviewedMeasurements(
    const std::vector<ReviewedMeasurement>& reviewed) {
  std::vector<std::string> lines;
  for (const ReviewedMeasurement& entry : reviewed) {
    const Eigen::Vector3d first_mm = 1e3 * entry.first.point_m;
    const Eigen::Vector3d again_mm = 1e3 * entry.again_point_m;
    char line[320];
    std::snprintf(line, sizeof line,
                  "vertex %d: %.2f %% off the others at (%.1f, %.1f, %.1f) mm (around it %.2f %%); "
                  "again at (%.1f, %.1f, %.1f) mm: %.2f %%, %.2f %% from the first: %s",
                  entry.first.vertex, 100.0 * entry.first.residual_rel, first_mm.x(), first_mm.y(),
                  first_mm.z(), 100.0 * entry.first.local_rel, again_mm.x(), again_mm.y(),
                  again_mm.z(), 100.0 * entry.again_residual_rel,
                  100.0 * (entry.again_value_n - entry.first.value_n).norm() /
                      std::max(entry.first.value_n.norm(), 1e-12),
                  describe(entry.verdict));
    lines.push_back(line);
  }
  return lines;
}

void addReviewedJson(nlohmann::json& report, const GravityMap& map) {
  nlohmann::json reviewed = nlohmann::json::array();
  int left_out = 0;
  for (const ReviewedMeasurement& entry : map.metadata().reviewed_measurements) {
    left_out += entry.verdict == ReviewVerdict::kLeftOut ? 1 : 0;
    reviewed.push_back({{"vertex", entry.first.vertex},
                        {"point_m", vectorJson(entry.first.point_m)},
                        {"residual_rel", entry.first.residual_rel},
                        {"local_rel", entry.first.local_rel},
                        {"again_point_m", vectorJson(entry.again_point_m)},
                        {"again_residual_rel", entry.again_residual_rel},
                        {"again_value_n", vectorJson(entry.again_value_n)},
                        {"value_n", vectorJson(entry.first.value_n)},
                        {"verdict", toString(entry.verdict)}});
  }
  report["measured_again"] = reviewed.size();
  report["left_out"] = left_out;
  report["reviewed_measurements"] = std::move(reviewed);
  // What the first points measured again saw of the motors warming (thermal_drift).
  const ThermalDrift& drift = map.metadata().thermal_drift;
  report["thermal_drift_points"] = drift.points;
  report["thermal_drift_rel"] = drift.drift_rel;
  report["thermal_gain_loss_per_load"] = drift.gain_loss_per_load;
  report["thermal_gain_loss_standard_error"] = drift.gain_loss_standard_error;
  report["thermal_load_first"] = drift.first_load;
  report["thermal_load_again"] = drift.again_load;
}

std::string describeThermalDrift(const ThermalDrift& drift) {
  if (drift.points == 0) return "not looked for (the motors hardly warmed, or no redo)";
  char line[256];
  std::snprintf(line, sizeof line,
                "%d points read %+.2f %% more command at load %.3f than at %.3f: "
                "torque loss %.3f +- %.3f per unit load%s",
                drift.points, 100.0 * drift.drift_rel, drift.again_load, drift.first_load,
                drift.gain_loss_per_load, drift.gain_loss_standard_error,
                drift.gain_loss_per_load > 0.0 ? ", corrected in the map and in use"
                                               : ", nothing to correct");
  return line;
}

AgreementText describeAgreement(const GravityMap& map, const MapAgreement& judged) {
  AgreementText text;
  text.field_model = describeFieldModel(map);
  text.model_scores = describeFieldModelScores(map.metadata().field_model_scores);
  if (!judged.agreement) {
    text.summary = "not available: " + judged.unavailable;
    return text;
  }
  const MeasurementAgreement& agreement = *judged.agreement;
  char line[256];
  std::snprintf(line, sizeof line,
                "median %.2f %%, 90th percentile %.2f %%, largest %.2f %% of |G_hat|",
                100.0 * agreement.median_rel, 100.0 * agreement.p90_rel, 100.0 * agreement.max_rel);
  text.summary = line;
  for (int vertex : agreement.least_sure_vertices) {
    const VertexEstimate& v = map.vertices()[static_cast<std::size_t>(vertex)];
    const Eigen::Vector3d at_mm = v.measuredAt_m(map.grid().vertexPosition(vertex)) * 1e3;
    std::snprintf(line, sizeof line, "%s vertex %d [%.0f, %.0f, %.0f] mm",
                  text.least_sure.empty() ? "least sure at" : ",", vertex, at_mm.x(), at_mm.y(),
                  at_mm.z());
    text.least_sure += line;
  }
  std::snprintf(line, sizeof line,
                "every measurement agrees with the others within %.0f %% of |G_hat|",
                100.0 * MeasurementAgreement::kWorthMeasuring);
  text.least_sure = text.least_sure.empty()
                        ? std::string(line)
                        : text.least_sure + " (more measurements near them would help most)";
  return text;
}

void printAgreement(const char* label, const AgreementText& text) {
  if (!text.field_model.empty()) std::printf("%-34s %s\n", "field model", text.field_model.c_str());
  for (const std::string& line : text.model_scores) std::printf("%-34s %s\n", "", line.c_str());
  std::printf("%-34s %s\n", label, text.summary.c_str());
  if (!text.least_sure.empty()) std::printf("%-34s %s\n", "", text.least_sure.c_str());
}

void addAgreementJson(nlohmann::json& report, const MapAgreement& judged) {
  if (!judged.agreement) {
    report["leave_one_out_unavailable"] = judged.unavailable;
    return;
  }
  report["leave_one_out_median_rel"] = judged.agreement->median_rel;
  report["leave_one_out_p90_rel"] = judged.agreement->p90_rel;
  report["leave_one_out_max_rel"] = judged.agreement->max_rel;
  report["least_sure_vertices"] = judged.agreement->least_sure_vertices;
}

std::optional<RealTimePriority> enterServoPriority(const DeviceHandle& device) {
  if (device.simulation) return std::nullopt;
  const RealTimePriority priority = enterRealTimePriority();
  warnIfNormalPriority(priority);
  return priority;
}

void warnIfNormalPriority(const RealTimePriority& priority) {
  if (!priority.granted) std::fprintf(stderr, "servo thread: %s\n", describe(priority).c_str());
}

void addServoPriorityJson(nlohmann::json& report, const std::optional<RealTimePriority>& priority) {
  if (!priority) return;
  report["servo_real_time_priority"] = priority->granted;
  report["servo_priority"] = describe(*priority);
}

}  // namespace autograv::cli
