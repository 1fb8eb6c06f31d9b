#pragma once

// Private: the JSON document form of a gravity map, shared by map_io.cpp and the tests (which
// corrupt single fields of a valid document to check that the loader names them).

#include <string>

#include <nlohmann/json.hpp>

#include "autograv/map/gravity_map.h"
#include "autograv/map/map_io.h"

namespace autograv::detail {

/// Value of the "format" member of every map document.
inline constexpr const char* kMapFormatName = "autograv-gravity-map";
/// Value of "checksum"/"algorithm".
inline constexpr const char* kChecksumAlgorithm = "fnv1a-64";

/// The complete document, checksum included. Throws autograv::Error when `map` cannot make a valid
/// file (the result is validated with mapFromDocument before it is returned).
/// Not real-time safe.
nlohmann::json mapToDocument(const GravityMap& map);

/// Validates every field of `document` and builds the map. Throws autograv::Error naming
/// `source`, the JSON pointer of the offending field and what was expected.
/// Not real-time safe.
GravityMap mapFromDocument(const nlohmann::json& document, const std::string& source,
                           const MapLoadOptions& options);

/// 16 lower-case hex digits of FNV-1a 64 over the compact dump of `document` without its
/// "checksum" member. Not real-time safe.
std::string documentChecksum(const nlohmann::json& document);

/// Re-computes and stores the checksum member (for tests that edit a document on purpose).
void stampChecksum(nlohmann::json& document);

/// Current UTC time as "YYYY-MM-DDTHH:MM:SSZ". Not real-time safe.
std::string currentUtcTimestamp();

}  // namespace autograv::detail
