#include "core/map/map_json.h"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <sstream>
#include <utility>
#include <vector>

#include "autograv/error.h"

// The reader of the map document (mapFromDocument): every field checked and, when wrong, named
// by its JSON pointer. The writer is map_json.cpp.

namespace autograv::detail {

namespace {

using nlohmann::json;

/// Short description of a JSON value for error messages: its type and the start of its text.
std::string describe(const json& value) {
  std::string text = value.dump();
  if (text.size() > 48) text = text.substr(0, 45) + "...";
  return std::string(value.type_name()) + " " + text;
}

/// Escapes a member name for a JSON pointer (RFC 6901).
std::string escapePointerToken(const std::string& key) {
  std::string escaped;
  for (const char c : key) {
    if (c == '~') {
      escaped += "~0";
    } else if (c == '/') {
      escaped += "~1";
    } else {
      escaped += c;
    }
  }
  return escaped;
}

/// "YYYY-MM-DDTHH:MM:SS[.fraction]Z" with plausible field ranges. (std::regex would do, but
/// GCC 12 warns inside <regex> under the sanitizers.)
bool isIso8601Utc(const std::string& text) {
  const auto digits = [&](std::size_t from, std::size_t count, int low, int high) {
    if (from + count > text.size()) return false;
    int value = 0;
    for (std::size_t i = from; i < from + count; ++i) {
      if (text[i] < '0' || text[i] > '9') return false;
      value = 10 * value + (text[i] - '0');
    }
    return value >= low && value <= high;
  };
  if (text.size() < 20 || text[4] != '-' || text[7] != '-' || text[10] != 'T' || text[13] != ':' ||
      text[16] != ':' || text.back() != 'Z') {
    return false;
  }
  if (!digits(0, 4, 0, 9999) || !digits(5, 2, 1, 12) || !digits(8, 2, 1, 31) ||
      !digits(11, 2, 0, 23) || !digits(14, 2, 0, 59) || !digits(17, 2, 0, 60)) {
    return false;
  }
  if (text.size() == 20) return true;
  // A fraction: '.', at least one digit, then the final 'Z'.
  if (text[19] != '.' || text.size() < 22) return false;
  return std::all_of(text.begin() + 20, text.end() - 1,
                     [](char c) { return c >= '0' && c <= '9'; });
}

enum class Range { kAny, kNonNegative, kPositive };

/// Walks a document and throws autograv::Error naming the source, the JSON pointer of the field
/// and what was expected at the first problem it finds.
class DocumentReader {
 public:
  explicit DocumentReader(std::string source) : source_(std::move(source)) {}

  /// The schema version the document declares, named in messages about missing or extra fields.
  void setSchemaVersion(int version) { schema_version_ = version; }
  int schemaVersion() const { return schema_version_; }

  [[noreturn]] void fail(const std::string& pointer, const std::string& message) const {
    throw Error("map file '" + source_ + "': field " + (pointer.empty() ? "/" : pointer) + ": " +
                message);
  }

  [[noreturn]] void expected(const std::string& pointer, const std::string& what,
                             const json& got) const {
    fail(pointer, "expected " + what + ", got " + describe(got));
  }

  /// `value` must be an object holding all of `keys`, and nothing but them and `optional_keys`.
  void requireObject(const json& value, const std::string& pointer,
                     std::initializer_list<const char*> keys,
                     std::initializer_list<const char*> optional_keys = {}) const {
    if (!value.is_object()) expected(pointer, "an object", value);
    for (const char* key : keys) {
      if (!value.contains(key)) {
        fail(pointer + "/" + key,
             "missing (required by schema version " + std::to_string(schema_version_) + ")");
      }
    }
    for (auto it = value.begin(); it != value.end(); ++it) {
      const auto is_key = [&](const char* key) { return it.key() == key; };
      const bool known = std::any_of(keys.begin(), keys.end(), is_key) ||
                         std::any_of(optional_keys.begin(), optional_keys.end(), is_key);
      if (!known) {
        fail(pointer + "/" + escapePointerToken(it.key()),
             "unexpected field (not part of schema version " + std::to_string(schema_version_) +
                 "; misspelt, or written by a newer autograv?)");
      }
    }
  }

  double number(const json& parent, const std::string& parent_pointer, const char* key, Range range,
                const char* unit) const {
    const std::string pointer = parent_pointer + "/" + key;
    const json& value = parent.at(key);
    const char* range_text = range == Range::kPositive      ? "a finite number > 0"
                             : range == Range::kNonNegative ? "a finite number >= 0"
                                                            : "a finite number";
    const std::string what = std::string(range_text) + " (unit: " + unit + ")";
    if (!value.is_number()) expected(pointer, what, value);
    const double x = value.get<double>();
    const bool ok =
        std::isfinite(x) && (range == Range::kAny || (range == Range::kNonNegative && x >= 0.0) ||
                             (range == Range::kPositive && x > 0.0));
    if (!ok) expected(pointer, what, value);
    return x;
  }

  int integer(const json& parent, const std::string& parent_pointer, const char* key, int min,
              int max) const {
    return integerValue(parent.at(key), parent_pointer + "/" + key, min, max);
  }

  std::string string(const json& parent, const std::string& parent_pointer, const char* key,
                     bool non_empty) const {
    const std::string pointer = parent_pointer + "/" + key;
    const json& value = parent.at(key);
    if (!value.is_string() || (non_empty && value.get_ref<const std::string&>().empty())) {
      expected(pointer, non_empty ? "a non-empty string" : "a string", value);
    }
    return value.get<std::string>();
  }

  Eigen::Vector3d vector3(const json& parent, const std::string& parent_pointer, const char* key,
                          const char* unit) const {
    return vector3Value(parent.at(key), parent_pointer + "/" + key, unit);
  }

  /// Three finite numbers at `pointer` (an element of an array, or a member).
  Eigen::Vector3d vector3Value(const json& value, const std::string& pointer,
                               const char* unit) const {
    const std::string what = std::string("an array of 3 finite numbers (unit: ") + unit + ")";
    if (!value.is_array() || value.size() != 3) expected(pointer, what, value);
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) {
      const json& element = value[static_cast<std::size_t>(i)];
      if (!element.is_number() || !std::isfinite(element.get<double>())) {
        expected(pointer + "/" + std::to_string(i),
                 std::string("a finite number (unit: ") + unit + ")", element);
      }
      v[i] = element.get<double>();
    }
    return v;
  }

  /// Three integers in [min, max], e.g. vertices per axis.
  Eigen::Vector3i integer3(const json& parent, const std::string& parent_pointer, const char* key,
                           int min, int max) const {
    const std::string pointer = parent_pointer + "/" + key;
    const json& value = parent.at(key);
    if (!value.is_array() || value.size() != 3) {
      expected(
          pointer,
          "an array of 3 integers in [" + std::to_string(min) + ", " + std::to_string(max) + "]",
          value);
    }
    Eigen::Vector3i v;
    for (int i = 0; i < 3; ++i) {
      v[i] = integerValue(value[static_cast<std::size_t>(i)], pointer + "/" + std::to_string(i),
                          min, max);
    }
    return v;
  }

  const std::string& source() const { return source_; }

 private:
  int integerValue(const json& value, const std::string& pointer, int min, int max) const {
    const std::string what =
        "an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "]";
    if (!value.is_number_integer()) expected(pointer, what, value);
    // Read as a 64-bit signed value first so that huge numbers do not wrap into range.
    if (value.is_number_unsigned() &&
        value.get<std::uint64_t>() > static_cast<std::uint64_t>(max)) {
      expected(pointer, what, value);
    }
    const std::int64_t x = value.get<std::int64_t>();
    if (x < min || x > max) expected(pointer, what, value);
    return static_cast<int>(x);
  }

  std::string source_;
  int schema_version_ = kMapSchemaVersion;
};

EstimationParameters readParameters(const DocumentReader& reader, const json& value) {
  const std::string p = "/parameters";
  reader.requireObject(value, p,
                       {"alpha_per_s", "beta_per_s2", "k0_n_per_m", "n_s", "eps_s_m_per_s", "n_g",
                        "eps_g_n", "min_step_duration_s", "max_step_duration_s", "max_iterations",
                        "servo_period_s", "lipschitz_prior_n_per_m"},
                       // Optional: maps made before the dither method was the paper's method.
                       {"method", "dither_amplitude_n", "dither_frequency_hz",
                        "dither_periods_per_window", "steady_windows", "final_steady_windows"});
  constexpr int kMaxCount = 1000000;
  // A file without "method" was written before the dither method existed.
  EstimationParameters parameters = EstimationParameters::paper();
  parameters.alpha_per_s = reader.number(value, p, "alpha_per_s", Range::kPositive, "1/s");
  parameters.beta_per_s2 = reader.number(value, p, "beta_per_s2", Range::kPositive, "1/s^2");
  parameters.k0_n_per_m = reader.number(value, p, "k0_n_per_m", Range::kPositive, "N/m");
  parameters.n_s = reader.integer(value, p, "n_s", 1, kMaxCount);
  parameters.eps_s_m_per_s = reader.number(value, p, "eps_s_m_per_s", Range::kPositive, "m/s");
  parameters.n_g = reader.integer(value, p, "n_g", 1, kMaxCount);
  parameters.eps_g_n = reader.number(value, p, "eps_g_n", Range::kPositive, "N");
  parameters.min_step_duration_s =
      reader.number(value, p, "min_step_duration_s", Range::kNonNegative, "s");
  parameters.max_step_duration_s =
      reader.number(value, p, "max_step_duration_s", Range::kPositive, "s");
  if (parameters.max_step_duration_s < parameters.min_step_duration_s) {
    reader.expected(p + "/max_step_duration_s", "a duration >= /parameters/min_step_duration_s",
                    value.at("max_step_duration_s"));
  }
  parameters.max_iterations = reader.integer(value, p, "max_iterations", 1, kMaxCount);
  parameters.servo_period_s = reader.number(value, p, "servo_period_s", Range::kPositive, "s");
  parameters.lipschitz_prior_n_per_m =
      reader.number(value, p, "lipschitz_prior_n_per_m", Range::kNonNegative, "N/m");
  if (value.contains("method")) {
    const std::string method = reader.string(value, p, "method", true);
    if (method == toString(EstimationMethod::kPaper)) {
      parameters.method = EstimationMethod::kPaper;
    } else if (method == toString(EstimationMethod::kDither)) {
      parameters.method = EstimationMethod::kDither;
    } else {
      reader.expected(p + "/method", "\"paper\" or \"dither\"", value.at("method"));
    }
  }
  if (value.contains("dither_amplitude_n")) {
    parameters.dither_amplitude_n =
        reader.number(value, p, "dither_amplitude_n", Range::kNonNegative, "N");
  }
  if (value.contains("dither_frequency_hz")) {
    parameters.dither_frequency_hz =
        reader.number(value, p, "dither_frequency_hz", Range::kPositive, "Hz");
  }
  if (value.contains("dither_periods_per_window")) {
    parameters.dither_periods_per_window =
        reader.integer(value, p, "dither_periods_per_window", 1, kMaxCount);
  }
  if (value.contains("steady_windows")) {
    parameters.steady_windows = reader.integer(value, p, "steady_windows", 1, kMaxCount);
  }
  // Maps made before the final windows existed read their steady state like the others.
  parameters.final_steady_windows =
      value.contains("final_steady_windows")
          ? reader.integer(value, p, "final_steady_windows", 1, kMaxCount)
          : parameters.steady_windows;
  return parameters;
}

/// A model's name: one a saved map can have (never "choose": a map keeps what was chosen).
FieldModel readModelName(const DocumentReader& reader, const json& value, const std::string& path) {
  FieldModel model = FieldModel::kThinPlate;
  const std::string name = reader.string(value, path, "name", true);
  if (!parseFieldModel(name, model) || model == FieldModel::kChoose) {
    reader.expected(path + "/name",
                    "\"conservative\", \"componentwise\", \"corrected\" or \"thin_plate\"",
                    value.at("name"));
  }
  return model;
}

void readFieldModel(const DocumentReader& reader, const json& value, MapMetadata& metadata) {
  const std::string path = "/field_model";
  reader.requireObject(value, path, {"name", "curl_weight"}, {"scores"});
  metadata.field_model = readModelName(reader, value, path);
  metadata.curl_weight = reader.number(value, path, "curl_weight", Range::kNonNegative, "1");
  if (metadata.curl_weight > FieldFit::kMaxCurlWeight) {
    reader.expected(path + "/curl_weight",
                    "a number in [0, " + std::to_string(FieldFit::kMaxCurlWeight) + "]",
                    value.at("curl_weight"));
  }
  if (!value.contains("scores")) return;
  const json& scores = value.at("scores");
  if (!scores.is_array() || scores.size() > 8) {
    reader.expected(path + "/scores", "an array of at most 8 candidate scores", scores);
  }
  for (std::size_t i = 0; i < scores.size(); ++i) {
    const std::string at = path + "/scores/" + std::to_string(i);
    const json& entry = scores[i];
    reader.requireObject(entry, at,
                         {"name", "curl_weight", "loo_median_rel", "loo_p90_rel", "loo_mean_rel"});
    FieldModelScore score;
    score.model = readModelName(reader, entry, at);
    score.curl_weight = reader.number(entry, at, "curl_weight", Range::kNonNegative, "1");
    score.median_rel = reader.number(entry, at, "loo_median_rel", Range::kNonNegative, "1");
    score.p90_rel = reader.number(entry, at, "loo_p90_rel", Range::kNonNegative, "1");
    score.mean_rel = reader.number(entry, at, "loo_mean_rel", Range::kNonNegative, "1");
    metadata.field_model_scores.push_back(score);
  }
}

WorkspaceGrid readGrid(const DocumentReader& reader, const json& value) {
  constexpr int kMinResolution = 2;
  constexpr int kMaxResolution = 64;
  if (reader.schemaVersion() == 1) {
    reader.requireObject(value, "/grid", {"center_m", "side_m", "resolution"});
    const Eigen::Vector3d center = reader.vector3(value, "/grid", "center_m", "m");
    const double side = reader.number(value, "/grid", "side_m", Range::kPositive, "m");
    const int resolution =
        reader.integer(value, "/grid", "resolution", kMinResolution, kMaxResolution);
    return WorkspaceGrid(center, side, resolution);
  }
  if (reader.schemaVersion() == 4) {
    reader.requireObject(value, "/grid", {"center_m", "size_m", "resolution"},
                         {"lookup_refinement", "lookup_interpolant"});
  } else if (reader.schemaVersion() >= 3) {
    reader.requireObject(value, "/grid", {"center_m", "size_m", "resolution"},
                         {"lookup_refinement"});
  } else {
    reader.requireObject(value, "/grid", {"center_m", "size_m", "resolution"});
  }
  const Eigen::Vector3d center = reader.vector3(value, "/grid", "center_m", "m");
  const Eigen::Vector3d size = reader.vector3(value, "/grid", "size_m", "m");
  for (int axis = 0; axis < 3; ++axis) {
    if (!(size[axis] > 0.0)) {
      reader.expected("/grid/size_m/" + std::to_string(axis), "a finite number > 0 (unit: m)",
                      value.at("size_m")[static_cast<std::size_t>(axis)]);
    }
  }
  const Eigen::Vector3i resolution =
      reader.integer3(value, "/grid", "resolution", kMinResolution, kMaxResolution);
  // Bounded per axis above, so the product (at most 64^3) cannot overflow.
  return WorkspaceGrid(center, size, resolution);
}

ExploredWorkspace readWorkspace(const DocumentReader& reader, const json& value) {
  const std::string p = "/workspace";
  reader.requireObject(value, p, {"center_m", "directions", "radii_m"});
  const Eigen::Vector3d center = reader.vector3(value, p, "center_m", "m");
  const json& directions = value.at("directions");
  const json& radii = value.at("radii_m");
  constexpr std::size_t kMaxDirections = ExploredWorkspace::kMaxDirections;
  if (!directions.is_array() || directions.size() < 6 || directions.size() > kMaxDirections) {
    reader.expected(p + "/directions",
                    "an array of 6 to " + std::to_string(kMaxDirections) + " direction vectors",
                    directions);
  }
  if (!radii.is_array() || radii.size() != directions.size()) {
    reader.expected(p + "/radii_m",
                    "an array of " + std::to_string(directions.size()) +
                        " distances (one per direction, unit: m)",
                    radii);
  }
  std::vector<Eigen::Vector3d> units;
  std::vector<double> distances;
  for (std::size_t i = 0; i < directions.size(); ++i) {
    const json wrapped_direction = json{{"d", directions[i]}};
    const json wrapped_radius = json{{"r", radii[i]}};
    const std::string at = std::to_string(i);
    const Eigen::Vector3d u = reader.vector3(wrapped_direction, p + "/directions", "d", "1");
    if (!(u.norm() > 1e-6)) {
      reader.expected(p + "/directions/" + at, "a non-zero direction", directions[i]);
    }
    units.push_back(u);
    distances.push_back(reader.number(wrapped_radius, p + "/radii_m", "r", Range::kPositive, "m"));
  }
  return ExploredWorkspace(center, std::move(units), std::move(distances));
}

/// The names toString(CorrectionModel) gives (maintenance/unit_transfer.h), spelt out here: the
/// map library does not depend on maintenance.
constexpr const char* kCorrectionModels[] = {"shift", "affine", "conservative", "componentwise"};

/// An array of at most `max_size` vectors of 3 finite numbers.
std::vector<Eigen::Vector3d> readVectors(const DocumentReader& reader, const json& parent,
                                         const std::string& parent_pointer, const char* key,
                                         std::size_t max_size, const char* unit) {
  const std::string pointer = parent_pointer + "/" + key;
  const json& value = parent.at(key);
  if (!value.is_array() || value.size() > max_size) {
    reader.expected(pointer,
                    "an array of at most " + std::to_string(max_size) +
                        " arrays of 3 finite numbers (unit: " + unit + ")",
                    value);
  }
  std::vector<Eigen::Vector3d> vectors;
  vectors.reserve(value.size());
  for (std::size_t i = 0; i < value.size(); ++i) {
    vectors.push_back(reader.vector3Value(value[i], pointer + "/" + std::to_string(i), unit));
  }
  return vectors;
}

MapPrior readPrior(const DocumentReader& reader, const json& value) {
  const std::string p = "/prior";
  reader.requireObject(
      value, p,
      {"source", "device_serial", "created_utc", "correction_model", "gain", "offset_n", "points_m",
       "residuals_n", "check_points", "check_mean_rel", "check_max_rel", "workspace_difference_m"});
  MapPrior prior;
  prior.source = reader.string(value, p, "source", false);
  prior.device_serial = reader.string(value, p, "device_serial", false);
  // Empty when the prior map's own time was unknown.
  prior.created_utc = reader.string(value, p, "created_utc", false);
  if (!prior.created_utc.empty() && !isIso8601Utc(prior.created_utc)) {
    reader.expected(p + "/created_utc",
                    "an ISO 8601 UTC time like \"2026-11-23T13:25:00Z\", or \"\" when unknown",
                    value.at("created_utc"));
  }
  prior.correction_model = reader.string(value, p, "correction_model", true);
  if (std::none_of(std::begin(kCorrectionModels), std::end(kCorrectionModels),
                   [&](const char* name) { return prior.correction_model == name; })) {
    reader.expected(p + "/correction_model",
                    "\"shift\", \"affine\", \"conservative\" or \"componentwise\"",
                    value.at("correction_model"));
  }
  const json& gain = value.at("gain");
  if (!gain.is_array() || gain.size() != 3) {
    reader.expected(p + "/gain", "an array of 3 rows of 3 finite numbers (unit: 1)", gain);
  }
  for (int row = 0; row < 3; ++row) {
    const json& values = gain[static_cast<std::size_t>(row)];
    prior.gain.row(row) =
        reader.vector3Value(values, p + "/gain/" + std::to_string(row), "1").transpose();
  }
  prior.offset_n = reader.vector3(value, p, "offset_n", "N");
  // A correction fits a few spot measurements; a field part takes at most FieldFit's count.
  const auto max_points = static_cast<std::size_t>(FieldFit::kMaxMeasurements);
  prior.points_m = readVectors(reader, value, p, "points_m", max_points, "m");
  prior.residuals_n = readVectors(reader, value, p, "residuals_n", max_points, "N");
  if (!prior.residuals_n.empty() && prior.residuals_n.size() != prior.points_m.size()) {
    reader.expected(p + "/residuals_n",
                    "an empty array or one of " + std::to_string(prior.points_m.size()) +
                        " residuals (one per point of /prior/points_m, unit: N)",
                    value.at("residuals_n"));
  }
  prior.check_points = reader.integer(value, p, "check_points", 0, 1000000);
  prior.check_mean_rel = reader.number(value, p, "check_mean_rel", Range::kNonNegative, "1");
  prior.check_max_rel = reader.number(value, p, "check_max_rel", Range::kNonNegative, "1");
  prior.workspace_difference_m =
      reader.number(value, p, "workspace_difference_m", Range::kNonNegative, "m");
  return prior;
}

std::vector<ReviewedMeasurement> readReviewed(const DocumentReader& reader, const json& value,
                                              const WorkspaceGrid& grid) {
  const std::string p = "/reviewed_measurements";
  if (!value.is_array() || value.size() > static_cast<std::size_t>(grid.vertexCount())) {
    reader.expected(p,
                    "an array of at most " + std::to_string(grid.vertexCount()) +
                        " reviewed measurements (one per vertex of the grid)",
                    value);
  }
  std::vector<ReviewedMeasurement> reviewed;
  for (std::size_t i = 0; i < value.size(); ++i) {
    const std::string at = p + "/" + std::to_string(i);
    const json& entry = value[i];
    reader.requireObject(entry, at,
                         {"vertex", "point_m", "value_n", "residual_rel", "local_rel",
                          "again_point_m", "again_value_n", "again_residual_rel", "verdict"});
    ReviewedMeasurement measurement;
    measurement.first.vertex = reader.integer(entry, at, "vertex", 0, grid.vertexCount() - 1);
    measurement.first.point_m = reader.vector3(entry, at, "point_m", "m");
    measurement.first.value_n = reader.vector3(entry, at, "value_n", "N");
    measurement.first.residual_rel =
        reader.number(entry, at, "residual_rel", Range::kNonNegative, "1");
    measurement.first.local_rel = reader.number(entry, at, "local_rel", Range::kNonNegative, "1");
    measurement.again_point_m = reader.vector3(entry, at, "again_point_m", "m");
    measurement.again_value_n = reader.vector3(entry, at, "again_value_n", "N");
    measurement.again_residual_rel =
        reader.number(entry, at, "again_residual_rel", Range::kNonNegative, "1");
    const std::string verdict = reader.string(entry, at, "verdict", true);
    if (!parseReviewVerdict(verdict, measurement.verdict)) {
      reader.expected(at + "/verdict",
                      "one of confirmed, replaced, left_out, not_measured_again, pending",
                      entry.at("verdict"));
    }
    reviewed.push_back(measurement);
  }
  return reviewed;
}

ThermalDrift readThermalDrift(const DocumentReader& reader, const json& value) {
  const std::string p = "/thermal_drift";
  reader.requireObject(value, p,
                       {"gain_loss_per_load", "gain_loss_standard_error", "points", "first_load",
                        "again_load", "drift_rel"});
  ThermalDrift drift;
  drift.gain_loss_per_load =
      reader.number(value, p, "gain_loss_per_load", Range::kNonNegative, "1 per unit load");
  if (drift.gain_loss_per_load > kMaxGainLossPerLoad) {
    reader.expected(
        p + "/gain_loss_per_load",
        "a loss of torque per unit load in [0, " + std::to_string(kMaxGainLossPerLoad) + "]",
        value.at("gain_loss_per_load"));
  }
  drift.gain_loss_standard_error =
      reader.number(value, p, "gain_loss_standard_error", Range::kNonNegative, "1 per unit load");
  drift.points = reader.integer(value, p, "points", 0, kThermalDriftPoints * 100);
  drift.first_load = reader.number(value, p, "first_load", Range::kNonNegative, "1");
  drift.again_load = reader.number(value, p, "again_load", Range::kNonNegative, "1");
  drift.drift_rel = reader.number(value, p, "drift_rel", Range::kAny, "1");
  return drift;
}

VertexEstimate readVertex(const DocumentReader& reader, const json& value,
                          const WorkspaceGrid& grid, int index) {
  const std::string p = "/vertices/" + std::to_string(index);
  const bool has_provenance = reader.schemaVersion() >= 2;
  if (reader.schemaVersion() >= 3) {
    reader.requireObject(value, p,
                         {"index", "position_m", "gravity_n", "iterations", "seconds", "outcome",
                          "provenance", "history"},
                         {"measured_at_m", "measured_gravity_n"});
    if (value.contains("measured_at_m") != value.contains("measured_gravity_n")) {
      reader.fail(p, "measured_at_m and measured_gravity_n come together or not at all");
    }
  } else if (has_provenance) {
    reader.requireObject(value, p,
                         {"index", "position_m", "gravity_n", "iterations", "seconds", "outcome",
                          "provenance", "history"});
  } else {
    reader.requireObject(
        value, p,
        {"index", "position_m", "gravity_n", "iterations", "seconds", "outcome", "history"});
  }
  const int stored_index = reader.integer(value, p, "index", 0, grid.vertexCount() - 1);
  if (stored_index != index) {
    reader.expected(p + "/index", std::to_string(index) + " (vertices are stored in index order)",
                    value.at("index"));
  }
  const Eigen::Vector3d position = reader.vector3(value, p, "position_m", "m");
  const Eigen::Vector3d expected_position = grid.vertexPosition(index);
  // The position is redundant (it follows from the grid); it is stored for people and other
  // tools, and a mismatch means the grid or the vertex order was edited.
  if ((position - expected_position).cwiseAbs().maxCoeff() >
      1e-9 + 1e-9 * grid.size_m().maxCoeff()) {
    std::ostringstream what;
    what.precision(17);
    what << "the grid position of vertex " << index << ", [" << expected_position.x() << ", "
         << expected_position.y() << ", " << expected_position.z()
         << "] m (was /grid or the vertex order edited?)";
    reader.expected(p + "/position_m", what.str(), value.at("position_m"));
  }
  VertexEstimate vertex;
  vertex.gravity_n = reader.vector3(value, p, "gravity_n", "N");
  vertex.iterations = reader.integer(value, p, "iterations", 0, 1000000000);
  vertex.seconds = reader.number(value, p, "seconds", Range::kNonNegative, "s");
  const std::string outcome = reader.string(value, p, "outcome", true);
  const bool has_left_out = reader.schemaVersion() >= 7;
  if (!parseVertexOutcome(outcome, vertex.outcome) ||
      (!has_provenance && vertex.outcome == VertexOutcome::kUnreachable) ||
      (!has_left_out && vertex.outcome == VertexOutcome::kLeftOut)) {
    reader.expected(p + "/outcome",
                    std::string("one of pending, converged, iteration_cap, no_steady_state, "
                                "saturated, device_fault") +
                        (has_left_out     ? ", unreachable, left_out"
                         : has_provenance ? ", unreachable"
                                          : " (schema version 1)"),
                    value.at("outcome"));
  }
  if (vertex.outcome == VertexOutcome::kLeftOut && !value.contains("measured_at_m")) {
    reader.fail(p,
                "a vertex left out keeps what it measured: measured_at_m and "
                "measured_gravity_n are missing");
  }
  if (has_provenance) {
    const std::string provenance = reader.string(value, p, "provenance", true);
    if (!parseVertexProvenance(provenance, vertex.provenance)) {
      reader.expected(p + "/provenance", "one of measured, filled", value.at("provenance"));
    }
  }
  if (value.contains("measured_at_m")) {
    vertex.measured_at_m = reader.vector3(value, p, "measured_at_m", "m");
    vertex.measured_gravity_n = reader.vector3(value, p, "measured_gravity_n", "N");
  }
  const json& history = value.at("history");
  if (!history.is_array())
    reader.expected(p + "/history", "an array of iteration records", history);
  vertex.history.reserve(history.size());
  for (std::size_t j = 0; j < history.size(); ++j) {
    const std::string r = p + "/history/" + std::to_string(j);
    const json& entry = history[j];
    reader.requireObject(
        entry, r, {"position_error_m", "mass_estimate_kg", "gravity_estimate_n", "duration_s"});
    IterationRecord record;
    record.position_error_m = reader.number(entry, r, "position_error_m", Range::kNonNegative, "m");
    record.mass_estimate_kg =
        reader.number(entry, r, "mass_estimate_kg", Range::kNonNegative, "kg");
    record.gravity_estimate_n = reader.vector3(entry, r, "gravity_estimate_n", "N");
    record.duration_s = reader.number(entry, r, "duration_s", Range::kNonNegative, "s");
    vertex.history.push_back(record);
  }
  return vertex;
}

}  // namespace

GravityMap mapFromDocument(const json& document, const std::string& source,
                           const MapLoadOptions& options) {
  DocumentReader reader(source);
  if (!document.is_object()) reader.expected("", "a JSON object (an autograv map)", document);
  if (!document.contains("format")) {
    reader.fail("/format", std::string("missing; not an autograv map file (expected \"") +
                               kMapFormatName + "\")");
  }
  if (reader.string(document, "", "format", true) != kMapFormatName) {
    reader.expected("/format", std::string("\"") + kMapFormatName + "\"", document.at("format"));
  }
  if (!document.contains("schema_version")) reader.fail("/schema_version", "missing");
  {
    const json& version = document.at("schema_version");
    if (!version.is_number_integer() || version.get<std::int64_t>() < kOldestMapSchemaVersion ||
        version.get<std::int64_t>() > kMapSchemaVersion) {
      reader.expected("/schema_version",
                      "an integer in [" + std::to_string(kOldestMapSchemaVersion) + ", " +
                          std::to_string(kMapSchemaVersion) + "] (this autograv reads schema " +
                          "versions " + std::to_string(kOldestMapSchemaVersion) + " to " +
                          std::to_string(kMapSchemaVersion) + " only)",
                      version);
    }
    reader.setSchemaVersion(static_cast<int>(version.get<std::int64_t>()));
  }
  if (reader.schemaVersion() >= 8) {
    reader.requireObject(document, "",
                         {"format", "schema_version", "units", "device", "created_utc", "grid",
                          "field_model", "parameters", "vertices", "checksum"},
                         {"workspace", "prior", "reviewed_measurements", "thermal_drift"});
  } else if (reader.schemaVersion() >= 7) {
    reader.requireObject(document, "",
                         {"format", "schema_version", "units", "device", "created_utc", "grid",
                          "field_model", "parameters", "vertices", "checksum"},
                         {"workspace", "prior", "reviewed_measurements"});
  } else if (reader.schemaVersion() >= 6) {
    reader.requireObject(document, "",
                         {"format", "schema_version", "units", "device", "created_utc", "grid",
                          "field_model", "parameters", "vertices", "checksum"},
                         {"workspace", "prior"});
  } else if (reader.schemaVersion() >= 5) {
    reader.requireObject(document, "",
                         {"format", "schema_version", "units", "device", "created_utc", "grid",
                          "field_model", "parameters", "vertices", "checksum"},
                         {"workspace"});
  } else if (reader.schemaVersion() >= 3) {
    reader.requireObject(document, "",
                         {"format", "schema_version", "units", "device", "created_utc", "grid",
                          "parameters", "vertices", "checksum"},
                         {"workspace"});
  } else {
    reader.requireObject(document, "",
                         {"format", "schema_version", "units", "device", "created_utc", "grid",
                          "parameters", "vertices", "checksum"});
  }

  // Units are fixed; the block exists so that a reader never has to guess.
  const json& units = document.at("units");
  reader.requireObject(units, "/units", {"length", "force", "time", "mass"});
  const std::pair<const char*, const char*> kUnits[] = {
      {"length", "m"}, {"force", "N"}, {"time", "s"}, {"mass", "kg"}};
  for (const auto& [quantity, unit] : kUnits) {
    if (reader.string(units, "/units", quantity, true) != unit) {
      reader.expected(std::string("/units/") + quantity, std::string("\"") + unit + "\"",
                      units.at(quantity));
    }
  }

  const json& device = document.at("device");
  reader.requireObject(device, "/device", {"model", "serial"});
  MapMetadata metadata;
  metadata.device_model = reader.string(device, "/device", "model", true);
  metadata.device_serial = reader.string(device, "/device", "serial", false);

  metadata.created_utc = reader.string(document, "", "created_utc", true);
  if (!isIso8601Utc(metadata.created_utc)) {
    reader.expected("/created_utc", "an ISO 8601 UTC time like \"2026-11-23T13:25:00Z\"",
                    document.at("created_utc"));
  }

  const WorkspaceGrid grid = readGrid(reader, document.at("grid"));
  if (document.at("grid").contains("lookup_refinement")) {
    metadata.lookup_refinement =
        reader.integer(document.at("grid"), "/grid", "lookup_refinement", 1, kMaxLookupRefinement);
  }
  if (document.at("grid").contains("lookup_interpolant")) {
    // Schema 4: the thin plate or the conservative fit, the only models then.
    const json& interpolant = document.at("grid").at("lookup_interpolant");
    if (!interpolant.is_string() ||
        !parseFieldModel(interpolant.get<std::string>(), metadata.field_model) ||
        (metadata.field_model != FieldModel::kThinPlate &&
         metadata.field_model != FieldModel::kConservative)) {
      reader.expected("/grid/lookup_interpolant", "\"thin_plate\" or \"conservative\"",
                      interpolant);
    }
  }
  if (document.contains("field_model"))
    readFieldModel(reader, document.at("field_model"), metadata);

  metadata.parameters = readParameters(reader, document.at("parameters"));
  if (document.contains("workspace")) {
    metadata.workspace = readWorkspace(reader, document.at("workspace"));
  }
  if (document.contains("prior")) metadata.prior = readPrior(reader, document.at("prior"));
  if (document.contains("reviewed_measurements")) {
    metadata.reviewed_measurements =
        readReviewed(reader, document.at("reviewed_measurements"), grid);
  }
  if (document.contains("thermal_drift")) {
    metadata.thermal_drift = readThermalDrift(reader, document.at("thermal_drift"));
  }

  const json& vertices_json = document.at("vertices");
  const auto vertex_count = static_cast<std::size_t>(grid.vertexCount());
  if (!vertices_json.is_array() || vertices_json.size() != vertex_count) {
    const std::string got = vertices_json.is_array()
                                ? "an array of " + std::to_string(vertices_json.size())
                                : describe(vertices_json);
    reader.fail("/vertices", "expected an array of " + std::to_string(vertex_count) +
                                 " vertex objects (grid of " + grid.describe() + "), got " + got);
  }
  std::vector<VertexEstimate> vertices;
  vertices.reserve(vertex_count);
  for (std::size_t i = 0; i < vertex_count; ++i) {
    vertices.push_back(readVertex(reader, vertices_json[i], grid, static_cast<int>(i)));
  }

  // The checksum comes after the fields so that a hand edit that breaks a field is reported by
  // name; a flipped digit that still parses is caught here.
  const json& checksum = document.at("checksum");
  reader.requireObject(checksum, "/checksum", {"algorithm", "value"});
  if (reader.string(checksum, "/checksum", "algorithm", true) != kChecksumAlgorithm) {
    reader.expected("/checksum/algorithm", std::string("\"") + kChecksumAlgorithm + "\"",
                    checksum.at("algorithm"));
  }
  const std::string stored = reader.string(checksum, "/checksum", "value", true);
  const std::string computed = documentChecksum(document);
  if (stored != computed) {
    reader.fail("/checksum/value",
                "expected \"" + computed + "\" (FNV-1a 64 of the content), got \"" + stored +
                    "\": the file was modified or corrupted after it was written; recalibrate "
                    "or restore a backup");
  }

  if (!options.expected_device_model.empty() &&
      metadata.device_model != options.expected_device_model && !options.allow_model_mismatch) {
    reader.fail("/device/model", "the map was calibrated on a \"" + metadata.device_model +
                                     "\" but the device is a \"" + options.expected_device_model +
                                     "\"; calibrate this device, or allow the mismatch "
                                     "explicitly if the two are the same hardware "
                                     "(MapLoadOptions::allow_model_mismatch = true)");
  }

  try {
    return GravityMap(grid, std::move(vertices), std::move(metadata));
  } catch (const Error& error) {
    throw Error("map file '" + source + "': " + error.what());
  }
}

}  // namespace autograv::detail
