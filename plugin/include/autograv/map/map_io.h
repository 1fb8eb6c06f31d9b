#pragma once

#include <cstdint>
#include <string>

#include "autograv/map/gravity_map.h"

namespace autograv {

/// Map file schema version written by saveMap. Schema 8 adds what the calibration saw of its
/// motors warming and the correction the decorator applies for it (thermal_drift); schema 7 adds
/// the measurements the calibration measured again because the others contradicted them
/// (reviewed_measurements), the vertices left out of the fit (outcome "left_out"); schema 6 adds,
/// for a map corrected from another unit's map, where it came from and the correction (prior);
/// schema 5 names the field model and the scores it was chosen by (field_model); schema 4 adds the
/// lookup's interpolant (grid.lookup_interpolant: "thin_plate", the default, or "conservative");
/// schema 3 adds the explored workspace and the points measured off their vertices; schema 2 (box
/// grids and where each vertex's value came from) and schema 1 (cubic grids) files still load.
/// Other versions are refused.
inline constexpr int kMapSchemaVersion = 8;
/// Oldest schema version loadMap reads.
inline constexpr int kOldestMapSchemaVersion = 1;

/// What loadMap checks besides the file's own consistency.
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

/// Writes `text` to `path` so that `path` holds either its previous content or all of `text`,
/// whatever happens: a unique temporary file in the same folder (rename is atomic only within
/// one file system), written, fsync'ed, renamed over the target, then the folder fsync'ed so
/// that the rename itself survives a power cut. What saveMap does; reports use it too. A path
/// that names a device or a pipe (/dev/null, /dev/stdout) is written into instead, never replaced.
/// Throws autograv::Error saying "saving <what> '<path>': ..." and why (disk full, read-only
/// folder, ...). Not real-time safe.
void writeFileAtomically(const std::string& path, const std::string& text,
                         const std::string& what = "file");

/// Throws autograv::Error saying "cannot write <what> '<path>': ..." and why when
/// writeFileAtomically could not write `path` now (the folder is missing, read-only or full), so
/// that a long run can refuse at its start rather than fail at its end. Creates and removes a
/// one-byte temporary file in the folder; leaves `path` alone. Not real-time safe.
void checkWritable(const std::string& path, const std::string& what = "file");

// --- In-memory form and checksum (additions for tools and tests) ---------------------------
//
// File format (schema version 8), one JSON object:
//   format "autograv-gravity-map", schema_version, units {length m, force N, time s, mass kg},
//   device {model, serial}, created_utc (ISO 8601, UTC, "Z"), grid {center_m[3], size_m[3],
//   resolution[3]} (extents and vertex counts along x, y, z; from schema 3 lookup_refinement,
//   schema 4 only lookup_interpolant), from schema 5 field_model {name (conservative,
//   componentwise, corrected, thin_plate), curl_weight, scores[] of {name, curl_weight,
//   loo_median_rel, loo_p90_rel, loo_mean_rel} where the model was chosen}, from schema 7 and only
//   where the calibration measured a point again reviewed_measurements[] of {vertex, point_m[3],
//   value_n[3], residual_rel, local_rel, again_point_m[3], again_value_n[3], again_residual_rel,
//   left_out}, from schema 8 and only where the calibration measured its first points again
//   thermal_drift {gain_loss_per_load, gain_loss_standard_error, points, first_load, again_load,
//   drift_rel}, from schema 6 and only for a map corrected from another unit's map prior {source,
//   device_serial, created_utc (ISO 8601 or ""), correction_model (shift, affine, conservative,
//   componentwise), gain (3 rows of 3), offset_n[3], points_m[] of [3], residuals_n[] of [3] (none,
//   or one per point), check_points, check_mean_rel, check_max_rel, workspace_difference_m},
//   parameters {every EstimationParameters field under its C++ name}, vertices[] (one object per
//   grid vertex, in vertex-index order ix + nx (iy + ny iz): index, position_m[3], gravity_n[3],
//   iterations, seconds, outcome (pending, converged, iteration_cap, no_steady_state, saturated,
//   device_fault, unreachable, from schema 7 left_out: then with measured_at_m and
//   measured_gravity_n), provenance ("measured": estimated at the vertex; "filled":
//   filled from measured vertices because the device could not reach it), history[] of
//   {position_error_m, mass_estimate_kg, gravity_estimate_n[3], duration_s}), and checksum
//   {algorithm "fnv1a-64", value}.
// Schema version 1 differs only in its grid, a cube {center_m[3], side_m, resolution}, and in
// its vertices, which have no provenance (all measured) and no "unreachable" outcome.
// The checksum is FNV-1a 64 over the UTF-8 bytes of the compact canonical dump of the whole
// document WITHOUT its "checksum" member (nlohmann::json::dump() with no indent: keys sorted,
// no spaces, doubles in shortest round-trip form), written as 16 lower-case hex digits.

/// FNV-1a 64-bit hash of `bytes` (offset basis 0xcbf29ce484222325, prime 0x100000001b3).
/// Real-time safe (no allocation).
std::uint64_t fnv1a64(const std::string& bytes) noexcept;

/// The exact text saveMap writes for `map` (indented JSON with its checksum). An empty
/// metadata.created_utc is replaced by the current UTC time. Throws autograv::Error when the map
/// cannot be written as a valid file (empty device model, non-finite history values).
/// Not real-time safe.
std::string mapToJson(const GravityMap& map);

/// The "parameters" object of a map file on its own (compact JSON text, the same keys and SI
/// units), for reports. Not real-time safe.
std::string parametersToJson(const EstimationParameters& parameters);

/// Parses and validates `text` exactly as loadMap validates a file; `source` names the text in
/// error messages (a path, "<stdin>", ...). Not real-time safe.
GravityMap mapFromJson(const std::string& text, const std::string& source,
                       const MapLoadOptions& options = {});

}  // namespace autograv
