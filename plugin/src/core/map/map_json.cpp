#include "core/map/map_json.h"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <initializer_list>
#include <limits>
#include <sstream>
#include <utility>
#include <vector>

#include "autograv/error.h"

namespace autograv::detail {

namespace {

using nlohmann::json;

json vectorToJson(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

json vectorToJson(const Eigen::Vector3i& v) { return json::array({v.x(), v.y(), v.z()}); }

}  // namespace

json parametersDocument(const EstimationParameters& p) {
  return json{{"alpha_per_s", p.alpha_per_s},
              {"beta_per_s2", p.beta_per_s2},
              {"k0_n_per_m", p.k0_n_per_m},
              {"n_s", p.n_s},
              {"eps_s_m_per_s", p.eps_s_m_per_s},
              {"n_g", p.n_g},
              {"eps_g_n", p.eps_g_n},
              {"min_step_duration_s", p.min_step_duration_s},
              {"max_step_duration_s", p.max_step_duration_s},
              {"max_iterations", p.max_iterations},
              {"servo_period_s", p.servo_period_s},
              {"lipschitz_prior_n_per_m", p.lipschitz_prior_n_per_m},
              {"method", toString(p.method)},
              {"dither_amplitude_n", p.dither_amplitude_n},
              {"dither_frequency_hz", p.dither_frequency_hz},
              {"dither_periods_per_window", p.dither_periods_per_window},
              {"steady_windows", p.steady_windows},
              {"final_steady_windows", p.final_steady_windows}};
}

namespace {

json vertexToJson(const WorkspaceGrid& grid, int index, const VertexEstimate& vertex) {
  json history = json::array();
  for (const IterationRecord& record : vertex.history) {
    history.push_back(json{{"position_error_m", record.position_error_m},
                           {"mass_estimate_kg", record.mass_estimate_kg},
                           {"gravity_estimate_n", vectorToJson(record.gravity_estimate_n)},
                           {"duration_s", record.duration_s}});
  }
  json object{{"index", index},
              {"position_m", vectorToJson(grid.vertexPosition(index))},
              {"gravity_n", vectorToJson(vertex.gravity_n)},
              {"iterations", vertex.iterations},
              {"seconds", vertex.seconds},
              {"outcome", toString(vertex.outcome)},
              {"provenance", toString(vertex.provenance)},
              {"history", std::move(history)}};
  if (vertex.measuredOffVertex()) {
    object["measured_at_m"] = vectorToJson(vertex.measured_at_m);
    object["measured_gravity_n"] = vectorToJson(vertex.measured_gravity_n);
  }
  return object;
}

json reviewedToJson(const ReviewedMeasurement& reviewed) {
  return json{{"vertex", reviewed.first.vertex},
              {"point_m", vectorToJson(reviewed.first.point_m)},
              {"value_n", vectorToJson(reviewed.first.value_n)},
              {"residual_rel", reviewed.first.residual_rel},
              {"local_rel", reviewed.first.local_rel},
              {"again_point_m", vectorToJson(reviewed.again_point_m)},
              {"again_value_n", vectorToJson(reviewed.again_value_n)},
              {"again_residual_rel", reviewed.again_residual_rel},
              {"verdict", toString(reviewed.verdict)}};
}

json workspaceToJson(const ExploredWorkspace& workspace) {
  json directions = json::array();
  for (const Eigen::Vector3d& u : workspace.directions()) directions.push_back(vectorToJson(u));
  return json{{"center_m", vectorToJson(workspace.center_m())},
              {"directions", std::move(directions)},
              {"radii_m", workspace.radii_m()}};
}

json vectorsToJson(const std::vector<Eigen::Vector3d>& vectors) {
  json array = json::array();
  for (const Eigen::Vector3d& v : vectors) array.push_back(vectorToJson(v));
  return array;
}

json priorToJson(const MapPrior& prior) {
  // Row-major: gain[i][j] multiplies component j of the prior's value into component i.
  json gain = json::array();
  for (int row = 0; row < 3; ++row) {
    gain.push_back(vectorToJson(Eigen::Vector3d(prior.gain.row(row).transpose())));
  }
  return json{{"source", prior.source},
              {"device_serial", prior.device_serial},
              {"created_utc", prior.created_utc},
              {"correction_model", prior.correction_model},
              {"gain", std::move(gain)},
              {"offset_n", vectorToJson(prior.offset_n)},
              {"points_m", vectorsToJson(prior.points_m)},
              {"residuals_n", vectorsToJson(prior.residuals_n)},
              {"check_points", prior.check_points},
              {"check_mean_rel", prior.check_mean_rel},
              {"check_max_rel", prior.check_max_rel},
              {"workspace_difference_m", prior.workspace_difference_m}};
}

}  // namespace

std::string currentUtcTimestamp() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

std::string documentChecksum(const json& document) {
  json content = document;
  if (content.is_object()) content.erase("checksum");
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016" PRIx64, fnv1a64(content.dump()));
  return hex;
}

void stampChecksum(json& document) {
  document["checksum"] =
      json{{"algorithm", kChecksumAlgorithm}, {"value", documentChecksum(document)}};
}

json mapToDocument(const GravityMap& map) {
  const MapMetadata& metadata = map.metadata();
  if (metadata.device_model.empty()) {
    throw Error(
        "cannot save gravity map: metadata.device_model is empty; set it to the model_name of "
        "the device the map was calibrated on (maps are tied to a device model)");
  }
  const WorkspaceGrid& grid = map.grid();
  json vertices = json::array();
  for (int i = 0; i < grid.vertexCount(); ++i) {
    vertices.push_back(vertexToJson(grid, i, map.vertices()[static_cast<std::size_t>(i)]));
  }
  json document{
      {"format", kMapFormatName},
      {"schema_version", kMapSchemaVersion},
      {"units", json{{"length", "m"}, {"force", "N"}, {"time", "s"}, {"mass", "kg"}}},
      {"device", json{{"model", metadata.device_model}, {"serial", metadata.device_serial}}},
      {"created_utc", metadata.created_utc.empty() ? currentUtcTimestamp() : metadata.created_utc},
      {"grid", json{{"center_m", vectorToJson(grid.center_m())},
                    {"size_m", vectorToJson(grid.size_m())},
                    {"resolution", vectorToJson(grid.resolution())}}},
      {"parameters", parametersDocument(metadata.parameters)},
      {"vertices", std::move(vertices)},
  };
  if (!metadata.workspace.empty()) document["workspace"] = workspaceToJson(metadata.workspace);
  if (metadata.lookup_refinement != 1) {
    document["grid"]["lookup_refinement"] = metadata.lookup_refinement;
  }
  json field_model{{"name", toString(metadata.field_model)}, {"curl_weight", metadata.curl_weight}};
  if (!metadata.field_model_scores.empty()) {
    json scores = json::array();
    for (const FieldModelScore& score : metadata.field_model_scores) {
      scores.push_back(json{{"name", toString(score.model)},
                            {"curl_weight", score.curl_weight},
                            {"loo_median_rel", score.median_rel},
                            {"loo_p90_rel", score.p90_rel},
                            {"loo_mean_rel", score.mean_rel}});
    }
    field_model["scores"] = std::move(scores);
  }
  document["field_model"] = std::move(field_model);
  // Only maps corrected from another unit's map have one: a calibrated map's file is unchanged.
  if (metadata.prior) document["prior"] = priorToJson(*metadata.prior);
  // Only maps whose calibration measured a point again have it.
  if (!metadata.reviewed_measurements.empty()) {
    json reviewed = json::array();
    for (const ReviewedMeasurement& entry : metadata.reviewed_measurements) {
      reviewed.push_back(reviewedToJson(entry));
    }
    document["reviewed_measurements"] = std::move(reviewed);
  }
  // Only maps whose calibration measured its first points again to see its motors warm.
  const ThermalDrift& drift = metadata.thermal_drift;
  if (drift.points > 0) {
    document["thermal_drift"] = json{{"gain_loss_per_load", drift.gain_loss_per_load},
                                     {"gain_loss_standard_error", drift.gain_loss_standard_error},
                                     {"points", drift.points},
                                     {"first_load", drift.first_load},
                                     {"again_load", drift.again_load},
                                     {"drift_rel", drift.drift_rel}};
  }
  stampChecksum(document);
  // Whatever is written must load again: validate with the reader itself, so that a bad value
  // (a NaN in a history record, a malformed timestamp) is refused here and not found later.
  try {
    mapFromDocument(document, "<map being saved>", MapLoadOptions{});
  } catch (const Error& error) {
    throw Error(std::string("cannot save gravity map, it would not load again: ") + error.what());
  }
  return document;
}

}  // namespace autograv::detail

namespace autograv {

std::string parametersToJson(const EstimationParameters& parameters) {
  return detail::parametersDocument(parameters).dump();
}

}  // namespace autograv
