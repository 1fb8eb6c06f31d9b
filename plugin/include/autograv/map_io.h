#pragma once

#include <string>

#include "autograv/gravity_map.h"

namespace autograv {

/// Current map file schema version; files with another major version are refused.
inline constexpr int kMapSchemaVersion = 1;

struct MapLoadOptions {
  /// When non-empty, a map whose device_model differs is refused.
  std::string expected_device_model;
  /// Accept a map made for another device model anyway.
  bool allow_model_mismatch = false;
};

/// Reads and fully validates a JSON map file (schema, units, grid, parameters, every vertex,
/// checksum). Throws autograv::Error naming the file, the field and what was expected; nothing
/// half-loaded is ever returned. Not real-time safe.
GravityMap loadMap(const std::string& path, const MapLoadOptions& options = {});

/// Writes `map` atomically: a temporary file in the same folder, flushed, then renamed over
/// `path`, so a crash mid-write never destroys the previous file. Throws autograv::Error.
/// Not real-time safe.
void saveMap(const GravityMap& map, const std::string& path);

}  // namespace autograv
