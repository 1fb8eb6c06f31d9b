// autograv render / plot / export / compare: pictures of a gravity map, its convergence, a
// ParaView file, and the screenshot comparison our users run in their CI. The commands always
// exist; without autograv::viz (AUTOGRAV_BUILD_VIZ=OFF) they fail with a clear message.
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "advanced_options.h"
#include "autograv/error.h"
#include "commands.h"

#ifdef AUTOGRAV_HAVE_VIZ
#include "autograv/image/image_comparison.h"
#include "autograv/image/png.h"
#include "autograv/map/map_io.h"
#include "autograv/viz/plots.h"
#include "autograv/viz/scene.h"
#include "autograv/viz/vtk_export.h"
#include "cli_support.h"
#endif

namespace autograv::cli {

namespace {

struct TruthOptions {
  std::string device;  // "sim:omega", "sim:omni"; empty = no ground truth
  Advanced advanced;   // its --seed
};

struct CompareOptions {
  double tolerance = 5.0e-5;
  int channel_threshold = 40;
  std::string diff_path;
};

struct RenderOptions {
  std::string map_path;
  std::string out_path;
  std::string view = "iso";
  std::string size = "1280x960";
  std::string background = "white";
  std::string color_map = "viridis";
  double workspace_radius_mm = -1.0;  // < 0: the truth device's, else none
  std::vector<double> position_mm;
  bool hide_explored_workspace = false;
  std::string title;
  std::string golden_path;
  TruthOptions truth;
  CompareOptions compare;
};

struct PlotCommandOptions {
  std::string map_path;
  std::string out_path;
  int vertex = -1;
  bool summary = false;
  std::string size = "1280x960";
  std::string background = "white";
  std::string title;
  TruthOptions truth;
};

struct ExportCommandOptions {
  std::string map_path;
  std::string out_path;
  TruthOptions truth;
};

struct CompareCommandOptions {
  std::string actual_path;
  std::string golden_path;
  CompareOptions compare;
};

void addTruthOptions(CLI::App* command, TruthOptions& truth, const Advanced& advanced) {
  command->add_option("--truth", truth.device,
                      "Simulated device whose true gravity is the reference (sim:omega, "
                      "sim:omni, sim:falcon; its seed: --seed)");
  truth.advanced = advanced;
  advanced->accept(*command, {{"--seed"}});
}

void addCompareOptions(CLI::App* command, CompareOptions& compare) {
  command
      ->add_option("--tolerance", compare.tolerance,
                   "Largest fraction of differing pixels that still passes")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  command
      ->add_option("--channel-threshold", compare.channel_threshold,
                   "A pixel differs when a channel differs by more than this (0-255)")
      ->capture_default_str()
      ->check(CLI::Range(0, 255));
  command->add_option("--diff", compare.diff_path,
                      "Write the difference picture here (default: <output>.diff.png on failure)");
}

#ifdef AUTOGRAV_HAVE_VIZ

void parseSize(const std::string& text, int& width_px, int& height_px) {
  int w = 0;
  int h = 0;
  char extra = 0;
  if (std::sscanf(text.c_str(), "%dx%d%c", &w, &h, &extra) != 2) {
    throw Error("--size-px " + text + ": expected WIDTHxHEIGHT in pixels, e.g. 1280x960");
  }
  width_px = w;
  height_px = h;
}

viz::Background parseBackgroundOption(const std::string& text) {
  viz::Background background = viz::Background::kWhite;
  if (!viz::parseBackground(text, background)) {
    throw Error("--background " + text + ": expected white or dark");
  }
  return background;
}

// The ground truth of a simulated device; the device stays alive inside the function.
struct Truth {
  viz::GroundTruth gravity;
  viz::Reachability reachable;
  double workspace_radius_m = 0.0;
  Eigen::Vector3d workspace_center_m = Eigen::Vector3d::Zero();
};

std::optional<Truth> makeTruth(const TruthOptions& options) {
  if (options.device.empty()) return std::nullopt;
  std::shared_ptr<sim::SimulatedDevice> device =
      openSimulatedDevice(options.device, options.advanced->simulation().seed);
  Truth truth;
  truth.workspace_radius_m = device->specifications().workspace_radius_m;
  truth.workspace_center_m = device->workspaceCenter_m();
  truth.gravity = [device](const Eigen::Vector3d& position_m) {
    return device->trueGravity(position_m);
  };
  truth.reachable = [device](const Eigen::Vector3d& position_m) {
    return device->isReachable(position_m);
  };
  return truth;
}

void warnModelMismatch(const GravityMap& map, const TruthOptions& truth) {
  if (!truth.device.empty() && map.metadata().device_model != truth.device) {
    std::fprintf(stderr, "autograv: warning: the map was made for '%s', the truth is '%s'\n",
                 map.metadata().device_model.c_str(), truth.device.c_str());
  }
}

// Compares `actual_png` with the golden picture, prints the verdict and fails the command
// (exit code 1) with a difference picture when it departs.
void compareWithGolden(const std::string& actual_png, const std::string& golden_png,
                       const CompareOptions& options) {
  ImageComparisonOptions compare;
  compare.tolerance = options.tolerance;
  compare.channel_threshold = options.channel_threshold;
  std::string diff_path = options.diff_path;
  const RgbImage actual = readPng(actual_png);
  const RgbImage golden = readPng(golden_png);
  RgbImage diff;
  const ImageComparison result = compareImages(actual, golden, compare, &diff);
  if (!result.passed && diff_path.empty()) {
    const auto dot = actual_png.find_last_of('.');
    diff_path = (dot == std::string::npos ? actual_png : actual_png.substr(0, dot)) + ".diff.png";
  }
  if (!diff_path.empty()) viz::writePng(diff, diff_path);
  std::printf("compare %s with %s: %s\n", actual_png.c_str(), golden_png.c_str(),
              describe(result, compare).c_str());
  if (!result.passed) {
    std::printf("the picture departs from the golden one; differences in red: %s\n",
                diff_path.c_str());
    throw CLI::RuntimeError(1);
  }
}

void runRender(const RenderOptions& options) {
  const GravityMap map = loadMap(options.map_path);
  viz::SceneOptions scene;
  parseSize(options.size, scene.width_px, scene.height_px);
  if (!viz::parseCameraView(options.view, scene.view)) {
    throw Error("--view " + options.view + ": expected iso, front or top");
  }
  scene.background = parseBackgroundOption(options.background);
  if (!viz::parseColorMap(options.color_map, scene.color_map)) {
    throw Error("--color-map " + options.color_map + ": expected viridis, coolwarm or grayscale");
  }
  const std::optional<Truth> truth = makeTruth(options.truth);
  warnModelMismatch(map, options.truth);
  if (truth) {
    scene.ground_truth = truth->gravity;
    scene.reachable = truth->reachable;
    scene.workspace_radius_m = truth->workspace_radius_m;
    scene.workspace_center_m = truth->workspace_center_m;
  }
  if (options.workspace_radius_mm >= 0.0)
    scene.workspace_radius_m = options.workspace_radius_mm * 1e-3;
  if (!options.position_mm.empty()) {
    if (options.position_mm.size() != 3) throw Error("--position-mm: expected X,Y,Z in mm");
    scene.device_position_m =
        Eigen::Vector3d(options.position_mm[0], options.position_mm[1], options.position_mm[2]) *
        1e-3;
  }
  scene.show_explored_workspace = !options.hide_explored_workspace;
  scene.title = options.title;
  viz::writePng(viz::renderScene(map, scene), options.out_path);
  std::printf("wrote %s (%dx%d px, %s view)\n", options.out_path.c_str(), scene.width_px,
              scene.height_px, viz::toString(scene.view));
  if (!options.golden_path.empty()) {
    compareWithGolden(options.out_path, options.golden_path, options.compare);
  }
}

void runPlot(const PlotCommandOptions& options) {
  if (options.summary == (options.vertex >= 0)) {
    throw Error("plot: give exactly one of --vertex I or --summary");
  }
  const GravityMap map = loadMap(options.map_path);
  viz::PlotOptions plot;
  parseSize(options.size, plot.width_px, plot.height_px);
  plot.background = parseBackgroundOption(options.background);
  plot.title = options.title;
  const std::optional<Truth> truth = makeTruth(options.truth);
  warnModelMismatch(map, options.truth);
  if (truth) plot.ground_truth = truth->gravity;
  const RgbImage image = options.summary ? viz::renderSummaryPlot(map, plot)
                                         : viz::renderConvergencePlot(map, options.vertex, plot);
  viz::writePng(image, options.out_path);
  std::printf("wrote %s (%dx%d px)\n", options.out_path.c_str(), plot.width_px, plot.height_px);
}

void runExport(const ExportCommandOptions& options) {
  const GravityMap map = loadMap(options.map_path);
  viz::ExportOptions export_options;
  const std::optional<Truth> truth = makeTruth(options.truth);
  warnModelMismatch(map, options.truth);
  if (truth) export_options.ground_truth = truth->gravity;
  viz::exportMap(map, options.out_path, export_options);
  std::printf("wrote %s (%d points; vectors \"gravity_N\"%s)\n", options.out_path.c_str(),
              map.grid().vertexCount(),
              truth ? "; \"true_gravity_N\" and \"residual_N\" from the truth" : "");
}

void runCompare(const CompareCommandOptions& options) {
  compareWithGolden(options.actual_path, options.golden_path, options.compare);
}

#else  // AUTOGRAV_HAVE_VIZ

[[noreturn]] void noViz() {
  throw Error("autograv was built without AUTOGRAV_BUILD_VIZ=ON (needs libvtk9-dev)");
}
void runRender(const RenderOptions&) { noViz(); }
void runPlot(const PlotCommandOptions&) { noViz(); }
void runExport(const ExportCommandOptions&) { noViz(); }
void runCompare(const CompareCommandOptions&) { noViz(); }

#endif  // AUTOGRAV_HAVE_VIZ

// A subcommand `name` whose options live as long as the program; `run` gets them once parsed.
template <typename Options>
std::pair<CLI::App*, std::shared_ptr<Options>> addSubcommand(CLI::App& app, const std::string& name,
                                                             const std::string& description,
                                                             void (*run)(const Options&)) {
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand(name, description);
  command->callback([options, run] { run(*options); });
  return {command, options};
}

// The map to read and the file to write, the first two options of render, plot and export.
template <typename Options>
void addMapAndOutput(CLI::App* command, Options& options, const std::string& output) {
  command->add_option("map", options.map_path, "Map file (JSON)")->required();
  command->add_option("-o,--out", options.out_path, output)->required();
}

// WIDTHxHEIGHT in pixels, as --size-px (once --size).
void addSizeOption(CLI::App* command, std::string& size) {
  command->add_option("--size-px", size, "WIDTHxHEIGHT in pixels")->capture_default_str();
  addRenamedOption<std::string>(*command, "--size", "--size-px",
                                [&size](const std::string& value) { size = value; });
}

void addRenderCommand(CLI::App& app, const Advanced& advanced) {
  const auto [command, options] = addSubcommand<RenderOptions>(
      app, "render",
      "Render a map: workspace, grid, gravity arrows, where each value was measured (PNG, "
      "headless)",
      runRender);
  addMapAndOutput(command, *options, "PNG to write");
  command->add_option("--view", options->view, "Camera: iso, front or top")->capture_default_str();
  addSizeOption(command, options->size);
  command->add_option("--background", options->background, "white or dark")->capture_default_str();
  command->add_option("--color-map", options->color_map, "viridis, coolwarm or grayscale")
      ->capture_default_str();
  command->add_option("--workspace-radius-mm", options->workspace_radius_mm,
                      "Draw the workspace sphere with this radius when the map has no "
                      "explored workspace (default: the --truth device's, else the grid's box)");
  command->add_option("--position-mm", options->position_mm, "Device position X,Y,Z [mm]")
      ->delimiter(',')
      ->expected(3);
  command
      ->add_option_function<std::vector<double>>(
          "--position",
          [&position = options->position_mm](const std::vector<double>& position_mm) {
            noteRenamed("--position", "--position-mm");
            position = position_mm;
          },
          "Old spelling of --position-mm")
      ->delimiter(',')
      ->expected(3)
      ->group(kOldSpellingsGroup);
  command->add_flag("--no-explored-workspace", options->hide_explored_workspace,
                    "Draw the sphere or box instead of the map's explored workspace");
  command->add_option("--title", options->title, "Title (default: model, grid, converged)");
  addTruthOptions(command, options->truth, advanced);
  command->add_option("--compare", options->golden_path,
                      "Golden PNG: exit 1 with a difference picture when the render departs");
  addCompareOptions(command, options->compare);
}

void addPlotCommand(CLI::App& app, const Advanced& advanced) {
  const auto [command, options] = addSubcommand<PlotCommandOptions>(
      app, "plot", "Plot the convergence at a vertex (Figs. 8-9) or a whole-map summary (PNG)",
      runPlot);
  addMapAndOutput(command, *options, "PNG to write");
  command->add_option("--vertex", options->vertex, "Vertex index: Delta_j and M_hat_j over j");
  command->add_flag("--summary", options->summary,
                    "Histograms of iterations per vertex (and of the error with --truth)");
  addSizeOption(command, options->size);
  command->add_option("--background", options->background, "white or dark")->capture_default_str();
  command->add_option("--title", options->title, "Title (default: from the map)");
  addTruthOptions(command, options->truth, advanced);
}

void addExportCommand(CLI::App& app, const Advanced& advanced) {
  const auto [command, options] = addSubcommand<ExportCommandOptions>(
      app, "export", "Write a map for ParaView: .vti (image data) or .vtu", runExport);
  addMapAndOutput(command, *options, "File to write (.vti or .vtu)");
  addTruthOptions(command, options->truth, advanced);
}

void addCompareCommand(CLI::App& app) {
  const auto [command, options] = addSubcommand<CompareCommandOptions>(
      app, "compare", "Compare a picture with a golden one; exit 1 with a difference picture",
      runCompare);
  command->add_option("actual", options->actual_path, "PNG to check")->required();
  command->add_option("golden", options->golden_path, "Golden PNG")->required();
  addCompareOptions(command, options->compare);
}

void addRenderCommands(CLI::App& app, const Advanced& advanced) {
  addRenderCommand(app, advanced);
  addPlotCommand(app, advanced);
  addExportCommand(app, advanced);
  addCompareCommand(app);
}

}  // namespace

AUTOGRAV_REGISTER_COMMAND(70, addRenderCommands);

}  // namespace autograv::cli
