#include "autograv/map/map_io.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "autograv/error.h"
#include "core/map/map_json.h"
#include "scratch_folder.h"

namespace autograv {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A 5x5x5 map with distinct, awkward values everywhere so that a round trip checks every field.
GravityMap makeMap(const std::string& model = "sim:omni") {
  const WorkspaceGrid grid(Eigen::Vector3d(0.001, -0.0125, 0.03), 0.09, 5);
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (int i = 0; i < grid.vertexCount(); ++i) {
    VertexEstimate& v = vertices[static_cast<std::size_t>(i)];
    v.gravity_n = Eigen::Vector3d(0.01 * i, -1.0 / (i + 3), -2.0 - std::sqrt(i + 0.5));
    v.iterations = i % 7;
    v.seconds = 0.1 * i + 1.0 / 3.0;
    v.outcome = static_cast<VertexOutcome>(i % 6);
    for (int j = 0; j < v.iterations; ++j) {
      IterationRecord record;
      record.position_error_m = 1e-3 / (j + 1);
      record.mass_estimate_kg = 0.2 + 1e-17 * j;
      record.gravity_estimate_n = Eigen::Vector3d(1e-300, -0.0, 3.0e8 + j);
      record.duration_s = 0.1 + j;
      v.history.push_back(record);
    }
  }
  MapMetadata metadata;
  metadata.device_model = model;
  metadata.device_serial = "SN-0042 \"quoted\" ünïcode";
  metadata.created_utc = "2026-11-23T13:25:00Z";
  metadata.parameters.alpha_per_s = 41.5;
  metadata.parameters.n_s = 23;
  metadata.parameters.eps_g_n = 0.1 + 0.2;
  metadata.parameters.max_iterations = 77;
  return GravityMap(grid, std::move(vertices), metadata);
}

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void writeText(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// Runs `load` and returns the autograv::Error message, or "" when it did not throw.
std::string errorOf(const std::function<void()>& load) {
  try {
    load();
  } catch (const Error& error) {
    return error.what();
  }
  return "";
}

void expectSameMap(const GravityMap& a, const GravityMap& b) {
  EXPECT_EQ(a.grid().center_m(), b.grid().center_m());
  EXPECT_EQ(a.grid().size_m(), b.grid().size_m());
  EXPECT_EQ(a.grid().resolution(), b.grid().resolution());
  EXPECT_EQ(a.metadata().device_model, b.metadata().device_model);
  EXPECT_EQ(a.metadata().device_serial, b.metadata().device_serial);
  EXPECT_EQ(a.metadata().created_utc, b.metadata().created_utc);
  const EstimationParameters& p = a.metadata().parameters;
  const EstimationParameters& q = b.metadata().parameters;
  EXPECT_EQ(p.alpha_per_s, q.alpha_per_s);
  EXPECT_EQ(p.beta_per_s2, q.beta_per_s2);
  EXPECT_EQ(p.k0_n_per_m, q.k0_n_per_m);
  EXPECT_EQ(p.n_s, q.n_s);
  EXPECT_EQ(p.eps_s_m_per_s, q.eps_s_m_per_s);
  EXPECT_EQ(p.n_g, q.n_g);
  EXPECT_EQ(p.eps_g_n, q.eps_g_n);
  EXPECT_EQ(p.min_step_duration_s, q.min_step_duration_s);
  EXPECT_EQ(p.max_step_duration_s, q.max_step_duration_s);
  EXPECT_EQ(p.max_iterations, q.max_iterations);
  EXPECT_EQ(p.servo_period_s, q.servo_period_s);
  EXPECT_EQ(p.lipschitz_prior_n_per_m, q.lipschitz_prior_n_per_m);
  ASSERT_EQ(a.vertices().size(), b.vertices().size());
  for (std::size_t i = 0; i < a.vertices().size(); ++i) {
    const VertexEstimate& u = a.vertices()[i];
    const VertexEstimate& v = b.vertices()[i];
    EXPECT_EQ(u.gravity_n, v.gravity_n) << "vertex " << i;  // bit-exact, not approximate
    EXPECT_EQ(u.iterations, v.iterations);
    EXPECT_EQ(u.seconds, v.seconds);
    EXPECT_EQ(u.outcome, v.outcome);
    EXPECT_EQ(u.provenance, v.provenance);
    ASSERT_EQ(u.history.size(), v.history.size());
    for (std::size_t j = 0; j < u.history.size(); ++j) {
      EXPECT_EQ(u.history[j].position_error_m, v.history[j].position_error_m);
      EXPECT_EQ(u.history[j].mass_estimate_kg, v.history[j].mass_estimate_kg);
      EXPECT_EQ(u.history[j].gravity_estimate_n, v.history[j].gravity_estimate_n);
      EXPECT_EQ(u.history[j].duration_s, v.history[j].duration_s);
      EXPECT_EQ(std::signbit(u.history[j].gravity_estimate_n.y()),
                std::signbit(v.history[j].gravity_estimate_n.y()));
    }
  }
}

TEST(MapIoTest, Fnv1a64MatchesPublishedTestVectors) {
  EXPECT_EQ(fnv1a64(""), 0xcbf29ce484222325ULL);
  EXPECT_EQ(fnv1a64("a"), 0xaf63dc4c8601ec8cULL);
  EXPECT_EQ(fnv1a64("foobar"), 0x85944171f73967e8ULL);
}

TEST(MapIoTest, SaveThenLoadGivesTheSameMapBitForBit) {
  const testing::ScratchFolder folder("map-io");
  const GravityMap original = makeMap();
  saveMap(original, folder.file("map.json"));
  const GravityMap loaded = loadMap(folder.file("map.json"));
  expectSameMap(original, loaded);
  // Saving what was loaded writes the very same bytes (the format is canonical).
  saveMap(loaded, folder.file("again.json"));
  EXPECT_EQ(readText(folder.file("map.json")), readText(folder.file("again.json")));
}

TEST(MapIoTest, FileHoldsTheDocumentedFieldsAndChecksum) {
  const json document = json::parse(mapToJson(makeMap()));
  EXPECT_EQ(document.at("format"), "autograv-gravity-map");
  EXPECT_EQ(document.at("schema_version"), kMapSchemaVersion);
  EXPECT_EQ(document.at("units").at("force"), "N");
  EXPECT_EQ(document.at("device").at("model"), "sim:omni");
  EXPECT_EQ(document.at("grid").at("resolution"), json::array({5, 5, 5}));
  EXPECT_EQ(document.at("vertices").at(17).at("provenance"), "measured");
  EXPECT_EQ(document.at("parameters").at("n_s"), 23);
  EXPECT_EQ(document.at("vertices").size(), 125u);
  EXPECT_EQ(document.at("vertices").at(17).at("outcome"), "device_fault");
  EXPECT_EQ(document.at("vertices").at(17).at("history").size(), 3u);
  // The checksum is FNV-1a 64 over the compact dump of everything but the checksum itself.
  json content = document;
  content.erase("checksum");
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx",
                static_cast<unsigned long long>(fnv1a64(content.dump())));
  EXPECT_EQ(document.at("checksum").at("algorithm"), "fnv1a-64");
  EXPECT_EQ(document.at("checksum").at("value"), hex);
}

TEST(MapIoTest, InMemoryTextRoundTrips) {
  const GravityMap original = makeMap();
  expectSameMap(original, mapFromJson(mapToJson(original), "memory"));
}

// One corrupted field per case: the checksum is re-stamped so that the field check itself is what
// must fire, and the message must name the JSON pointer of the field and what was expected.
struct Corruption {
  const char* name;
  std::function<void(json&)> edit;
  const char* pointer;
  const char* expected;
};

TEST(MapIoTest, EveryCorruptedFieldIsNamed) {
  const std::vector<Corruption> cases = {
      {"gravity as text", [](json& d) { d["vertices"][17]["gravity_n"] = "down"; },
       "field /vertices/17/gravity_n:", "array of 3 finite numbers (unit: N)"},
      {"gravity too short", [](json& d) { d["vertices"][3]["gravity_n"].erase(2); },
       "field /vertices/3/gravity_n:", "array of 3"},
      {"gravity component null", [](json& d) { d["vertices"][4]["gravity_n"][1] = nullptr; },
       "field /vertices/4/gravity_n/1:", "finite number"},
      {"resolution 1", [](json& d) { d["grid"]["resolution"][1] = 1; },
       "field /grid/resolution/1:", "integer in [2, 64]"},
      {"resolution float", [](json& d) { d["grid"]["resolution"][0] = 5.0; },
       "field /grid/resolution/0:", "integer"},
      {"resolution scalar", [](json& d) { d["grid"]["resolution"] = 5; },
       "field /grid/resolution:", "array of 3 integers"},
      {"negative extent", [](json& d) { d["grid"]["size_m"][2] = -0.09; },
       "field /grid/size_m/2:", "> 0 (unit: m)"},
      {"unknown provenance", [](json& d) { d["vertices"][4]["provenance"] = "guessed"; },
       "field /vertices/4/provenance:", "one of measured, filled"},
      {"missing provenance", [](json& d) { d["vertices"][4].erase("provenance"); },
       "field /vertices/4/provenance:", "missing (required by schema version 8)"},
      {"centre 2-D",
       [](json& d) {
         d["grid"]["center_m"] = json::array({0.0, 0.0});
       },
       "field /grid/center_m:", "array of 3"},
      {"one vertex missing", [](json& d) { d["vertices"].erase(124); },
       "field /vertices:", "125 vertex objects"},
      {"unknown outcome", [](json& d) { d["vertices"][9]["outcome"] = "done"; },
       "field /vertices/9/outcome:", "one of pending, converged"},
      {"negative iterations", [](json& d) { d["vertices"][9]["iterations"] = -1; },
       "field /vertices/9/iterations:", "integer"},
      {"negative seconds", [](json& d) { d["vertices"][9]["seconds"] = -1.0; },
       "field /vertices/9/seconds:", ">= 0"},
      {"vertices swapped", [](json& d) { std::swap(d["vertices"][1], d["vertices"][2]); },
       "field /vertices/1/index:", "vertices are stored in index order"},
      {"moved vertex", [](json& d) { d["vertices"][5]["position_m"][0] = 1.0; },
       "field /vertices/5/position_m:", "grid position of vertex 5"},
      {"history record",
       [](json& d) { d["vertices"][13]["history"][0]["mass_estimate_kg"] = -0.2; },
       "field /vertices/13/history/0/mass_estimate_kg:", ">= 0 (unit: kg)"},
      {"history extra field", [](json& d) { d["vertices"][13]["history"][1]["note"] = 1; },
       "field /vertices/13/history/1/note:", "unexpected field"},
      {"millimetres", [](json& d) { d["units"]["length"] = "mm"; },
       "field /units/length:", "\"m\""},
      {"newer schema", [](json& d) { d["schema_version"] = kMapSchemaVersion + 1; },
       "field /schema_version:", "reads schema versions 1 to 8 only"},
      {"unknown field model", [](json& d) { d["field_model"]["name"] = "spline"; },
       "field /field_model/name:", "\"conservative\", \"componentwise\", \"corrected\""},
      {"a request, not a model", [](json& d) { d["field_model"]["name"] = "choose"; },
       "field /field_model/name:", "\"conservative\", \"componentwise\", \"corrected\""},
      {"negative curl weight", [](json& d) { d["field_model"]["curl_weight"] = -1.0; },
       "field /field_model/curl_weight:", ">= 0"},
      {"huge curl weight", [](json& d) { d["field_model"]["curl_weight"] = 1e6; },
       "field /field_model/curl_weight:", "in [0, 1000"},
      {"score without its mean",
       [](json& d) {
         d["field_model"]["scores"] = json::array({json{{"name", "conservative"},
                                                        {"curl_weight", 0.0},
                                                        {"loo_median_rel", 0.01},
                                                        {"loo_p90_rel", 0.02}}});
       },
       "field /field_model/scores/0/loo_mean_rel:", "missing"},
      {"no field model in schema 7", [](json& d) { d.erase("field_model"); },
       "field /field_model:", "missing"},
      {"interpolant in schema 8", [](json& d) { d["grid"]["lookup_interpolant"] = "conservative"; },
       "field /grid/lookup_interpolant:", "unexpected field (not part of schema version 8"},
      {"a thermal drift beyond its bound",
       [](json& d) {
         d["thermal_drift"] = json{{"gain_loss_per_load", 1.5},
                                   {"gain_loss_standard_error", 0.1},
                                   {"points", 3},
                                   {"first_load", 0.01},
                                   {"again_load", 0.1},
                                   {"drift_rel", 0.02}};
       },
       "field /thermal_drift/gain_loss_per_load:", "a loss of torque per unit load in [0, 1"},
      {"a thermal drift without its points",
       [](json& d) {
         d["thermal_drift"] = json{{"gain_loss_per_load", 0.1},
                                   {"gain_loss_standard_error", 0.1},
                                   {"first_load", 0.01},
                                   {"again_load", 0.1},
                                   {"drift_rel", 0.02}};
       },
       "field /thermal_drift/points:", "missing"},
      {"a thermal drift in schema 7",
       [](json& d) {
         d["schema_version"] = 7;
         d["thermal_drift"] = json{{"gain_loss_per_load", 0.1},
                                   {"gain_loss_standard_error", 0.1},
                                   {"points", 3},
                                   {"first_load", 0.01},
                                   {"again_load", 0.1},
                                   {"drift_rel", 0.02}};
       },
       "field /thermal_drift:", "unexpected field (not part of schema version 7"},
      {"interpolant in schema 5",
       [](json& d) {
         d["schema_version"] = 5;
         d["grid"]["lookup_interpolant"] = "conservative";
       },
       "field /grid/lookup_interpolant:", "unexpected field (not part of schema version 5"},
      {"unknown interpolant in schema 4",
       [](json& d) {
         d["schema_version"] = 4;
         d.erase("field_model");
         d["grid"]["lookup_interpolant"] = "spline";
       },
       "field /grid/lookup_interpolant:", "\"thin_plate\" or \"conservative\""},
      {"interpolant in schema 3",
       [](json& d) {
         d["schema_version"] = 3;
         d.erase("field_model");
         d["grid"]["lookup_interpolant"] = "conservative";
       },
       "field /grid/lookup_interpolant:", "unexpected field (not part of schema version 3"},
      {"not a map", [](json& d) { d.erase("format"); },
       "field /format:", "not an autograv map file"},
      {"misspelt member", [](json& d) { d["grid"]["sizes_m"] = 0.1; },
       "field /grid/sizes_m:", "unexpected field"},
      {"missing parameter", [](json& d) { d["parameters"].erase("n_g"); },
       "field /parameters/n_g:", "missing"},
      {"zero alpha", [](json& d) { d["parameters"]["alpha_per_s"] = 0.0; },
       "field /parameters/alpha_per_s:", "> 0 (unit: 1/s)"},
      {"step bounds crossed", [](json& d) { d["parameters"]["max_step_duration_s"] = 0.01; },
       "field /parameters/max_step_duration_s:", ">= /parameters/min_step_duration_s"},
      {"bad timestamp", [](json& d) { d["created_utc"] = "yesterday"; },
       "field /created_utc:", "ISO 8601"},
      {"month 13", [](json& d) { d["created_utc"] = "2026-13-23T13:25:00Z"; },
       "field /created_utc:", "ISO 8601"},
      {"no zone", [](json& d) { d["created_utc"] = "2026-11-23T13:25:00"; },
       "field /created_utc:", "ISO 8601"},
      {"empty fraction", [](json& d) { d["created_utc"] = "2026-11-23T13:25:00.Z"; },
       "field /created_utc:", "ISO 8601"},
      {"empty model", [](json& d) { d["device"]["model"] = ""; },
       "field /device/model:", "non-empty string"},
      {"huge integer", [](json& d) { d["parameters"]["n_s"] = 18446744073709551615ULL; },
       "field /parameters/n_s:", "integer in [1, 1000000]"},
      {"not an object",
       [](json& d) {
         d = json::array({1, 2});
       },
       "field /:", "a JSON object"},
  };
  const json valid = json::parse(mapToJson(makeMap()));
  for (const Corruption& corruption : cases) {
    json document = valid;
    corruption.edit(document);
    if (document.is_object()) detail::stampChecksum(document);
    const std::string message = errorOf([&] { mapFromJson(document.dump(1), "maps/omni.json"); });
    EXPECT_NE(message.find("map file 'maps/omni.json'"), std::string::npos)
        << corruption.name << ": " << message;
    EXPECT_NE(message.find(corruption.pointer), std::string::npos)
        << corruption.name << ": " << message;
    EXPECT_NE(message.find(corruption.expected), std::string::npos)
        << corruption.name << ": " << message;
  }
}

TEST(MapIoTest, AnEditThatStillParsesFailsTheChecksum) {
  json document = json::parse(mapToJson(makeMap()));
  document["vertices"][17]["gravity_n"][2] = -2.5;  // plausible, but not what was written
  const std::string message = errorOf([&] { mapFromJson(document.dump(), "m.json"); });
  EXPECT_NE(message.find("field /checksum/value"), std::string::npos) << message;
  EXPECT_NE(message.find("modified or corrupted"), std::string::npos) << message;
}

TEST(MapIoTest, ByteFlipsAndTruncationsNeverLoad) {
  const testing::ScratchFolder folder("map-io");
  const std::string text = mapToJson(makeMap());
  // Every truncation fails as invalid JSON (the document closes only at its last brace).
  for (const std::size_t length :
       {std::size_t{0}, std::size_t{1}, text.size() / 3, text.size() / 2, text.size() - 3}) {
    writeText(folder.file("cut.json"), text.substr(0, length));
    const std::string message = errorOf([&] { loadMap(folder.file("cut.json")); });
    EXPECT_NE(message.find("not valid JSON"), std::string::npos) << length << ": " << message;
    EXPECT_NE(message.find(folder.file("cut.json")), std::string::npos) << message;
  }
  // Changing a digit either fails (a field error or the checksum) or changes nothing that was
  // written: the 17th significant digit of a double can change without changing the value, and
  // the checksum covers values (the canonical dump), not bytes.
  const GravityMap original = makeMap();
  int refused = 0;
  int harmless = 0;
  for (std::size_t i = 0; i < text.size(); i += 211) {
    if (text[i] < '0' || text[i] > '8') continue;
    std::string corrupted = text;
    corrupted[i] = static_cast<char>(corrupted[i] + 1);
    try {
      const GravityMap loaded = mapFromJson(corrupted, "flip");
      expectSameMap(original, loaded);
      ++harmless;
    } catch (const Error&) {
      ++refused;
    }
  }
  EXPECT_GT(refused, 10);
  EXPECT_LT(harmless, refused / 4);
}

// A number beyond the range of double is a JSON parse failure of its own kind in nlohmann
// (out_of_range, not parse_error); it must still be an autograv::Error naming file and field.
TEST(MapIoTest, ANumberBeyondDoubleRangeNamesTheFileAndTheField) {
  const testing::ScratchFolder folder("map-io");
  std::string text = json::parse(mapToJson(makeMap())).dump();
  const std::string size = "\"size_m\":[0.09";
  ASSERT_NE(text.find(size), std::string::npos) << text;
  text.replace(text.find(size), size.size(), "\"size_m\":[1e999");
  writeText(folder.file("huge.json"), text);
  const std::string message = errorOf([&] { loadMap(folder.file("huge.json")); });
  EXPECT_NE(message.find(folder.file("huge.json")), std::string::npos) << message;
  EXPECT_NE(message.find("field /grid/size_m/0:"), std::string::npos) << message;
  EXPECT_NE(message.find("beyond the range of double"), std::string::npos) << message;

  // Inside arrays the pointer names the element: here the second component of vertex 2's gravity.
  const std::string negative = "-1e400";
  const std::string value = json::parse(mapToJson(makeMap()))["vertices"][2]["gravity_n"].dump();
  std::string in_array = json::parse(mapToJson(makeMap())).dump();
  const std::size_t at = in_array.find(value);
  ASSERT_NE(at, std::string::npos);
  const std::size_t comma = in_array.find(',', at);
  in_array.replace(comma + 1, in_array.find(',', comma + 1) - comma - 1, negative);
  const std::string array_message = errorOf([&] { mapFromJson(in_array, "m.json"); });
  EXPECT_NE(array_message.find("field /vertices/2/gravity_n/1:"), std::string::npos)
      << array_message;
}

TEST(MapIoTest, ASyntaxErrorNamesTheFieldBeingRead) {
  std::string text = json::parse(mapToJson(makeMap())).dump();
  const std::string units = "\"units\":{";
  ASSERT_NE(text.find(units), std::string::npos);
  text.insert(text.find(units) + units.size(), "\"force\":N,");
  const std::string message = errorOf([&] { mapFromJson(text, "m.json"); });
  EXPECT_NE(message.find("not valid JSON"), std::string::npos) << message;
  EXPECT_NE(message.find("in field /units/force"), std::string::npos) << message;
}

TEST(MapIoTest, MissingFileNamesThePathAndTheFix) {
  const std::string message = errorOf([] { loadMap("/nonexistent/omni.json"); });
  EXPECT_NE(message.find("/nonexistent/omni.json"), std::string::npos) << message;
  EXPECT_NE(message.find("cannot open"), std::string::npos) << message;
  EXPECT_NE(message.find("WizardConfig::map_path"), std::string::npos) << message;
}

TEST(MapIoTest, AMapForAnotherModelIsRefusedUnlessAllowed) {
  const testing::ScratchFolder folder("map-io");
  saveMap(makeMap("sim:omni"), folder.file("omni.json"));
  MapLoadOptions options;
  options.expected_device_model = "sim:omega";
  const std::string message = errorOf([&] { loadMap(folder.file("omni.json"), options); });
  EXPECT_NE(message.find("field /device/model"), std::string::npos) << message;
  EXPECT_NE(message.find("\"sim:omni\""), std::string::npos) << message;
  EXPECT_NE(message.find("\"sim:omega\""), std::string::npos) << message;
  // How to allow it, for code as for the command line.
  EXPECT_NE(message.find("MapLoadOptions::allow_model_mismatch"), std::string::npos) << message;
  options.allow_model_mismatch = true;
  EXPECT_EQ(loadMap(folder.file("omni.json"), options).metadata().device_model, "sim:omni");
  options = MapLoadOptions{};
  options.expected_device_model = "sim:omni";
  EXPECT_EQ(loadMap(folder.file("omni.json"), options).metadata().device_model, "sim:omni");
}

TEST(MapIoTest, SaveReplacesAtomicallyAndLeavesNoTemporaryFiles) {
  const testing::ScratchFolder folder("map-io");
  const std::string path = folder.file("map.json");
  saveMap(makeMap("first"), path);
  saveMap(makeMap("second"), path);
  EXPECT_EQ(loadMap(path).metadata().device_model, "second");
  EXPECT_EQ(folder.names(), std::vector<std::string>{"map.json"});
  EXPECT_EQ(fs::status(path).permissions() & fs::perms::others_read, fs::perms::others_read);
}

TEST(MapIoTest, AFailedSaveKeepsThePreviousFile) {
  const testing::ScratchFolder folder("map-io");
  const std::string path = folder.file("map.json");
  saveMap(makeMap(), path);
  const std::string before = readText(path);

  // A map that cannot make a valid file (NaN in a history record) is refused before writing.
  const GravityMap good = makeMap();
  std::vector<VertexEstimate> vertices = good.vertices();
  vertices[20].history.at(0).duration_s = NAN;
  const GravityMap bad(good.grid(), vertices, good.metadata());
  const std::string message = errorOf([&] { saveMap(bad, path); });
  EXPECT_NE(message.find("/vertices/20/history/0/duration_s"), std::string::npos) << message;
  EXPECT_EQ(readText(path), before);

  // No device model: refused, with the fix in the message.
  const GravityMap anonymous(good.grid(), good.vertices(), MapMetadata{});
  EXPECT_NE(errorOf([&] { saveMap(anonymous, path); }).find("device_model is empty"),
            std::string::npos);
  EXPECT_EQ(readText(path), before);
  EXPECT_EQ(folder.names(), std::vector<std::string>{"map.json"});

  // A folder that does not exist: named in the message.
  const std::string nowhere = folder.file("missing/map.json");
  EXPECT_NE(errorOf([&] { saveMap(good, nowhere); }).find(folder.file("missing")),
            std::string::npos);
}

TEST(MapIoTest, FractionalSecondsAreAccepted) {
  json document = json::parse(mapToJson(makeMap()));
  document["created_utc"] = "2026-11-23T13:25:00.123456789012Z";
  detail::stampChecksum(document);
  EXPECT_EQ(mapFromJson(document.dump(), "m").metadata().created_utc,
            "2026-11-23T13:25:00.123456789012Z");
}

TEST(MapIoTest, AnEmptyCreationTimeIsStampedWithTheCurrentTime) {
  const GravityMap good = makeMap();
  MapMetadata metadata = good.metadata();
  metadata.created_utc.clear();
  const GravityMap unstamped(good.grid(), good.vertices(), metadata);
  const std::string created = mapFromJson(mapToJson(unstamped), "m").metadata().created_utc;
  ASSERT_EQ(created.size(), 20u) << created;
  EXPECT_EQ(created[10], 'T');
  EXPECT_EQ(created.back(), 'Z');
  EXPECT_GE(created.substr(0, 4), "2024");
}

// A box grid whose far corner vertices were unreachable and filled: schema 2 keeps the box and
// says which values were measured.
GravityMap makeBoxMap() {
  const WorkspaceGrid grid(Eigen::Vector3d(0.0, 0.002, -0.01), Eigen::Vector3d(0.16, 0.12, 0.07),
                           Eigen::Vector3i(7, 5, 4));
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (int i = 0; i < grid.vertexCount(); ++i) {
    VertexEstimate& v = vertices[static_cast<std::size_t>(i)];
    v.gravity_n = Eigen::Vector3d(0.001 * i, 0.5, 2.0 + 1.0 / (i + 1));
    const bool far = grid.vertexPosition(i).norm() > 0.085;
    v.outcome = far ? VertexOutcome::kUnreachable : VertexOutcome::kConverged;
    v.provenance = far ? VertexProvenance::kFilled : VertexProvenance::kMeasured;
    v.iterations = far ? 3 : 5;
  }
  MapMetadata metadata;
  metadata.device_model = "sim:omni";
  metadata.created_utc = "2026-11-30T12:00:00Z";
  return GravityMap(grid, std::move(vertices), metadata);
}

TEST(MapIoTest, BoxGridAndProvenanceRoundTripInTheCurrentSchema) {
  const testing::ScratchFolder folder("map-io");
  const GravityMap original = makeBoxMap();
  ASSERT_GT(original.filledCount(), 0);
  ASSERT_TRUE(original.isComplete());
  saveMap(original, folder.file("box.json"));
  const json document = json::parse(readText(folder.file("box.json")));
  EXPECT_EQ(document.at("schema_version"), kMapSchemaVersion);
  EXPECT_EQ(document.at("grid").at("size_m"), json::array({0.16, 0.12, 0.07}));
  EXPECT_EQ(document.at("grid").at("resolution"), json::array({7, 5, 4}));
  EXPECT_EQ(document.at("vertices").at(0).at("outcome"), "unreachable");
  EXPECT_EQ(document.at("vertices").at(0).at("provenance"), "filled");
  const GravityMap loaded = loadMap(folder.file("box.json"));
  expectSameMap(original, loaded);
  EXPECT_EQ(loaded.filledCount(), original.filledCount());
  EXPECT_EQ(loaded.unreachableCount(), original.unreachableCount());
  EXPECT_TRUE(loaded.isComplete());
}

/// The schema 1 form of a cubic map's document: a cube {side_m, resolution} and no provenance.
json schema1Document(const GravityMap& map) {
  json document = json::parse(mapToJson(map));
  document["schema_version"] = 1;
  json& grid = document["grid"];
  grid["side_m"] = grid["size_m"][0];
  grid["resolution"] = grid["resolution"][0];
  grid.erase("size_m");
  document.erase("field_model");
  for (json& vertex : document["vertices"]) vertex.erase("provenance");
  detail::stampChecksum(document);
  return document;
}

TEST(MapIoTest, Schema1FilesStillLoad) {
  const GravityMap original = makeMap();
  const GravityMap loaded = mapFromJson(schema1Document(original).dump(), "old.json");
  expectSameMap(original, loaded);
  // Maps written by an earlier autograv (the visual tests' fixtures before schema 2), as users
  // have them on disk.
  for (const char* name : {"omega_map_schema1.json", "omni_map_schema1.json"}) {
    const std::string path = std::string(AUTOGRAV_SOURCE_DIR) + "/tests/core/map/fixtures/" + name;
    const GravityMap golden = loadMap(path);
    EXPECT_TRUE(golden.grid().isCube()) << path;
    EXPECT_EQ(golden.filledCount(), 0) << path;
  }
}

TEST(MapIoTest, Schema1FieldsAreCheckedAsSchema1) {
  const GravityMap original = makeMap();
  json document = schema1Document(original);
  document["vertices"][3]["outcome"] = "unreachable";
  detail::stampChecksum(document);
  std::string message = errorOf([&] { mapFromJson(document.dump(), "old.json"); });
  EXPECT_NE(message.find("field /vertices/3/outcome:"), std::string::npos) << message;
  EXPECT_NE(message.find("(schema version 1)"), std::string::npos) << message;

  document = schema1Document(original);
  document["vertices"][3]["provenance"] = "measured";
  detail::stampChecksum(document);
  message = errorOf([&] { mapFromJson(document.dump(), "old.json"); });
  EXPECT_NE(message.find("field /vertices/3/provenance: unexpected field (not part of schema "
                         "version 1"),
            std::string::npos)
      << message;

  document = schema1Document(original);
  document["grid"]["resolution"] = json::array({5, 5, 5});
  detail::stampChecksum(document);
  message = errorOf([&] { mapFromJson(document.dump(), "old.json"); });
  EXPECT_NE(message.find("map file 'old.json': field /grid/resolution: expected an integer"),
            std::string::npos)
      << message;
}

// --- Schema 6: the prior of a map corrected from another unit's map -------------------------

// A correction with awkward values everywhere, so that a round trip checks every field bit for
// bit.
MapPrior makePrior() {
  MapPrior prior;
  prior.source = "maps/omni A \"first\" ünït.json";
  prior.device_serial = "SN-0017";
  prior.created_utc = "2026-10-01T08:00:00.25Z";
  prior.correction_model = "conservative";
  prior.gain << 1.0 + 1.0 / 3.0, -1e-17, 0.002, 0.1 + 0.2, 0.987, -0.0, 1e-300, 3e-3, 1.003;
  prior.offset_n = Eigen::Vector3d(0.0041, -1.0 / 7.0, -0.0);
  for (int i = 0; i < 6; ++i) {
    prior.points_m.emplace_back(0.01 * i, -0.02 + 1e-3 / (i + 1), 0.03 * std::sqrt(i + 0.5));
    prior.residuals_n.emplace_back(1e-3 * i, -2e-4 / (i + 3), 1.0 / 3.0 - i);
  }
  prior.check_points = 4;
  prior.check_mean_rel = 0.0041;
  prior.check_max_rel = 0.1 * 0.093;
  prior.workspace_difference_m = 0.0032;
  return prior;
}

GravityMap withPrior(const GravityMap& map, const std::optional<MapPrior>& prior) {
  MapMetadata metadata = map.metadata();
  metadata.prior = prior;
  return GravityMap(map.grid(), map.vertices(), std::move(metadata));
}

void expectSamePrior(const MapPrior& a, const MapPrior& b) {
  EXPECT_EQ(a.source, b.source);
  EXPECT_EQ(a.device_serial, b.device_serial);
  EXPECT_EQ(a.created_utc, b.created_utc);
  EXPECT_EQ(a.correction_model, b.correction_model);
  EXPECT_EQ(a.gain, b.gain);  // bit-exact, not approximate
  EXPECT_EQ(std::signbit(a.gain(1, 2)), std::signbit(b.gain(1, 2)));
  EXPECT_EQ(a.offset_n, b.offset_n);
  EXPECT_EQ(std::signbit(a.offset_n.z()), std::signbit(b.offset_n.z()));
  EXPECT_EQ(a.points_m, b.points_m);
  EXPECT_EQ(a.residuals_n, b.residuals_n);
  EXPECT_EQ(a.check_points, b.check_points);
  EXPECT_EQ(a.check_mean_rel, b.check_mean_rel);
  EXPECT_EQ(a.check_max_rel, b.check_max_rel);
  EXPECT_EQ(a.workspace_difference_m, b.workspace_difference_m);
}

TEST(MapIoTest, ThermalDriftRoundTripsBitForBitAndAMapWithoutOneHasNone) {
  const testing::ScratchFolder folder("map-io");
  const GravityMap plain = makeMap();
  saveMap(plain, folder.file("plain.json"));
  EXPECT_FALSE(json::parse(readText(folder.file("plain.json"))).contains("thermal_drift"));
  EXPECT_EQ(loadMap(folder.file("plain.json")).metadata().thermal_drift.points, 0);

  MapMetadata metadata = plain.metadata();
  metadata.thermal_drift.gain_loss_per_load = 0.1 + 0.2;
  metadata.thermal_drift.gain_loss_standard_error = 0.031;
  metadata.thermal_drift.points = 3;
  metadata.thermal_drift.first_load = 0.004;
  metadata.thermal_drift.again_load = 0.121;
  metadata.thermal_drift.drift_rel = -0.0;
  const GravityMap warmed(plain.grid(), plain.vertices(), metadata);
  saveMap(warmed, folder.file("warmed.json"));
  const GravityMap loaded = loadMap(folder.file("warmed.json"));
  const ThermalDrift& drift = loaded.metadata().thermal_drift;
  EXPECT_EQ(drift.gain_loss_per_load, 0.1 + 0.2);
  EXPECT_EQ(drift.gain_loss_standard_error, 0.031);
  EXPECT_EQ(drift.points, 3);
  EXPECT_EQ(drift.first_load, 0.004);
  EXPECT_EQ(drift.again_load, 0.121);
  saveMap(loaded, folder.file("again.json"));
  EXPECT_EQ(readText(folder.file("warmed.json")), readText(folder.file("again.json")));
}

TEST(MapIoTest, PriorRoundTripsBitForBit) {
  const testing::ScratchFolder folder("map-io");
  const GravityMap original = withPrior(makeMap(), makePrior());
  saveMap(original, folder.file("corrected.json"));
  const json document = json::parse(readText(folder.file("corrected.json")));
  EXPECT_EQ(document.at("schema_version"), kMapSchemaVersion);
  const json& prior = document.at("prior");
  EXPECT_EQ(prior.at("gain").size(), 3u);
  EXPECT_EQ(prior.at("gain").at(1), json::array({0.1 + 0.2, 0.987, -0.0}));  // row-major
  EXPECT_EQ(prior.at("points_m").size(), 6u);
  EXPECT_EQ(prior.at("residuals_n").at(2).size(), 3u);

  const GravityMap loaded = loadMap(folder.file("corrected.json"));
  expectSameMap(original, loaded);
  ASSERT_TRUE(loaded.metadata().prior.has_value());
  expectSamePrior(*original.metadata().prior, *loaded.metadata().prior);
  // Canonical: saving what was loaded writes the very same bytes.
  saveMap(loaded, folder.file("again.json"));
  EXPECT_EQ(readText(folder.file("corrected.json")), readText(folder.file("again.json")));

  // A shift or affine correction has no field part: no residuals, and no serial or time known.
  MapPrior shift = makePrior();
  shift.correction_model = "shift";
  shift.residuals_n.clear();
  shift.device_serial.clear();
  shift.created_utc.clear();
  shift.source.clear();
  shift.check_points = 0;
  const GravityMap shifted = mapFromJson(mapToJson(withPrior(makeMap(), shift)), "memory");
  ASSERT_TRUE(shifted.metadata().prior.has_value());
  expectSamePrior(shift, *shifted.metadata().prior);
}

TEST(MapIoTest, AMapWithoutPriorWritesNoPriorKey) {
  const GravityMap original = makeMap();
  ASSERT_FALSE(original.metadata().prior.has_value());
  const json document = json::parse(mapToJson(original));
  EXPECT_FALSE(document.contains("prior"));
  EXPECT_FALSE(mapFromJson(document.dump(), "memory").metadata().prior.has_value());
}

TEST(MapIoTest, OlderSchemasLoadWithoutPrior) {
  // Schema 5 as it was written: the same document, no prior.
  json schema5 = json::parse(mapToJson(makeMap()));
  schema5["schema_version"] = 5;
  detail::stampChecksum(schema5);
  const GravityMap loaded = mapFromJson(schema5.dump(), "schema5.json");
  expectSameMap(makeMap(), loaded);
  EXPECT_FALSE(loaded.metadata().prior.has_value());
  EXPECT_FALSE(
      mapFromJson(schema1Document(makeMap()).dump(), "old.json").metadata().prior.has_value());
}

TEST(MapIoTest, EveryCorruptedPriorFieldIsNamed) {
  const std::vector<Corruption> cases = {
      {"residuals of another count", [](json& d) { d["prior"]["residuals_n"].erase(5); },
       "field /prior/residuals_n:", "an empty array or one of 6 residuals (one per point"},
      {"gain as text", [](json& d) { d["prior"]["gain"][1][2] = "1.0"; },
       "field /prior/gain/1/2:", "a finite number (unit: 1)"},
      {"gain not finite", [](json& d) { d["prior"]["gain"][0][0] = nullptr; },
       "field /prior/gain/0/0:", "a finite number (unit: 1)"},
      {"gain of 2 rows", [](json& d) { d["prior"]["gain"].erase(2); },
       "field /prior/gain:", "an array of 3 rows of 3 finite numbers"},
      {"gain row too short", [](json& d) { d["prior"]["gain"][2].erase(0); },
       "field /prior/gain/2:", "an array of 3 finite numbers (unit: 1)"},
      {"offset in text", [](json& d) { d["prior"]["offset_n"][1] = "-0.1"; },
       "field /prior/offset_n/1:", "a finite number (unit: N)"},
      {"point 2-D", [](json& d) { d["prior"]["points_m"][3].erase(2); },
       "field /prior/points_m/3:", "an array of 3 finite numbers (unit: m)"},
      {"points not an array", [](json& d) { d["prior"]["points_m"] = 6; },
       "field /prior/points_m:", "an array of at most 512 arrays of 3"},
      {"unknown correction", [](json& d) { d["prior"]["correction_model"] = "spline"; },
       "field /prior/correction_model:", "\"shift\", \"affine\", \"conservative\""},
      {"bad prior time", [](json& d) { d["prior"]["created_utc"] = "last week"; },
       "field /prior/created_utc:", "ISO 8601"},
      {"negative check count", [](json& d) { d["prior"]["check_points"] = -1; },
       "field /prior/check_points:", "an integer in [0, 1000000]"},
      {"negative check error", [](json& d) { d["prior"]["check_max_rel"] = -0.01; },
       "field /prior/check_max_rel:", ">= 0 (unit: 1)"},
      {"workspace difference as text",
       [](json& d) { d["prior"]["workspace_difference_m"] = "3 mm"; },
       "field /prior/workspace_difference_m:", ">= 0 (unit: m)"},
      {"missing serial", [](json& d) { d["prior"].erase("device_serial"); },
       "field /prior/device_serial:", "missing (required by schema version 8)"},
      {"misspelt member", [](json& d) { d["prior"]["gains"] = 1; },
       "field /prior/gains:", "unexpected field"},
      {"not an object", [](json& d) { d["prior"] = "maps/a.json"; },
       "field /prior:", "expected an object"},
      {"prior in schema 5", [](json& d) { d["schema_version"] = 5; },
       "field /prior:", "unexpected field (not part of schema version 5"},
  };
  const json valid = json::parse(mapToJson(withPrior(makeMap(), makePrior())));
  for (const Corruption& corruption : cases) {
    json document = valid;
    corruption.edit(document);
    detail::stampChecksum(document);
    const std::string message = errorOf([&] { mapFromJson(document.dump(1), "maps/b.json"); });
    EXPECT_NE(message.find("map file 'maps/b.json'"), std::string::npos)
        << corruption.name << ": " << message;
    EXPECT_NE(message.find(corruption.pointer), std::string::npos)
        << corruption.name << ": " << message;
    EXPECT_NE(message.find(corruption.expected), std::string::npos)
        << corruption.name << ": " << message;
  }
}

TEST(MapIoTest, APriorThatWouldNotLoadIsNotSaved) {
  MapPrior prior = makePrior();
  prior.gain(2, 1) = std::numeric_limits<double>::quiet_NaN();
  const std::string nan_gain = errorOf([&] { mapToJson(withPrior(makeMap(), prior)); });
  EXPECT_NE(nan_gain.find("cannot save gravity map"), std::string::npos) << nan_gain;
  EXPECT_NE(nan_gain.find("field /prior/gain/2/1:"), std::string::npos) << nan_gain;

  prior = makePrior();
  prior.residuals_n.pop_back();
  const std::string short_residuals = errorOf([&] { mapToJson(withPrior(makeMap(), prior)); });
  EXPECT_NE(short_residuals.find("field /prior/residuals_n:"), std::string::npos)
      << short_residuals;
}

// makeMap with vertex 7 left out of the fit (measured at a point of its own, contradicted twice)
// and the review that left it out.
GravityMap withLeftOut(const GravityMap& map) {
  std::vector<VertexEstimate> vertices = map.vertices();
  VertexEstimate& left = vertices[7];
  left.outcome = VertexOutcome::kLeftOut;
  left.provenance = VertexProvenance::kFilled;
  left.measured_at_m = Eigen::Vector3d(0.011, -0.0201, 0.0333);
  left.measured_gravity_n = Eigen::Vector3d(0.1 + 0.2, -0.7, -1.9);
  MapMetadata metadata = map.metadata();
  ReviewedMeasurement reviewed;
  reviewed.first.vertex = 7;
  reviewed.first.point_m = Eigen::Vector3d(0.011, -0.0201, 0.0365);
  reviewed.first.value_n = Eigen::Vector3d(0.3, -0.6, -1.5);
  reviewed.first.residual_rel = 0.167;
  reviewed.first.local_rel = 0.0014;
  reviewed.again_point_m = left.measured_at_m;
  reviewed.again_value_n = left.measured_gravity_n;
  reviewed.again_residual_rel = 0.05;
  reviewed.verdict = ReviewVerdict::kLeftOut;
  metadata.reviewed_measurements = {reviewed};
  return GravityMap(map.grid(), std::move(vertices), std::move(metadata));
}

TEST(MapIoTest, AVertexLeftOutAndTheReviewRoundTripBitForBit) {
  const testing::ScratchFolder folder("map-io");
  const GravityMap original = withLeftOut(makeMap());
  saveMap(original, folder.file("reviewed.json"));
  const json document = json::parse(readText(folder.file("reviewed.json")));
  EXPECT_EQ(document.at("vertices").at(7).at("outcome"), "left_out");
  EXPECT_EQ(document.at("reviewed_measurements").size(), 1u);
  const GravityMap loaded = loadMap(folder.file("reviewed.json"));
  expectSameMap(original, loaded);
  const VertexEstimate& left = loaded.vertices()[7];
  EXPECT_EQ(left.measured_at_m, original.vertices()[7].measured_at_m);
  EXPECT_EQ(left.measured_gravity_n, original.vertices()[7].measured_gravity_n);
  ASSERT_EQ(loaded.metadata().reviewed_measurements.size(), 1u);
  const ReviewedMeasurement& a = original.metadata().reviewed_measurements.front();
  const ReviewedMeasurement& b = loaded.metadata().reviewed_measurements.front();
  EXPECT_EQ(a.first.vertex, b.first.vertex);
  EXPECT_EQ(a.first.point_m, b.first.point_m);
  EXPECT_EQ(a.first.value_n, b.first.value_n);
  EXPECT_EQ(a.first.residual_rel, b.first.residual_rel);
  EXPECT_EQ(a.first.local_rel, b.first.local_rel);
  EXPECT_EQ(a.again_point_m, b.again_point_m);
  EXPECT_EQ(a.again_value_n, b.again_value_n);
  EXPECT_EQ(a.again_residual_rel, b.again_residual_rel);
  EXPECT_EQ(a.verdict, b.verdict);
  saveMap(loaded, folder.file("again.json"));
  EXPECT_EQ(readText(folder.file("reviewed.json")), readText(folder.file("again.json")));
}

TEST(MapIoTest, ALeftOutVertexOrAReviewThatAnOlderSchemaCannotHoldIsRefusedByName) {
  const std::vector<Corruption> cases = {
      {"left out in schema 6",
       [](json& d) {
         d["schema_version"] = 6;
         d.erase("reviewed_measurements");
       },
       "field /vertices/7/outcome:", "one of pending, converged"},
      {"review in schema 6",
       [](json& d) {
         d["schema_version"] = 6;
         d["vertices"][7]["outcome"] = "unreachable";
       },
       "field /reviewed_measurements:", "unexpected field (not part of schema version 6"},
      {"left out without what it measured",
       [](json& d) {
         d["vertices"][7].erase("measured_at_m");
         d["vertices"][7].erase("measured_gravity_n");
       },
       "field /vertices/7:", "a vertex left out keeps what it measured"},
      {"review of a vertex beyond the grid",
       [](json& d) { d["reviewed_measurements"][0]["vertex"] = 125; },
       "field /reviewed_measurements/0/vertex:", "integer"},
      {"unknown verdict", [](json& d) { d["reviewed_measurements"][0]["verdict"] = "kept"; },
       "field /reviewed_measurements/0/verdict:", "one of confirmed, replaced, left_out"},
  };
  const json valid = json::parse(mapToJson(withLeftOut(makeMap())));
  for (const Corruption& corruption : cases) {
    json document = valid;
    corruption.edit(document);
    detail::stampChecksum(document);
    const std::string message = errorOf([&] { mapFromJson(document.dump(1), "maps/c.json"); });
    EXPECT_NE(message.find(corruption.pointer), std::string::npos)
        << corruption.name << ": " << message;
    EXPECT_NE(message.find(corruption.expected), std::string::npos)
        << corruption.name << ": " << message;
  }
}

}  // namespace
}  // namespace autograv
