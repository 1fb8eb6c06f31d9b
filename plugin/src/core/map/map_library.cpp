#include "autograv/map/map_library.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <system_error>
#include <utility>

#include "autograv/error.h"
#include "autograv/map/map_io.h"

namespace autograv {

namespace {

namespace fs = std::filesystem;

std::string fileSafe(const std::string& text) {
  std::string safe = text;
  for (char& c : safe) {
    const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      c == '.' || c == '_' || c == '-';
    if (!keep) c = '_';
  }
  return safe;
}

std::string describe(const std::string& model, const std::string& serial) {
  return "\"" + model + "\"" + (serial.empty() ? "" : " (serial " + serial + ")");
}

}  // namespace

std::string defaultMapLibraryDir() {
  const char* data_home = std::getenv("XDG_DATA_HOME");
  if (data_home != nullptr && *data_home != '\0') {
    return (fs::path(data_home) / "autograv" / "maps").string();
  }
  const char* home = std::getenv("HOME");
  if (home != nullptr && *home != '\0') {
    return (fs::path(home) / ".local" / "share" / "autograv" / "maps").string();
  }
  throw Error(
      "no folder for the map library: neither XDG_DATA_HOME nor HOME is set; name one with "
      "MapLibrary(dir)");
}

MapLibrary::MapLibrary(std::string dir)
    : dir_(dir.empty() ? defaultMapLibraryDir() : std::move(dir)) {}

std::string MapLibrary::pathFor(const std::string& model, const std::string& serial) const {
  if (model.empty())
    throw Error(
        "map library: a map needs a device model to be filed under (MapMetadata::device_model)");
  const std::string name = fileSafe(model) + (serial.empty() ? "" : "@" + fileSafe(serial));
  return (fs::path(dir_) / (name + ".json")).string();
}

std::string MapLibrary::save(const GravityMap& map) const {
  std::error_code error;
  fs::create_directories(dir_, error);
  if (error) {
    throw Error("map library: cannot create the folder '" + dir_ + "': " + error.message());
  }
  const std::string path = pathFor(map.metadata().device_model, map.metadata().device_serial);
  saveMap(map, path);
  return path;
}

std::string MapLibrary::find(const std::string& model, const std::string& serial) const {
  std::error_code error;
  const std::string exact = pathFor(model, serial);
  if (fs::is_regular_file(exact, error)) return exact;
  return {};
}

std::string MapLibrary::findOtherUnit(const std::string& model, const std::string& serial) const {
  const std::string own = pathFor(model, serial);
  const std::string prefix = fileSafe(model);
  std::string newest;
  fs::file_time_type newest_time{};
  for (const std::string& path : list()) {
    const std::string name = fs::path(path).filename().string();
    const bool of_model = name == prefix + ".json" || name.rfind(prefix + "@", 0) == 0;
    if (!of_model || path == own) continue;
    try {
      const GravityMap map = loadMap(path);
      if (map.metadata().device_model != model || map.metadata().prior) continue;
    } catch (const Error&) {
      continue;  // not a map this version reads: not a prior
    }
    std::error_code error;
    const fs::file_time_type time = fs::last_write_time(path, error);
    if (!error && (newest.empty() || time > newest_time)) {
      newest = path;
      newest_time = time;
    }
  }
  return newest;
}

std::vector<std::string> MapLibrary::list() const {
  std::vector<std::string> paths;
  std::error_code error;
  if (!fs::is_directory(dir_, error)) return paths;
  for (const auto& entry : fs::directory_iterator(dir_, error)) {
    if (entry.is_regular_file(error) && entry.path().extension() == ".json") {
      paths.push_back(entry.path().string());
    }
  }
  std::sort(paths.begin(), paths.end());
  return paths;
}

GravityMap loadMapForUnit(const std::string& model, const std::string& serial,
                          const std::string& dir) {
  const MapLibrary library(dir);
  const std::string path = library.find(model, serial);
  if (path.empty()) {
    std::string held;
    for (const std::string& other : library.list()) {
      held += (held.empty() ? "" : ", ") + fs::path(other).filename().string();
    }
    throw Error("no map for the device " + describe(model, serial) + " in the map library '" +
                library.dir() + "' (" + (held.empty() ? "it holds none" : "it holds " + held) +
                "); calibrate this device first (CalibrationWizard, then MapLibrary::save), or "
                "name a map file");
  }
  MapLoadOptions options;
  options.expected_device_model = model;
  GravityMap map = loadMap(path, options);
  if (map.metadata().device_serial != serial) {
    throw Error("the map '" + path + "' was made on serial \"" + map.metadata().device_serial +
                "\" but the device is " + describe(model, serial) + "; calibrate this unit");
  }
  return map;
}

}  // namespace autograv
