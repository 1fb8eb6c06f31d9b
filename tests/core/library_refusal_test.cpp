// Every refusal a program meets through WizardConfig, EstimationParameters, loadMap, MapLibrary
// and GravityCompensatedDevice speaks the program's language: it names the C++ parameter to
// change (WizardConfig::advanced.box_size_m, EstimationParameters::beta_per_s2, ...), never a flag
// of the command line, which translates them itself (demo/cli/error_translation.h).

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <regex>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "autograv/compensation/gravity_compensated_device.h"
#include "autograv/error.h"
#include "autograv/estimation/pd_design.h"
#include "autograv/map/explored_workspace.h"
#include "autograv/map/map_io.h"
#include "autograv/map/map_library.h"
#include "autograv/sim/simulated_device.h"
#include "autograv/wizard/calibration_wizard.h"
#include "core/estimation/vertex_estimator.h"
#include "recording_device.h"
#include "scratch_folder.h"

namespace autograv {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Refusal {
  std::string what;                    ///< The case, for the failure message.
  std::string parameter;               ///< What the message must name.
  std::function<std::string()> raise;  ///< Returns the library's message.
};

/// The process's folder (ctest runs one test a process), gone at exit.
const std::filesystem::path& folder() {
  static const testing::ScratchFolder scratch("refusal");
  return scratch.path();
}

std::string thrownBy(const std::function<void()>& action) {
  try {
    action();
  } catch (const Error& error) {
    return error.what();
  }
  return "(nothing was thrown)";
}

WizardConfig smallConfig(const std::string& name) {
  WizardConfig config;
  config.advanced.box_size_m = Eigen::Vector3d::Constant(0.04);
  config.grid_resolution = Eigen::Vector3i::Constant(2);
  config.map_path = (folder() / (name + ".json")).string();
  config.advanced.explore = false;  // the box as given: its own refusals
  return config;
}

std::shared_ptr<sim::SimulatedDevice> omega() {
  return std::shared_ptr<sim::SimulatedDevice>(sim::makeSimulatedDevice("sim:omega", 1));
}

/// The constructor's refusal of `config`.
std::function<std::string()> constructing(std::function<void(WizardConfig&)> change) {
  return [change] {
    WizardConfig config = smallConfig("constructor");
    change(config);
    return thrownBy([&] { CalibrationWizard wizard(omega(), config); });
  };
}

/// What the Check step says (message and prompt) about `config` on a simulated omega.3.
std::function<std::string()> checking(std::function<void(WizardConfig&)> change,
                                      const std::string& name = "check") {
  return [change, name] {
    const auto device = omega();
    WizardConfig config = smallConfig(name);
    config.centre_m = device->workspaceCenter_m();
    change(config);
    CalibrationWizard wizard(device, config);
    wizard.service();
    const WizardStatus status = wizard.status();
    if (status.step != WizardStep::kCheck) return std::string("(Check passed)");
    return status.message + "\n" + status.prompt;
  };
}

std::shared_ptr<const GravityMap> mapFor(const std::string& model, const std::string& serial,
                                         const WorkspaceGrid& grid) {
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (auto& vertex : vertices) {
    vertex.gravity_n = Eigen::Vector3d(0.0, 0.0, 1.0);
    vertex.outcome = VertexOutcome::kConverged;
  }
  MapMetadata metadata;
  metadata.device_model = model;
  metadata.device_serial = serial;
  return std::make_shared<const GravityMap>(grid, std::move(vertices), metadata);
}

std::shared_ptr<const GravityMap> smallMap(const std::string& model, const std::string& serial) {
  return mapFor(model, serial, WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 2));
}

DeviceSpecifications specificationsOf(const std::string& model, const std::string& serial) {
  DeviceSpecifications specifications;
  specifications.model_name = model;
  specifications.serial_number = serial;
  return specifications;
}

std::function<std::string()> compensating(std::function<void(CompensationOptions&)> change) {
  return [change] {
    CompensationOptions options;
    change(options);
    return thrownBy([&] {
      GravityCompensatedDevice device(std::make_shared<testing::RecordingDevice>(), options);
    });
  };
}

std::function<std::string()> estimating(std::function<void(EstimationParameters&)> change,
                                        EstimationParameters parameters = {}) {
  return [change, parameters]() mutable {
    change(parameters);
    return thrownBy([&] { VertexEstimator estimator(parameters, 10.0); });
  };
}

std::vector<Refusal> everyRefusal() {
  using P = EstimationParameters;
  const P dither = EstimationParameters::frictionRobust();
  std::vector<Refusal> refusals = {
      // WizardConfig, refused by the constructor.
      {"no map path", "WizardConfig::map_path",
       constructing([](WizardConfig& c) { c.map_path = ""; })},
      {"centre tolerance", "WizardConfig::advanced.centre_tolerance_m",
       constructing([](WizardConfig& c) { c.advanced.centre_tolerance_m = 0.0; })},
      {"release patience", "WizardConfig::advanced.release_patience_s",
       constructing([](WizardConfig& c) { c.advanced.release_patience_s = -1.0; })},
      {"verify settle", "WizardConfig::advanced.verify_settle_s",
       constructing([](WizardConfig& c) { c.advanced.verify_settle_s = 0.0; })},
      {"verify release", "WizardConfig::advanced.verify_release_s",
       constructing([](WizardConfig& c) { c.advanced.verify_release_s = kNaN; })},
      {"verify drift", "WizardConfig::advanced.verify_drift_limit_m",
       constructing([](WizardConfig& c) { c.advanced.verify_drift_limit_m = 0.0; })},
      {"servo period", "EstimationParameters::servo_period_s",
       constructing([](WizardConfig& c) { c.advanced.parameters.servo_period_s = 0.0; })},
      {"field ramp", "WizardConfig::advanced.field_ramp_s",
       constructing([](WizardConfig& c) { c.advanced.field_ramp_s = -1.0; })},
      {"verify points", "WizardConfig::verify_points",
       constructing([](WizardConfig& c) { c.verify_points = 99; })},
      {"centre", "WizardConfig::centre_m",
       constructing([](WizardConfig& c) { c.centre_m.x() = kNaN; })},
      {"box size", "WizardConfig::advanced.box_size_m",
       constructing([](WizardConfig& c) { c.advanced.box_size_m->z() = 0.0; })},
      // Settings this run would not use.
      {"no exploration without a box", "WizardConfig::advanced.box_size_m",
       constructing([](WizardConfig& c) { c.advanced.box_size_m.reset(); })},
      {"exploration options without exploring", "WizardConfig::advanced.explorer",
       constructing([](WizardConfig& c) { c.advanced.explorer.directions = 14; })},
      {"workspace extent without exploring", "WizardConfig::advanced.min_workspace_extent_m",
       constructing([](WizardConfig& c) { c.advanced.min_workspace_extent_m = 0.03; })},
      {"release test timing without release tests", "WizardConfig::advanced.verify_settle_s",
       constructing([](WizardConfig& c) {
         c.verify_points = 0;
         c.advanced.verify_settle_s = 1.0;
       })},
      {"grid resolution", "WizardConfig::grid_resolution",
       constructing([](WizardConfig& c) { c.grid_resolution.y() = 1; })},
      {"smallest workspace", "WizardConfig::advanced.min_workspace_extent_m",
       constructing([](WizardConfig& c) { c.advanced.min_workspace_extent_m = 0.0; })},
      {"lookup refinement", "WizardConfig::advanced.lookup_refinement",
       constructing([](WizardConfig& c) { c.advanced.lookup_refinement = 0; })},
      // WizardConfig, refused by the Check step against the device.
      {"grid beyond the workspace", "WizardConfig::advanced.box_size_m",
       checking(
           [](WizardConfig& c) { c.advanced.box_size_m = Eigen::Vector3d(0.16, 0.12, 0.07); })},
      {"k0 stiffer than the device", "EstimationParameters::k0_n_per_m",
       checking([](WizardConfig& c) { c.advanced.parameters.k0_n_per_m = 1e7; })},
      {"no weight converges", "EstimationParameters::beta_per_s2", checking([](WizardConfig& c) {
         c.advanced.box_size_m = Eigen::Vector3d::Constant(0.05);
         c.grid_resolution = Eigen::Vector3i::Constant(4);
         c.advanced.parameters.lipschitz_prior_n_per_m = 200.0;
       })},
      {"map folder missing", "WizardConfig::map_path", checking([](WizardConfig& c) {
         c.map_path = (folder() / "no such folder" / "map.json").string();
       })},
      {"resume without a checkpoint", "WizardConfig::resume",
       checking([](WizardConfig& c) { c.resume = true; }, "no_checkpoint")},
      {"resume on another grid", "WizardConfig::advanced.box_size_m",
       checking(
           [](WizardConfig& c) {
             c.resume = true;
             const WorkspaceGrid other(c.centre_m, 0.05, 3);
             saveMap(*mapFor("sim:omega", "", other), c.map_path + ".partial");
           },
           "other_grid")},
      {"resume a fitted grid at another resolution", "WizardConfig::grid_resolution",
       checking(
           [](WizardConfig& c) {
             c.advanced.box_size_m.reset();
             c.advanced.explore = true;
             c.resume = true;
             const WorkspaceGrid other(c.centre_m, 0.05, 3);
             saveMap(*mapFor("sim:omega", "", other), c.map_path + ".partial");
           },
           "other_resolution")},
      {"exploration settings on a resumed workspace", "WizardConfig::advanced.explorer",
       checking(
           [](WizardConfig& c) {
             c.advanced.box_size_m.reset();
             c.advanced.explore = true;
             c.advanced.explorer.directions = 14;
             c.resume = true;
             const WorkspaceGrid grid(c.centre_m, 0.05, c.grid_resolution.x());
             std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
             MapMetadata metadata;
             metadata.device_model = "sim:omega";
             const std::vector<Eigen::Vector3d> directions = ExploredWorkspace::probeDirections(26);
             metadata.workspace =
                 ExploredWorkspace(c.centre_m, directions, std::vector<double>(26, 0.05));
             saveMap(GravityMap(grid, vertices, metadata), c.map_path + ".partial");
           },
           "resumed_workspace")},
      {"an earlier checkpoint", "WizardConfig::resume = true",
       checking(
           [](WizardConfig& c) {
             const WorkspaceGrid grid(c.centre_m, *c.advanced.box_size_m, c.grid_resolution);
             saveMap(*mapFor("sim:omega", "", grid), c.map_path + ".partial");
           },
           "earlier")},
      // EstimationParameters, through the wizard's Check and directly.
      {"alpha", "EstimationParameters::alpha_per_s", estimating([](P& p) { p.alpha_per_s = 0.0; })},
      {"beta", "EstimationParameters::beta_per_s2", estimating([](P& p) { p.beta_per_s2 = -1.0; })},
      {"n_G", "EstimationParameters::n_g", estimating([](P& p) { p.n_g = 0; })},
      {"eps_G", "EstimationParameters::eps_g_n", estimating([](P& p) { p.eps_g_n = 0.0; })},
      {"iterations", "EstimationParameters::max_iterations",
       estimating([](P& p) { p.max_iterations = p.n_g - 1; })},
      {"step durations", "EstimationParameters::max_step_duration_s",
       estimating([](P& p) { p.max_step_duration_s = p.min_step_duration_s; })},
      {"n_S", "EstimationParameters::n_s", estimating([](P& p) {
         p = EstimationParameters::paper();  // the rule that counts n_S samples
         p.n_s = 0;
       })},
      {"eps_S", "EstimationParameters::eps_s_m_per_s",
       estimating([](P& p) { p.eps_s_m_per_s = 0.0; })},
      {"dither amplitude", "EstimationParameters::dither_amplitude_n",
       estimating([](P& p) { p.dither_amplitude_n = -1.0; }, dither)},
      {"dither amplitude too large", "EstimationParameters::dither_amplitude_n",
       estimating([](P& p) { p.dither_amplitude_n = 6.0; }, dither)},
      {"steady windows", "EstimationParameters::steady_windows",
       estimating([](P& p) { p.steady_windows = 0; }, dither)},
      {"final steady windows", "EstimationParameters::final_steady_windows",
       estimating([](P& p) { p.final_steady_windows = 0; }, dither)},
      {"dither frequency", "EstimationParameters::dither_frequency_hz",
       estimating([](P& p) { p.dither_frequency_hz = 1e6; }, dither)},
      {"dither periods per window", "EstimationParameters::dither_periods_per_window",
       estimating([](P& p) { p.dither_periods_per_window = 0; }, dither)},
      {"k0 at Check", "EstimationParameters::k0_n_per_m",
       checking([](WizardConfig& c) { c.advanced.parameters.k0_n_per_m = 0.0; })},
      {"alpha at Check", "EstimationParameters::alpha_per_s",
       checking([](WizardConfig& c) { c.advanced.parameters.alpha_per_s = -5.0; })},
      {"convergence check", "EstimationParameters::beta_per_s2",
       [] { return checkConvergence(50.0, 1.0, 100.0).message; }},
      {"saturation check", "EstimationParameters::beta_per_s2",
       [] { return checkSaturation(3000.0, 2.0, 0.05, 3.0, 0.8).message; }},
      // loadMap.
      {"no map file", "WizardConfig::map_path",
       [] { return thrownBy([] { loadMap((folder() / "missing.json").string()); }); }},
      {"model mismatch", "MapLoadOptions::allow_model_mismatch",
       [] {
         const std::string path = (folder() / "falcon.json").string();
         saveMap(*smallMap("falcon", ""), path);
         MapLoadOptions options;
         options.expected_device_model = "omega.3";
         return thrownBy([&] { loadMap(path, options); });
       }},
      {"not a map", "not valid JSON",
       [] {
         const std::string path = (folder() / "broken.json").string();
         std::ofstream(path) << "{ \"format\": ";
         return thrownBy([&] { loadMap(path); });
       }},
      // MapLibrary.
      {"no map for the device", "CalibrationWizard",
       [] {
         const std::string dir = (folder() / "library").string();
         MapLibrary(dir).save(*smallMap("falcon", ""));
         return thrownBy([&] { loadMapForDevice(specificationsOf("omega.3", "A1"), dir); });
       }},
      {"map of another unit", "serial",
       [] {
         const std::string dir = (folder() / "library_serial").string();
         const std::string path = MapLibrary(dir).save(*smallMap("omega.3", "A1"));
         std::filesystem::rename(path, MapLibrary(dir).pathFor("omega.3", "B2"));
         return thrownBy([&] { loadMapForDevice(specificationsOf("omega.3", "B2"), dir); });
       }},
      {"a map with no model", "MapMetadata::device_model",
       [] {
         return thrownBy([] { MapLibrary((folder() / "lib2").string()).save(*smallMap("", "")); });
       }},
      {"no folder for the library", "MapLibrary(dir)",
       [] {
         const std::string home = std::getenv("HOME") != nullptr ? std::getenv("HOME") : "";
         const char* xdg = std::getenv("XDG_DATA_HOME");
         const std::string xdg_value = xdg != nullptr ? xdg : "";
         ::unsetenv("HOME");
         ::unsetenv("XDG_DATA_HOME");
         const std::string message = thrownBy([] { MapLibrary library; });
         if (!home.empty()) ::setenv("HOME", home.c_str(), 1);
         if (xdg != nullptr) ::setenv("XDG_DATA_HOME", xdg_value.c_str(), 1);
         return message;
       }},
      // The decorator.
      {"null device", "inner device",
       [] { return thrownBy([] { GravityCompensatedDevice device(nullptr); }); }},
      {"tick interval", "CompensationOptions::max_tick_interval_s",
       compensating([](CompensationOptions& o) { o.max_tick_interval_s = 0.0; })},
      {"ramp", "CompensationOptions::ramp_duration_s",
       compensating([](CompensationOptions& o) { o.ramp_duration_s = -1.0; })},
      {"outside margin", "CompensationOptions::outside_margin_m",
       compensating([](CompensationOptions& o) { o.outside_margin_m = kNaN; })},
      {"frozen window", "CompensationOptions::frozen_window_s",
       compensating([](CompensationOptions& o) { o.frozen_window_s = -1.0; })},
      {"frozen force floor", "CompensationOptions::frozen_force_floor_n",
       compensating([](CompensationOptions& o) { o.frozen_force_floor_n = -1.0; })},
      {"map of another model", "allow_model_mismatch",
       [] {
         auto fake = std::make_shared<testing::RecordingDevice>();
         GravityCompensatedDevice device(fake);
         return thrownBy([&] { device.publishMap(smallMap("falcon", "")); });
       }},
  };
  return refusals;
}

TEST(LibraryRefusalTest, EveryRefusalNamesItsParameterAndNoCommandLineFlag) {
  const std::regex flag("--[a-z]");
  int walked = 0;
  for (const Refusal& refusal : everyRefusal()) {
    const std::string message = refusal.raise();
    SCOPED_TRACE(refusal.what + ": " + message);
    EXPECT_FALSE(std::regex_search(message, flag)) << "names a command-line flag";
    EXPECT_NE(message.find(refusal.parameter), std::string::npos)
        << "does not name " << refusal.parameter;
    EXPECT_EQ(message.find("(nothing was thrown)"), std::string::npos);
    EXPECT_EQ(message.find("(Check passed)"), std::string::npos);
    ++walked;
  }
  EXPECT_GE(walked, 50);
}

}  // namespace
}  // namespace autograv
