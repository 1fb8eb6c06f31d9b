#include "advanced_options.h"

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "autograv/estimation/pd_design.h"
#include "boundary_probes_option.h"
#include "field_model_option.h"
#include "friction_option.h"
#include "servo_timing_option.h"

namespace autograv::cli {

namespace {

// The sections of --help-advanced: a title, and the topic a command's --help footer names.
const AdvancedOptions::Section kSimulatedDeviceSection{
    "Simulated devices (sim:*; ignored on hardware, except --seed for verify's points)",
    "the simulated device"};
const AdvancedOptions::Section kServoLoopSection{"The simulated servo loop", "its servo loop"};
const AdvancedOptions::Section kEstimationSection{
    "Estimation (paper Secs. II-III; the defaults are the dither method's, paper-experiment's the "
    "paper's)",
    "the estimation"};
const AdvancedOptions::Section kCalibrationRunSection{
    "How a calibration visits its points and reads its map", "the calibration run"};
const AdvancedOptions::Section kSimulatedWizardSection{"The wizard on a simulated device",
                                                       "the simulated hand"};

class HelpFormatter final : public CLI::Formatter {
 public:
  // Formatter::make_help with visibleGroups for its make_groups, which is not virtual.
  std::string make_help(const CLI::App* app, std::string name,
                        CLI::AppFormatMode mode) const override {
    if (mode == CLI::AppFormatMode::Sub) return make_expanded(app);
    std::ostringstream out;
    out << make_description(app) << make_usage(app, name) << make_positionals(app)
        << visibleGroups(app, mode) << make_subcommands(app, mode) << '\n'
        << make_footer(app);
    return out.str();
  }

 private:
  // Formatter::make_groups, without the groups --help leaves out.
  std::string visibleGroups(const CLI::App* app, CLI::AppFormatMode mode) const {
    std::ostringstream out;
    std::vector<std::string> groups = app->get_groups();
    groups.erase(std::remove_if(groups.begin(), groups.end(),
                                [](const std::string& group) {
                                  return group.empty() || group == kAdvancedGroup ||
                                         group == kOldSpellingsGroup;
                                }),
                 groups.end());
    for (const std::string& group : groups) {
      const std::vector<const CLI::Option*> options =
          app->get_options([app, mode, &group](const CLI::Option* option) {
            return option->get_group() == group && option->nonpositional() &&
                   (mode != CLI::AppFormatMode::Sub ||
                    (app->get_help_ptr() != option && app->get_help_all_ptr() != option));
          });
      if (!options.empty()) out << make_group(group, false, options);
    }
    return out.str();
  }
};

}  // namespace

std::shared_ptr<CLI::Formatter> makeHelpFormatter() { return std::make_shared<HelpFormatter>(); }

EstimationParameters estimationParameters(const EstimationKnobs& knobs,
                                          EstimationMethod default_method,
                                          const DeviceSpecifications& specifications) {
  EstimationParameters p = default_method == EstimationMethod::kDither
                               ? EstimationParameters{}
                               : EstimationParameters::paper();
  if (knobs.method) p.method = *knobs.method;
  if (knobs.alpha_per_s) p.alpha_per_s = *knobs.alpha_per_s;
  if (knobs.beta_per_s2) p.beta_per_s2 = *knobs.beta_per_s2;
  p.k0_n_per_m =
      knobs.k0_n_per_m ? *knobs.k0_n_per_m : defaultInitializationStiffness(specifications);
  if (knobs.n_s) p.n_s = *knobs.n_s;
  if (knobs.eps_s_m_per_s) p.eps_s_m_per_s = *knobs.eps_s_m_per_s;
  p.n_g = knobs.n_g                               ? *knobs.n_g
          : p.method == EstimationMethod::kDither ? EstimationParameters{}.n_g
                                                  : EstimationParameters::paper().n_g;
  if (knobs.eps_g_n) p.eps_g_n = *knobs.eps_g_n;
  if (knobs.max_iterations) p.max_iterations = *knobs.max_iterations;
  if (knobs.dither_amplitude_n) p.dither_amplitude_n = *knobs.dither_amplitude_n;
  if (knobs.dither_frequency_hz) p.dither_frequency_hz = *knobs.dither_frequency_hz;
  return p;
}

void noteRenamed(const std::string& old_name, const std::string& new_name) {
  std::fprintf(stderr, "autograv: note: %s is now %s; the old spelling will be removed\n",
               old_name.c_str(), new_name.c_str());
}

std::shared_ptr<AdvancedOptions> AdvancedOptions::declare(CLI::App& program) {
  std::shared_ptr<AdvancedOptions> options(new AdvancedOptions());
  options->declareOptions(program);
  // The flag's callback keeps the options alive as long as the program that parses into them.
  CLI::App* parsed = &program;
  program
      .add_flag_function(
          "--help-advanced",
          [options, parsed](std::int64_t) {
            const std::vector<CLI::App*> commands = parsed->get_subcommands();
            std::cout << options->help(commands.empty() ? nullptr : commands.front());
            throw CLI::Success();
          },
          "Print the research and simulation options (after a command: those it takes) and exit")
      ->trigger_on_parse();
  return options;
}

CLI::Option* AdvancedOptions::file(CLI::Option* option, const Section& section) {
  option->group(kAdvancedGroup);  // left out of --help (HelpFormatter): --help-advanced lists it
  options_.push_back({option, section});
  return option;
}

void AdvancedOptions::addOldSpelling(CLI::App& program, const std::string& old_name,
                                     const CLI::Option* current, std::function<void(double)> set) {
  const std::string new_name = current->get_name();
  old_options_[old_name] = program
                               .add_option_function<double>(
                                   old_name,
                                   [old_name, new_name, set](double value) {
                                     noteRenamed(old_name, new_name);
                                     set(value);
                                   },
                                   "Old spelling of " + new_name)
                               ->check(CLI::PositiveNumber)
                               ->group(kOldSpellingsGroup);
  old_spellings_[old_name] = new_name;
}

void AdvancedOptions::declareOptions(CLI::App& program) {
  // Simulated devices.
  SimulationKnobs& s = simulation_;
  file(program
           .add_option("--seed", s.seed,
                       "Noise seed of the simulated device (the same seed, the same run); "
                       "verify also draws its points from it, render, plot and export seed "
                       "the --truth device with it")
           ->capture_default_str(),
       kSimulatedDeviceSection);
  file(addFrictionOption(program, s.friction), kSimulatedDeviceSection);
  addSimulatedUnitOptions(program, s.unit);
  file(program.get_option("--unit"), kSimulatedDeviceSection);
  file(program.get_option("--actuators"), kSimulatedDeviceSection);
  for (const char* name : {"--session", "--thermal", "--motor-start-c", "--ambient-c"}) {
    file(program.get_option(name), kSimulatedDeviceSection);
  }
  addSimulatedLoadOptions(program, s.load);
  file(program.get_option("--payload-g"), kSimulatedDeviceSection);
  file(program.get_option("--tilt-deg"), kSimulatedDeviceSection);

  // The simulated servo loop.
  file(addServoTimingOption(program, s.servo_timing), kServoLoopSection);
  file(program.add_option("--servo-timing-seed", s.servo_timing_seed,
                          "Seed of the desktop, realtime or free loop's lateness (default: "
                          "--seed): the same device with another draw of late ticks"),
       kServoLoopSection);

  // Estimation, in the paper's units on the command line and SI values inside.
  EstimationKnobs& e = estimation_;
  file(
      program
          .add_option_function<std::string>(
              "--method", [&e](const std::string& name) { e.method = parseEstimationMethod(name); },
              "Estimation method: dither converges through dry friction, paper is eqs. 7-13 as "
              "published (default dither; paper-experiment: paper)")
          ->check(CLI::IsMember({"paper", "dither"})),
      kEstimationSection);
  const EstimationParameters defaults;
  CLI::Option* alpha =
      file(program
               .add_option_function<double>(
                   "--alpha-per-s", [&e](double value) { e.alpha_per_s = value; },
                   "PD damping alpha, K_D = alpha M [1/s] (default " +
                       std::to_string(static_cast<int>(defaults.alpha_per_s)) + ")")
               ->check(CLI::PositiveNumber),
           kEstimationSection);
  CLI::Option* beta = file(program
                               .add_option_function<double>(
                                   "--beta-per-s2", [&e](double value) { e.beta_per_s2 = value; },
                                   "PD stiffness beta, K_P = beta M [1/s^2] (default " +
                                       std::to_string(static_cast<int>(defaults.beta_per_s2)) + ")")
                               ->check(CLI::PositiveNumber),
                           kEstimationSection);
  CLI::Option* k0 =
      file(program
               .add_option_function<double>(
                   "--k0-n-per-mm", [&e](double value) { e.k0_n_per_m = value * 1e3; },
                   "Initialization field stiffness [N/mm] (default 0.5, at most a "
                   "tenth of the device's max stiffness)")
               ->check(CLI::PositiveNumber),
           kEstimationSection);
  file(program
           .add_option_function<int>(
               "--n-s", [&e](int value) { e.n_s = value; },
               "Slow samples that make a steady state (default " + std::to_string(defaults.n_s) +
                   ")")
           ->check(CLI::Range(1, 100000)),
       kEstimationSection);
  CLI::Option* eps_s =
      file(program
               .add_option_function<double>(
                   "--eps-s-mm-per-s", [&e](double value) { e.eps_s_m_per_s = value * 1e-3; },
                   "Steady-state speed threshold [mm/s] (default 0.1)")
               ->check(CLI::PositiveNumber),
           kEstimationSection);
  file(program
           .add_option_function<int>(
               "--n-g", [&e](int value) { e.n_g = value; },
               "Small updates in a row that end a vertex (default 3; 5 "
               "with --method paper)")
           ->check(CLI::Range(1, 1000)),
       kEstimationSection);
  CLI::Option* eps_g = file(
      program
          .add_option_function<double>(
              "--eps-g-gf", [&e](double grams) { e.eps_g_n = grams * 1e-3 * kStandardGravity; },
              "Estimate-change threshold [gram-force] (default 0.5)")
          ->check(CLI::PositiveNumber),
      kEstimationSection);
  file(program
           .add_option_function<int>(
               "--max-iterations", [&e](int value) { e.max_iterations = value; },
               "Iteration cap per vertex (default " + std::to_string(defaults.max_iterations) + ")")
           ->check(CLI::Range(1, 10000)),
       kEstimationSection);
  file(program
           .add_option_function<double>(
               "--dither-mn",
               [&e](double millinewtons) { e.dither_amplitude_n = millinewtons * 1e-3; },
               "Dither amplitude per axis for --method dither [mN] (default: 9 % of the device's "
               "max force, lowered at each point so that |G_hat| plus the dither stays within "
               "the continuous force rating, but not below 230 mN)")
           ->check(CLI::NonNegativeNumber),
       kEstimationSection);
  file(program
           .add_option_function<double>(
               "--dither-hz", [&e](double hertz) { e.dither_frequency_hz = hertz; },
               "Dither base frequency for --method dither [Hz] (default 20): x and y at f, z at "
               "3f, one averaging window per period; above the hold's bandwidth (about 4 Hz) and "
               "at most a quarter of the 1 kHz servo rate")
           ->check(CLI::Range(5.0, 250.0)),
       kEstimationSection);
  // The spellings before the units joined the names.
  addOldSpelling(program, "--alpha", alpha, [&e](double value) { e.alpha_per_s = value; });
  addOldSpelling(program, "--beta", beta, [&e](double value) { e.beta_per_s2 = value; });
  addOldSpelling(program, "--k0", k0, [&e](double value) { e.k0_n_per_m = value * 1e3; });
  addOldSpelling(program, "--eps-s", eps_s, [&e](double value) { e.eps_s_m_per_s = value * 1e-3; });
  addOldSpelling(program, "--eps-g", eps_g,
                 [&e](double value) { e.eps_g_n = value * 1e-3 * kStandardGravity; });

  // How a calibration visits its points.
  file(program.add_flag("--copy-initial-estimate", run_.copy_initial_estimate,
                        "Start each vertex from the previous estimate exactly as eq. (9) says, "
                        "instead of the fit to the nearest measurements"),
       kCalibrationRunSection);
  file(program
           .add_option("--redo-failed", run_.redo_failed,
                       "Visit the vertices that did not converge again, up to this many passes")
           ->check(CLI::Range(0, 10))
           ->capture_default_str(),
       kCalibrationRunSection);
  file(addBoundaryProbesOption(program, run_.boundary_probes), kCalibrationRunSection);
  file(addFieldModelOption(program, run_.field_model), kCalibrationRunSection);

  // The wizard on a simulated device.
  file(program.add_flag("--auto-hand", wizard_.auto_hand,
                        "The simulated hand does the manual step by itself (required without a "
                        "terminal, where prompts are answered automatically)"),
       kSimulatedWizardSection);
  file(program
           .add_option("--speed", wizard_.speed,
                       "Simulated seconds per wall second; 0 runs as fast as possible (default: 1 "
                       "on a terminal, 0 otherwise)")
           ->check(CLI::NonNegativeNumber),
       kSimulatedWizardSection);
  file(program.add_option("--frame-ms", wizard_.frame_ms, "Simulated time per screen frame [ms]")
           ->check(CLI::Range(1.0, 200.0))
           ->capture_default_str(),
       kSimulatedWizardSection);
  file(program.add_flag("--uncalibrated", wizard_.uncalibrated,
                        "Start the simulated device un-homed (to see the Check step stop)"),
       kSimulatedWizardSection);
}

void AdvancedOptions::accept(CLI::App& command,
                             const std::vector<std::vector<std::string>>& groups) {
  std::vector<std::string>& taken = taken_[command.get_name()];
  for (const std::vector<std::string>& group : groups) {
    for (const std::string& name : group) {
      if (std::find(taken.begin(), taken.end(), name) == taken.end()) taken.push_back(name);
    }
  }
  std::string topics;
  for (const Entry& entry : options_) {
    if (std::find(taken.begin(), taken.end(), entry.option->get_name()) == taken.end()) continue;
    if (topics.find(entry.section.topic) != std::string::npos) continue;
    topics += (topics.empty() ? "" : ", ") + entry.section.topic;
  }
  command.footer("Research and simulation options (" + topics + "): autograv " +
                 command.get_name() + " --help-advanced");
}

void AdvancedOptions::refuseOthers(CLI::App& program) {
  for (CLI::App* command : program.get_subcommands([](CLI::App*) { return true; })) {
    const std::string name = command->get_name();
    // Runs once the command's arguments are parsed (the program's options among them), before
    // any command starts.
    command->parse_complete_callback([this, name] {
      const auto taken = taken_.find(name);
      const auto takes = [&](const std::string& option) {
        return taken != taken_.end() &&
               std::find(taken->second.begin(), taken->second.end(), option) != taken->second.end();
      };
      const auto refuse = [&](const std::string& given) {
        throw CLI::ValidationError(
            "`autograv " + name + "` does not take " + given +
            (taken == taken_.end()
                 ? std::string(" (it takes no research or simulation "
                               "options)")
                 : " (autograv " + name + " --help-advanced lists those it takes)"));
      };
      for (const Entry& entry : options_) {
        if (entry.option->count() > 0 && !takes(entry.option->get_name())) {
          refuse(entry.option->get_name());
        }
      }
      for (const auto& [old_name, option] : old_options_) {
        if (option->count() > 0 && !takes(old_spellings_.at(old_name))) refuse(old_name);
      }
    });
  }
}

std::string AdvancedOptions::help(const CLI::App* command) const {
  std::ostringstream out;
  const CLI::Formatter formatter;  // the layout of every --help
  const std::vector<std::string>* taken = nullptr;
  if (command != nullptr) {
    const auto found = taken_.find(command->get_name());
    if (found == taken_.end()) {
      out << "`autograv " << command->get_name() << "` takes no research or simulation options.\n";
      return out.str();
    }
    taken = &found->second;
    out << "Research and simulation options of `autograv " << command->get_name()
        << "`, given after it like its own:\n";
  } else {
    out << "Research and simulation options, declared once for every command that takes them "
           "and given after the command like its own\n(autograv <command> --help-advanced lists "
           "a command's):\n";
  }
  const auto commandsTaking = [this](const std::string& option) {
    std::string names;
    for (const auto& [name, options] : taken_) {
      if (std::find(options.begin(), options.end(), option) == options.end()) continue;
      names += (names.empty() ? "" : ", ") + name;
    }
    return names;
  };
  std::string section;
  for (const Entry& entry : options_) {
    const std::string name = entry.option->get_name();
    if (taken != nullptr && std::find(taken->begin(), taken->end(), name) == taken->end()) {
      continue;
    }
    if (entry.section.title != section) {
      section = entry.section.title;
      out << "\n" << section << ":\n";
    }
    out << formatter.make_option(entry.option, false);
    if (taken == nullptr) out << std::string(30, ' ') << "(" << commandsTaking(name) << ")\n";
  }
  std::string old;
  for (const auto& [old_name, new_name] : old_spellings_) {
    if (taken != nullptr && std::find(taken->begin(), taken->end(), new_name) == taken->end()) {
      continue;
    }
    old += (old.empty() ? "" : ", ") + old_name + " (" + new_name + ")";
  }
  if (!old.empty()) out << "\nOld spellings, still accepted with a note: " << old << "\n";
  return out.str();
}

}  // namespace autograv::cli
