#pragma once

#include <string>
#include <vector>

#include "autograv/map/gravity_map.h"

namespace autograv {

/// The folder maps are kept in when none is named: $XDG_DATA_HOME/autograv/maps, or
/// ~/.local/share/autograv/maps when XDG_DATA_HOME is unset or empty. Throws autograv::Error when
/// neither XDG_DATA_HOME nor HOME is set. Not real-time safe.
std::string defaultMapLibraryDir();

/// One folder of maps, one per device, named by model and serial number (so a lab with two
/// Omegas keeps both): "<model>.json", or "<model>@<serial>.json" when the driver reports a serial,
/// with every character outside [A-Za-z0-9._-] replaced by '_'. Not real-time safe.
///
/// A device is named by what its DeviceSpecifications report, `model_name` and `serial_number`:
/// the members that take a device are templates on that pair, so that the map depends on no
/// device header (the device library's decorator holds maps).
class MapLibrary {
 public:
  /// An empty `dir` means defaultMapLibraryDir(). The folder need not exist until save().
  explicit MapLibrary(std::string dir = {});

  /// The library's folder.
  const std::string& dir() const noexcept { return dir_; }
  /// Where the map of this device (a DeviceSpecifications) is (or would be) kept.
  template <class Specifications>
  std::string pathFor(const Specifications& device) const {
    return pathFor(device.model_name, device.serial_number);
  }
  /// The same for a model and a serial number (empty when unknown).
  std::string pathFor(const std::string& model, const std::string& serial) const;
  /// Saves `map` under its metadata's model and serial, creating the folder if needed; returns the
  /// path. Throws autograv::Error when it cannot.
  std::string save(const GravityMap& map) const;
  /// The path of the map that fits `device` (a DeviceSpecifications): the one made on this very
  /// unit (model and serial), else, when the device reports no serial, the one of its model.
  /// Empty when none fits.
  template <class Specifications>
  std::string find(const Specifications& device) const {
    return find(device.model_name, device.serial_number);
  }
  /// The same for a model and a serial number (empty when unknown).
  std::string find(const std::string& model, const std::string& serial) const;
  /// The newest map (by file time) of another unit of `model`: a prior for a unit that has none
  /// yet (transferMap, `--like library`). The map of the unit `serial` itself is skipped, and so
  /// are maps that were themselves corrected from another's (a prior is a whole calibration).
  /// Empty when none fits.
  std::string findOtherUnit(const std::string& model, const std::string& serial) const;
  /// Every map file in the folder (sorted), empty when the folder does not exist.
  std::vector<std::string> list() const;

 private:
  std::string dir_;
};

/// Loads the map of the unit `model` with serial number `serial` (empty when unknown) from the
/// library in `dir` (empty: the default folder), checked against that model and serial. Throws
/// autograv::Error naming the folder, the maps it holds and how to make one when none fits. Not
/// real-time safe.
GravityMap loadMapForUnit(const std::string& model, const std::string& serial,
                          const std::string& dir = {});

/// loadMapForUnit for `device` (a DeviceSpecifications): its model_name and serial_number.
template <class Specifications>
GravityMap loadMapForDevice(const Specifications& device, const std::string& dir = {}) {
  return loadMapForUnit(device.model_name, device.serial_number, dir);
}

}  // namespace autograv
