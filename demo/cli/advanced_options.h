#pragma once

// The research and simulation options of `autograv`: declared once, on the program itself, and
// accepted after any command that uses them (`autograv calibrate --out m.json --friction high`).
// A command's --help lists what a user needs; `autograv --help-advanced` lists these, and
// `autograv <command> --help-advanced` those the command takes. One given to a command that does
// not use it is refused.

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "autograv/device/device_specifications.h"
#include "autograv/estimation/estimation_parameters.h"
#include "autograv/estimation/workspace_explorer.h"
#include "autograv/map/gravity_map.h"
#include "autograv/sim/actuators.h"
#include "autograv/sim/friction.h"
#include "autograv/sim/servo_timing_model.h"
#include "cli_support.h"

namespace autograv::cli {

/// The simulated device a command runs on, and its servo loop (sim: devices only).
struct SimulationKnobs {
  std::uint64_t seed = 1;  ///< --seed: the device's noise (and verify's points, --truth's device).
  sim::FrictionLevel friction = sim::FrictionLevel::kTypical;  ///< --friction
  /// --unit, --actuators, --session, --thermal, --ambient-c, --motor-start-c
  sim::SimulatedUnit unit;
  SimulatedLoad load;                                        ///< --payload-g, --tilt-deg
  sim::ServoTiming servo_timing = sim::ServoTiming::kExact;  ///< --servo-timing
  std::optional<std::uint64_t> servo_timing_seed;            ///< --servo-timing-seed
};

/// The estimation parameters given on the command line (paper Secs. II-III), in SI units; each
/// one not given keeps the default of the command's method.
struct EstimationKnobs {
  std::optional<EstimationMethod> method;
  std::optional<double> alpha_per_s;
  std::optional<double> beta_per_s2;
  std::optional<double> k0_n_per_m;
  std::optional<int> n_s;
  std::optional<double> eps_s_m_per_s;
  std::optional<int> n_g;
  std::optional<double> eps_g_n;
  std::optional<int> max_iterations;
  std::optional<double> dither_amplitude_n;
  std::optional<double> dither_frequency_hz;
};

/// How a calibration visits its points (calibrate; --boundary-probes the wizard too).
struct CalibrationRunKnobs {
  bool copy_initial_estimate = false;  ///< --copy-initial-estimate
  int redo_failed = 1;                 ///< --redo-failed
  int boundary_probes = WorkspaceExplorer::Options().boundary_directions;  ///< --boundary-probes
  FieldModel field_model = kDefaultFieldModel;                             ///< --field-model
};

/// The wizard on a simulated device: its simulated hand and pace.
struct SimulatedWizardKnobs {
  bool auto_hand = false;     ///< --auto-hand
  double speed = -1.0;        ///< --speed; < 0: real time on a terminal, else as fast as possible
  double frame_ms = 20.0;     ///< --frame-ms
  bool uncalibrated = false;  ///< --uncalibrated
};

/// The parameters a command runs with: the defaults of `default_method` (EstimationParameters{}
/// for the dither method, EstimationParameters::paper() for the paper's), the knobs given, and
/// what depends on the device or the method when not given: k0 (defaultInitializationStiffness)
/// and n_G (5 for the paper's method, 3 for the dither method).
EstimationParameters estimationParameters(const EstimationKnobs& knobs,
                                          EstimationMethod default_method,
                                          const DeviceSpecifications& specifications);

/// The names of the options, in groups, for AdvancedOptions::accept.
namespace knob {
inline const std::vector<std::string> kSimulatedDevice = {
    "--seed",    "--friction", "--unit",          "--actuators",
    "--session", "--thermal",  "--motor-start-c", "--ambient-c"};
inline const std::vector<std::string> kSimulatedLoad = {"--payload-g", "--tilt-deg"};
inline const std::vector<std::string> kServoTiming = {"--servo-timing"};
inline const std::vector<std::string> kServoTimingSeed = {"--servo-timing-seed"};
inline const std::vector<std::string> kMethod = {"--method"};
inline const std::vector<std::string> kEstimation = {
    "--method",         "--alpha-per-s", "--beta-per-s2", "--k0-n-per-mm",    "--n-s",
    "--eps-s-mm-per-s", "--n-g",         "--eps-g-gf",    "--max-iterations", "--dither-mn",
    "--dither-hz"};
inline const std::vector<std::string> kCalibrationRun = {"--copy-initial-estimate", "--redo-failed",
                                                         "--boundary-probes"};
inline const std::vector<std::string> kBoundaryProbes = {"--boundary-probes"};
inline const std::vector<std::string> kFieldModel = {"--field-model"};
inline const std::vector<std::string> kSimulatedWizard = {"--auto-hand", "--speed", "--frame-ms",
                                                          "--uncalibrated"};
}  // namespace knob

/// Every research and simulation option of the program, its value once parsed, and which command
/// takes which. Made once per program (makeApp), before the commands; the commands keep a
/// shared_ptr to read the values in their callbacks. Not real-time safe.
class AdvancedOptions {
 public:
  /// Declares every option on `program` (hidden from its --help), their old spellings (hidden,
  /// with a note on stderr when used) and --help-advanced.
  static std::shared_ptr<AdvancedOptions> declare(CLI::App& program);

  AdvancedOptions(const AdvancedOptions&) = delete;
  AdvancedOptions& operator=(const AdvancedOptions&) = delete;

  /// `command` takes the options named in `groups` (knob::...): they are listed by its
  /// --help-advanced and its --help's footer points there. Call once per command.
  void accept(CLI::App& command, const std::vector<std::vector<std::string>>& groups);
  /// Makes every subcommand of `program` refuse, once parsed, an option it does not take. Call
  /// once every command is added.
  void refuseOthers(CLI::App& program);

  /// The values, once parsed.
  const SimulationKnobs& simulation() const noexcept { return simulation_; }
  const EstimationKnobs& estimation() const noexcept { return estimation_; }
  const CalibrationRunKnobs& run() const noexcept { return run_; }
  const SimulatedWizardKnobs& wizard() const noexcept { return wizard_; }

  /// The text of --help-advanced: every option by section, or only those `command` takes.
  std::string help(const CLI::App* command) const;

  /// A section of --help-advanced: its title, and the topic a command's --help footer names.
  struct Section {
    std::string title;
    std::string topic;
  };

 private:
  AdvancedOptions() = default;
  void declareOptions(CLI::App& program);
  /// Adds a hidden `old_name` for the positive number `current` takes: it stores through `set`
  /// and notes the new name on stderr.
  void addOldSpelling(CLI::App& program, const std::string& old_name, const CLI::Option* current,
                      std::function<void(double)> set);
  /// `option` belongs to `section` of --help-advanced.
  CLI::Option* file(CLI::Option* option, const Section& section);

  SimulationKnobs simulation_;
  EstimationKnobs estimation_;
  CalibrationRunKnobs run_;
  SimulatedWizardKnobs wizard_;

  struct Entry {
    CLI::Option* option;
    Section section;
  };
  std::vector<Entry> options_;                             ///< In the order of --help-advanced.
  std::map<std::string, std::string> old_spellings_;       ///< Old name -> current name.
  std::map<std::string, CLI::Option*> old_options_;        ///< Old name -> its hidden option.
  std::map<std::string, std::vector<std::string>> taken_;  ///< Command -> current names.
};

/// The option groups that --help leaves out: the research and simulation options (listed by
/// --help-advanced instead) and the old spellings of renamed options.
inline constexpr const char* kAdvancedGroup = "Research and simulation options";
inline constexpr const char* kOldSpellingsGroup = "Old spellings";

/// The layout of every --help of the program: CLI11's, without the groups above. Set it on the
/// program before adding the commands, which inherit it.
std::shared_ptr<CLI::Formatter> makeHelpFormatter();

/// Says on stderr that `old_name` is now `new_name`. Every renamed flag keeps its old spelling,
/// hidden from --help, for scripts written before the rename.
void noteRenamed(const std::string& old_name, const std::string& new_name);

/// Adds a hidden option `old_name` to `command` that stores into what `current` stores (through
/// `set`) and notes the rename; for the renamed options of one command.
template <typename Value>
CLI::Option* addRenamedOption(CLI::App& command, const std::string& old_name,
                              const std::string& new_name, std::function<void(const Value&)> set) {
  return command
      .add_option_function<Value>(
          old_name,
          [old_name, new_name, set](const Value& value) {
            noteRenamed(old_name, new_name);
            set(value);
          },
          "Old spelling of " + new_name)
      ->group(kOldSpellingsGroup);
}

}  // namespace autograv::cli
