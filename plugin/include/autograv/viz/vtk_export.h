#pragma once

#include <string>

#include "autograv/map/gravity_map.h"
#include "autograv/viz/common.h"

namespace autograv::viz {

/// Options of exportMap.
struct ExportOptions {
  /// When set, adds the point arrays "true_gravity_N" and "residual_N" (|G_hat - G_true|).
  GroundTruth ground_truth;
};

/// Writes `map` as a VTK XML file that ParaView opens: ".vti" (image data) or ".vtu"
/// (unstructured grid of hexahedra). Points are in metres. Point arrays: "gravity_N" (vectors,
/// active), "gravity_magnitude_N", "apparent_mass_kg", "outcome" (codes; field "outcome_names"
/// lists their names), "iterations" and "seconds_s". Field data: "device_model", "length_unit".
/// Written in ASCII (maps are small), needs no display. Throws autograv::Error naming the file
/// for another extension or when it cannot be written. Not real-time safe.
void exportMap(const GravityMap& map, const std::string& path, const ExportOptions& options = {});

}  // namespace autograv::viz
