// The fitted lookups: the conservative fit (one potential through every measurement), the
// componentwise and the corrected fits, the choice between them, and schema 5.
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "allocation_counter.h"
#include "autograv/error.h"
#include "autograv/map/field_fit.h"
#include "autograv/map/gravity_map.h"
#include "autograv/map/map_io.h"
#include "autograv/map/vertex_fill.h"
#include "core/map/map_json.h"
#include "scratch_folder.h"

namespace autograv {
namespace {

// G = A x + b with A symmetric: the gradient of a quadratic potential (a weight and a linear
// spring). Unit: [N]
Eigen::Vector3d quadraticPotentialField(const Eigen::Vector3d& x_m) {
  Eigen::Matrix3d slope;
  slope << 2.0, -1.0, 0.5, -1.0, 1.5, -2.0, 0.5, -2.0, 3.0;
  return Eigen::Vector3d(0.1, -0.2, 1.0) + slope * x_m;
}

// The gradient of U = z + 0.01 (cos 20x + sin 15y cos 12z): a field that bends over the
// workspace as a linkage's does, by up to a fifth of its magnitude. Unit: [N]
Eigen::Vector3d curvedPotentialField(const Eigen::Vector3d& x_m) {
  const double x = x_m.x();
  const double y = x_m.y();
  const double z = x_m.z();
  return Eigen::Vector3d(-0.2 * std::sin(20.0 * x), 0.15 * std::cos(15.0 * y) * std::cos(12.0 * z),
                         1.0 - 0.12 * std::sin(15.0 * y) * std::sin(12.0 * z));
}

// The curved potential's gradient plus a smooth field without divergence of up to 43 mN (about
// 4 % of |G|), 0.025 (sin 20y, sin 20z, sin 20x): a field with a known curl, as unequal motor
// gains on a delta mechanism leave in the force that holds it. Unit: [N]
Eigen::Vector3d curledField(const Eigen::Vector3d& x_m) {
  return curvedPotentialField(x_m) + 0.025 * Eigen::Vector3d(std::sin(20.0 * x_m.y()),
                                                             std::sin(20.0 * x_m.z()),
                                                             std::sin(20.0 * x_m.x()));
}

// G = A x + b with any A (here with a rotation, a curl): every fit with a curl weight reproduces
// it. Unit: [N]
Eigen::Vector3d affineField(const Eigen::Vector3d& x_m) {
  Eigen::Matrix3d slope;
  slope << 2.0, -3.0, 0.5, 1.0, 1.5, -2.0, -0.5, 2.5, 3.0;
  return Eigen::Vector3d(0.1, -0.2, 1.0) + slope * x_m;
}

std::vector<Eigen::Vector3d> scatteredPoints(int count, double half_m, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> coordinate(-half_m, half_m);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i) {
    points.emplace_back(coordinate(random), coordinate(random), coordinate(random));
  }
  return points;
}

std::vector<Eigen::Vector3d> valuesAt(const std::vector<Eigen::Vector3d>& points,
                                      Eigen::Vector3d (*field)(const Eigen::Vector3d&)) {
  std::vector<Eigen::Vector3d> values;
  for (const Eigen::Vector3d& p : points) values.push_back(field(p));
  return values;
}

constexpr double kSphereRadius_m = 0.045;
constexpr double kBoundaryMargin_m = 0.004;

// A 5x5x5 map over a ball-shaped workspace as the calibration makes it: vertices 4 mm or more
// inside the ball measured where they are, those within a cell beyond it measured 4 mm inside
// along their ray, the rest unreachable; values filled as the calibration fills them.
GravityMap ballMap(Eigen::Vector3d (*field)(const Eigen::Vector3d&), FieldModel model) {
  const WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.1, 5);
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (int i = 0; i < grid.vertexCount(); ++i) {
    VertexEstimate& v = vertices[static_cast<std::size_t>(i)];
    const Eigen::Vector3d at = grid.vertexPosition(i);
    const double radius_m = at.norm();
    if (radius_m <= kSphereRadius_m - kBoundaryMargin_m) {
      v.outcome = VertexOutcome::kConverged;
      v.gravity_n = field(at);
    } else if (radius_m <= kSphereRadius_m + grid.maxSpacing_m()) {
      v.outcome = VertexOutcome::kConverged;
      v.measured_at_m = at * (kSphereRadius_m - kBoundaryMargin_m) / radius_m;
      v.measured_gravity_n = field(v.measured_at_m);
    } else {
      v.outcome = VertexOutcome::kUnreachable;
    }
  }
  fillUnreachableVertices(grid, vertices);
  MapMetadata metadata;
  metadata.device_model = "test";
  metadata.created_utc = "2026-12-04T12:00:00Z";
  // What the tools write for each model.
  metadata.lookup_refinement = lookupRefinementFor(grid, kDefaultLookupRefinement, model);
  metadata.field_model = model;
  return GravityMap(grid, std::move(vertices), metadata);
}

// The 99th percentile of the lookup's relative error at points uniform over the ball.
double ballErrorP99(const GravityMap& map, Eigen::Vector3d (*field)(const Eigen::Vector3d&)) {
  std::vector<double> errors;
  for (const Eigen::Vector3d& p : scatteredPoints(6000, kSphereRadius_m, 11)) {
    if (p.norm() > kSphereRadius_m) continue;
    errors.push_back((map.gravityAt(p) - field(p)).norm() / field(p).norm());
  }
  std::sort(errors.begin(), errors.end());
  return errors[static_cast<std::size_t>(0.99 * static_cast<double>(errors.size() - 1))];
}

TEST(FieldFitTest, ReproducesEveryMeasurementAndAnyQuadraticPotentialsField) {
  const std::vector<Eigen::Vector3d> points = scatteredPoints(40, 0.05, 3);
  const FieldFit fit(points, valuesAt(points, quadraticPotentialField));
  EXPECT_EQ(fit.measurementCount(), 40);
  // Between the points and 5 cm beyond them: exact.
  for (const Eigen::Vector3d& p : scatteredPoints(300, 0.10, 4)) {
    EXPECT_LT((fit.at(p) - quadraticPotentialField(p)).norm(), 1e-8) << p.transpose();
  }
  const FieldFit curved(points, valuesAt(points, curvedPotentialField));
  for (const Eigen::Vector3d& p : points) {
    EXPECT_LT((curved.at(p) - curvedPotentialField(p)).norm(), 1e-8) << p.transpose();
  }
}

// The leave-one-out residuals from one inverse are those of n refits, and they point at the
// measurement that disagrees with the others: the one carrying a 30 mN error.
TEST(FieldFitTest, LeaveOneOutResidualsAreThoseOfRefitsWithoutEachMeasurement) {
  const std::vector<Eigen::Vector3d> points = scatteredPoints(30, 0.05, 5);
  std::vector<Eigen::Vector3d> values = valuesAt(points, curvedPotentialField);
  constexpr std::size_t kOff = 17;
  values[kOff] += Eigen::Vector3d(0.0, 0.03, 0.0);
  const std::vector<Eigen::Vector3d> residuals_n = leaveOneOutResiduals_n(points, values);
  ASSERT_EQ(residuals_n.size(), points.size());
  std::size_t largest = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::vector<Eigen::Vector3d> others = points;
    std::vector<Eigen::Vector3d> other_values = values;
    others.erase(others.begin() + static_cast<std::ptrdiff_t>(i));
    other_values.erase(other_values.begin() + static_cast<std::ptrdiff_t>(i));
    const Eigen::Vector3d refit_n = FieldFit(others, other_values).at(points[i]) - values[i];
    EXPECT_LT((residuals_n[i] - refit_n).norm(), 1e-6 + 1e-4 * refit_n.norm())
        << "measurement " << i;
    if (residuals_n[i].norm() > residuals_n[largest].norm()) largest = i;
  }
  EXPECT_EQ(largest, kOff);
  // The others predict the true field there, so the residual is the error, less what the fit of
  // a curved field misses.
  EXPECT_NEAR(residuals_n[kOff].y(), -0.03, 0.01);
  // A field the fit reproduces exactly leaves nothing to predict.
  for (const Eigen::Vector3d& r :
       leaveOneOutResiduals_n(points, valuesAt(points, quadraticPotentialField))) {
    EXPECT_LT(r.norm(), 1e-6);
  }
  EXPECT_THROW(
      leaveOneOutResiduals_n(std::vector<Eigen::Vector3d>(points.begin(), points.begin() + 3),
                             std::vector<Eigen::Vector3d>(values.begin(), values.begin() + 3)),
      Error);
}

// A map's agreement names the vertex whose measurement the others do not predict, and nothing
// when they all agree.
TEST(FieldFitTest, AgreementNamesTheVertexTheOthersDoNotPredict) {
  GravityMap agreeing = ballMap(quadraticPotentialField, FieldModel::kConservative);
  const MeasurementAgreement clean = measurementAgreement(agreeing.grid(), agreeing.vertices());
  EXPECT_GT(clean.measurements, 20);
  EXPECT_LT(clean.max_rel, 1e-6);
  EXPECT_TRUE(clean.least_sure_vertices.empty());

  std::vector<VertexEstimate> vertices = agreeing.vertices();
  const int off = agreeing.grid().vertexIndex(2, 2, 2);  // the centre, measured where it is
  ASSERT_EQ(vertices[static_cast<std::size_t>(off)].outcome, VertexOutcome::kConverged);
  vertices[static_cast<std::size_t>(off)].gravity_n += Eigen::Vector3d(0.05, 0.0, 0.0);
  const MeasurementAgreement spoilt = measurementAgreement(agreeing.grid(), vertices);
  ASSERT_FALSE(spoilt.least_sure_vertices.empty());
  EXPECT_EQ(spoilt.least_sure_vertices.front(), off);
  EXPECT_LE(static_cast<int>(spoilt.least_sure_vertices.size()), MeasurementAgreement::kListed);
  EXPECT_GT(spoilt.max_rel, MeasurementAgreement::kWorthMeasuring);
  EXPECT_LE(spoilt.median_rel, spoilt.p90_rel);
  EXPECT_LE(spoilt.p90_rel, spoilt.max_rel);
}

TEST(FieldFitTest, RefusesMeasurementsThatDoNotDetermineAField) {
  const std::vector<Eigen::Vector3d> points = scatteredPoints(6, 0.05, 5);
  const std::vector<Eigen::Vector3d> values = valuesAt(points, curvedPotentialField);
  const auto refusal = [](const std::vector<Eigen::Vector3d>& p,
                          const std::vector<Eigen::Vector3d>& v) -> std::string {
    try {
      FieldFit fit(p, v);
    } catch (const Error& error) {
      return error.what();
    }
    return "accepted";
  };
  EXPECT_NE(refusal(points, {values.begin(), values.end() - 1}).find("6 points but 5 values"),
            std::string::npos);
  EXPECT_NE(refusal({points.begin(), points.begin() + 3}, {values.begin(), values.begin() + 3})
                .find("3 measurements; it needs at least 4"),
            std::string::npos);
  std::vector<Eigen::Vector3d> not_finite = values;
  not_finite[2].y() = std::nan("");
  EXPECT_NE(refusal(points, not_finite).find("measurement 2 is not finite"), std::string::npos);
  std::vector<Eigen::Vector3d> on_a_line;
  for (int i = 0; i < 6; ++i) on_a_line.emplace_back(0.01 * i, 0.02 * i, -0.01 * i);
  EXPECT_NE(refusal(on_a_line, values).find("do not determine the field"), std::string::npos);
  const std::vector<Eigen::Vector3d> one_point(6, Eigen::Vector3d(0.01, 0.0, 0.0));
  EXPECT_NE(refusal(one_point, values).find("every measurement is at one point"),
            std::string::npos);
}

TEST(FieldFitTest, TheMapFollowsACurvedFieldNearTheStopsBetterThanTheThinPlate) {
  const GravityMap thin_plate = ballMap(curvedPotentialField, FieldModel::kThinPlate);
  const GravityMap conservative = ballMap(curvedPotentialField, FieldModel::kConservative);
  ASSERT_EQ(thin_plate.fieldModel(), FieldModel::kThinPlate);
  ASSERT_EQ(conservative.fieldModel(), FieldModel::kConservative);
  const double thin_plate_p99 = ballErrorP99(thin_plate, curvedPotentialField);
  const double conservative_p99 = ballErrorP99(conservative, curvedPotentialField);
  RecordProperty("thin_plate_p99_percent", std::to_string(100.0 * thin_plate_p99));
  RecordProperty("conservative_p99_percent", std::to_string(100.0 * conservative_p99));
  EXPECT_LT(conservative_p99, 0.5 * thin_plate_p99)
      << "thin plate " << thin_plate_p99 << ", conservative " << conservative_p99;
  // An affine field that is a potential's gradient stays exact everywhere in the ball.
  EXPECT_LT(ballErrorP99(ballMap(quadraticPotentialField, FieldModel::kConservative),
                         quadraticPotentialField),
            1e-8);
}

TEST(FieldFitTest, MapValuesNotMeasuredWhereTheyStandFollowTheFit) {
  const GravityMap map = ballMap(curvedPotentialField, FieldModel::kConservative);
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> values;
  collectMeasurements(map.grid(), map.vertices(), points, values);
  const FieldFit fit(points, values);
  int filled = 0;
  for (int i = 0; i < map.grid().vertexCount(); ++i) {
    const VertexEstimate& v = map.vertices()[static_cast<std::size_t>(i)];
    const Eigen::Vector3d at = map.grid().vertexPosition(i);
    if (v.provenance == VertexProvenance::kFilled) {
      ++filled;
      EXPECT_LT((v.gravity_n - fit.at(at)).norm(), 1e-12) << i;
    } else if (v.outcome == VertexOutcome::kConverged) {
      EXPECT_EQ(v.gravity_n, curvedPotentialField(at)) << i;  // measured values stay
    }
    // The lookup gives the vertex's value where it stands.
    EXPECT_LT((map.gravityAt(at) - v.gravity_n).norm(), 1e-8) << i;
  }
  EXPECT_GT(filled, 40);
  bool inside = false;
  double sum = 0.0;
  testing::AllocationCounter counter;
  for (int k = 0; k < 10000; ++k) {
    const Eigen::Vector3d x(-0.06 + 1.2e-5 * k, 0.01, -0.02);
    sum += map.gravityAt(x).z() + map.gravityAt(x, 0.005, inside).z();
  }
  EXPECT_EQ(counter.count(), 0u);
  EXPECT_TRUE(std::isfinite(sum));
}

TEST(FieldFitTest, TooFewMeasurementsKeepTheThinPlateLookup) {
  const WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.1, 3);
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (int i = 0; i < grid.vertexCount(); ++i) {
    VertexEstimate& v = vertices[static_cast<std::size_t>(i)];
    v.outcome = i < 3 ? VertexOutcome::kConverged : VertexOutcome::kUnreachable;
    v.gravity_n = curvedPotentialField(grid.vertexPosition(i));
  }
  fillUnreachableVertices(grid, vertices);
  MapMetadata metadata;
  metadata.field_model = FieldModel::kConservative;
  metadata.lookup_refinement = kDefaultLookupRefinement;
  const GravityMap map(grid, vertices, metadata);
  EXPECT_EQ(map.fieldModel(), FieldModel::kThinPlate);
  EXPECT_EQ(map.metadata().field_model, FieldModel::kConservative);
  // The thin plate at the refinement of the maps before the fit: its sparse solve at 6 would
  // take seconds.
  EXPECT_EQ(map.lookupRefinement(), kThinPlateRefinement);
  EXPECT_EQ(map.metadata().lookup_refinement, kDefaultLookupRefinement);
  for (int i = 0; i < grid.vertexCount(); ++i) {
    EXPECT_EQ(map.vertices()[static_cast<std::size_t>(i)].gravity_n,
              vertices[static_cast<std::size_t>(i)].gravity_n);
  }
}

TEST(FieldFitTest, RoundTripsWithTheSameLookup) {
  const testing::ScratchFolder folder("field-fit");
  const std::string path = folder.file("conservative_map.json");
  const GravityMap original = ballMap(curvedPotentialField, FieldModel::kConservative);
  saveMap(original, path);
  const GravityMap loaded = loadMap(path);
  EXPECT_EQ(loaded.metadata().field_model, FieldModel::kConservative);
  EXPECT_EQ(loaded.fieldModel(), FieldModel::kConservative);
  EXPECT_EQ(loaded.metadata().lookup_refinement, kDefaultLookupRefinement);
  for (int i = 0; i < original.grid().vertexCount(); ++i) {
    EXPECT_EQ(loaded.vertices()[static_cast<std::size_t>(i)].gravity_n,
              original.vertices()[static_cast<std::size_t>(i)].gravity_n)
        << i;
  }
  for (const Eigen::Vector3d& p : scatteredPoints(200, 0.06, 9)) {
    EXPECT_EQ(loaded.gravityAt(p), original.gravityAt(p)) << p.transpose();
  }
  // The same map as schema 4 wrote it (the interpolant in the grid, no field_model) loads with
  // the same model and lookup.
  nlohmann::json schema4 = nlohmann::json::parse(mapToJson(original));
  schema4["schema_version"] = 4;
  schema4.erase("field_model");
  schema4["grid"]["lookup_interpolant"] = "conservative";
  detail::stampChecksum(schema4);
  const GravityMap old = mapFromJson(schema4.dump(), "schema4.json");
  EXPECT_EQ(old.fieldModel(), FieldModel::kConservative);
  EXPECT_TRUE(old.metadata().field_model_scores.empty());
  for (const Eigen::Vector3d& p : scatteredPoints(200, 0.06, 9)) {
    EXPECT_EQ(old.gravityAt(p), original.gravityAt(p)) << p.transpose();
  }
  EXPECT_STREQ(toString(FieldModel::kConservative), "conservative");
  FieldModel parsed = FieldModel::kConservative;
  EXPECT_TRUE(parseFieldModel("thin_plate", parsed));
  EXPECT_EQ(parsed, FieldModel::kThinPlate);
  EXPECT_TRUE(parseFieldModel("corrected", parsed));
  EXPECT_EQ(parsed, FieldModel::kCorrected);
  EXPECT_FALSE(parseFieldModel("spline", parsed));
}

TEST(FieldFitTest, TheToolsRefinementFitsEveryGrid) {
  // One grid cell of padding per side: 37^3 lookup vertices on a 5x5x5 grid at 6; a 6x6x6
  // grid would take 43^3 at 6, 36^3 at 5; an 8x8x8 grid 43^3 at 5, 37^3 at 4.
  EXPECT_EQ(lookupResolution(WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 5), 6,
                             FieldModel::kConservative),
            Eigen::Vector3i::Constant(37));
  EXPECT_EQ(lookupRefinementFor(WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 5), 6), 6);
  EXPECT_EQ(lookupRefinementFor(WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 6), 6), 5);
  EXPECT_EQ(lookupRefinementFor(WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 8), 6), 4);
  // A 9x9x9 grid has more vertices than a fit takes: the thin plate's refinement, while its
  // sparse solve stays within seconds (23^3 lookup vertices on a 12x12x12 grid, 25^3 on 13x13x13).
  EXPECT_EQ(lookupRefinementFor(WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 9), 4), 2);
  EXPECT_EQ(lookupRefinementFor(WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 12), 6), 2);
  EXPECT_EQ(lookupRefinementFor(WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 13), 6), 1);
  EXPECT_EQ(lookupRefinementFor(WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 5), 6,
                                FieldModel::kThinPlate),
            kThinPlateRefinement);
  EXPECT_EQ(lookupRefinementFor(WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 40), 4), 1);
  EXPECT_EQ(lookupRefinementFor(WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 5), 0), 1);
  for (const int resolution : {3, 8, 9, 17, 33}) {
    const WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.1, resolution);
    std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
    for (int i = 0; i < grid.vertexCount(); ++i) {
      vertices[static_cast<std::size_t>(i)].outcome = VertexOutcome::kConverged;
      vertices[static_cast<std::size_t>(i)].gravity_n =
          curvedPotentialField(grid.vertexPosition(i));
    }
    MapMetadata metadata;
    metadata.lookup_refinement = lookupRefinementFor(grid, kDefaultLookupRefinement);
    // The fit the tools make, given rather than chosen: choosing at 512 measurements would take
    // seconds, and its refinement is the point here.
    metadata.field_model = FieldModel::kConservative;
    const GravityMap map(grid, vertices, metadata);
    // Past FieldFit::kMaxMeasurements (512, an 8x8x8 grid's) the thin plate.
    EXPECT_EQ(map.fieldModel(),
              resolution <= 8 ? FieldModel::kConservative : FieldModel::kThinPlate)
        << resolution;
  }
}

TEST(FieldFitTest, EveryCurlWeightReproducesTheMeasurementsAndItsAffineFields) {
  const std::vector<Eigen::Vector3d> points = scatteredPoints(40, 0.05, 3);
  for (const double weight : {0.01, 0.3, 1.0, 10.0}) {
    const FieldFit fit(points, valuesAt(points, affineField), weight);
    EXPECT_EQ(fit.curlWeight(), weight);
    for (const Eigen::Vector3d& p : scatteredPoints(100, 0.10, 4)) {
      EXPECT_LT((fit.at(p) - affineField(p)).norm(), 1e-8) << weight << ": " << p.transpose();
    }
    const FieldFit curled(points, valuesAt(points, curledField), weight);
    for (const Eigen::Vector3d& p : points) {
      EXPECT_LT((curled.at(p) - curledField(p)).norm(), 1e-8) << weight << ": " << p.transpose();
    }
  }
  // The conservative fit has no rotation to give: a field with a curl is not reproduced between
  // its measurements.
  const FieldFit conservative(points, valuesAt(points, affineField));
  EXPECT_GT((conservative.at(Eigen::Vector3d(0.07, -0.07, 0.07)) -
             affineField(Eigen::Vector3d(0.07, -0.07, 0.07)))
                .norm(),
            1e-3);
  EXPECT_THROW(FieldFit(points, valuesAt(points, affineField), -0.5), Error);
  EXPECT_THROW(FieldFit(points, valuesAt(points, affineField), FieldFit::kMaxCurlWeight * 2),
               Error);
}

// At curl weight 1 the two kernels add up to |x|^3 I: each component is fitted from its own
// measured values alone.
TEST(FieldFitTest, WeightOneFitsEachComponentOnItsOwn) {
  const std::vector<Eigen::Vector3d> points = scatteredPoints(30, 0.05, 6);
  const std::vector<Eigen::Vector3d> values = valuesAt(points, curvedPotentialField);
  std::vector<Eigen::Vector3d> other_y = values;
  for (std::size_t i = 0; i < other_y.size(); ++i) other_y[i].y() += 0.1 * std::sin(3.0 * i);
  const FieldFit fit(points, values, 1.0);
  const FieldFit changed(points, other_y, 1.0);
  const FieldFit conservative(points, values);
  const FieldFit changed_conservative(points, other_y);
  double conservative_x_change = 0.0;
  for (const Eigen::Vector3d& p : scatteredPoints(50, 0.05, 7)) {
    EXPECT_NEAR(fit.at(p).x(), changed.at(p).x(), 1e-9) << p.transpose();
    EXPECT_NEAR(fit.at(p).z(), changed.at(p).z(), 1e-9) << p.transpose();
    conservative_x_change = std::max(
        conservative_x_change, std::abs(conservative.at(p).x() - changed_conservative.at(p).x()));
  }
  // The conservative fit ties the components together.
  EXPECT_GT(conservative_x_change, 1e-3);
}

// The leave-one-out residuals of every curl weight are those of refits without each measurement.
TEST(FieldFitTest, LeaveOneOutResidualsOfEveryWeightAreThoseOfRefits) {
  const std::vector<Eigen::Vector3d> points = scatteredPoints(25, 0.05, 8);
  const std::vector<Eigen::Vector3d> values = valuesAt(points, curledField);
  for (const double weight : {0.1, 1.0, 10.0}) {
    const std::vector<Eigen::Vector3d> residuals_n = leaveOneOutResiduals_n(points, values, weight);
    ASSERT_EQ(residuals_n.size(), points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
      std::vector<Eigen::Vector3d> others = points;
      std::vector<Eigen::Vector3d> other_values = values;
      others.erase(others.begin() + static_cast<std::ptrdiff_t>(i));
      other_values.erase(other_values.begin() + static_cast<std::ptrdiff_t>(i));
      const Eigen::Vector3d refit_n =
          FieldFit(others, other_values, weight).at(points[i]) - values[i];
      EXPECT_LT((residuals_n[i] - refit_n).norm(), 1e-6 + 1e-4 * refit_n.norm())
          << "weight " << weight << ", measurement " << i;
    }
  }
}

// The mean, median and 90th percentile of |refit without point i - value i| / |value i|: what
// each candidate's score says.
FieldModelScore refitScore(const std::vector<Eigen::Vector3d>& points,
                           const std::vector<Eigen::Vector3d>& values, double weight) {
  std::vector<double> ratios;
  double sum = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::vector<Eigen::Vector3d> others = points;
    std::vector<Eigen::Vector3d> other_values = values;
    others.erase(others.begin() + static_cast<std::ptrdiff_t>(i));
    other_values.erase(other_values.begin() + static_cast<std::ptrdiff_t>(i));
    const double ratio = (FieldFit(others, other_values, weight).at(points[i]) - values[i]).norm() /
                         values[i].norm();
    ratios.push_back(ratio);
    sum += ratio;
  }
  std::sort(ratios.begin(), ratios.end());
  FieldModelScore score;
  score.curl_weight = weight;
  score.median_rel = ratios[static_cast<std::size_t>(0.5 * static_cast<double>(ratios.size() - 1))];
  score.p90_rel = ratios[static_cast<std::size_t>(0.9 * static_cast<double>(ratios.size() - 1))];
  score.mean_rel = sum / static_cast<double>(ratios.size());
  return score;
}

std::vector<Eigen::Vector3d> measurementsOf(const GravityMap& map,
                                            std::vector<Eigen::Vector3d>& values) {
  std::vector<Eigen::Vector3d> points;
  collectMeasurements(map.grid(), map.vertices(), points, values);
  return points;
}

TEST(FieldModelChoiceTest, TheScoresAreTheErrorsOfRefitsWithoutEachPoint) {
  const GravityMap map = ballMap(curledField, FieldModel::kChoose);
  const std::vector<FieldModelScore>& scores = map.metadata().field_model_scores;
  ASSERT_EQ(scores.size(), 3u);
  EXPECT_EQ(scores[0].model, FieldModel::kConservative);
  EXPECT_EQ(scores[1].model, FieldModel::kComponentwise);
  EXPECT_EQ(scores[2].model, FieldModel::kCorrected);
  EXPECT_EQ(scores[0].curl_weight, 0.0);
  EXPECT_EQ(scores[1].curl_weight, 1.0);
  std::vector<Eigen::Vector3d> values;
  const std::vector<Eigen::Vector3d> points = measurementsOf(map, values);
  for (const FieldModelScore& score : scores) {
    const FieldModelScore refit = refitScore(points, values, score.curl_weight);
    EXPECT_NEAR(score.mean_rel, refit.mean_rel, 1e-6 * refit.mean_rel) << toString(score.model);
    EXPECT_NEAR(score.median_rel, refit.median_rel, 1e-6 * refit.mean_rel) << toString(score.model);
    EXPECT_NEAR(score.p90_rel, refit.p90_rel, 1e-6 * refit.mean_rel) << toString(score.model);
  }
  // The corrected candidate's weight is the best of those it tries.
  for (const double weight : correctedCurlWeights()) {
    EXPECT_GE(refitScore(points, values, weight).mean_rel, scores[2].mean_rel * (1.0 - 1e-6))
        << weight;
  }
}

TEST(FieldModelChoiceTest, AConservativeFieldKeepsTheConservativeFit) {
  const GravityMap map = ballMap(curvedPotentialField, FieldModel::kChoose);
  EXPECT_EQ(map.fieldModel(), FieldModel::kConservative);
  EXPECT_EQ(map.metadata().field_model, FieldModel::kConservative);
  EXPECT_EQ(map.curlWeight(), 0.0);
  const std::vector<FieldModelScore>& scores = map.metadata().field_model_scores;
  ASSERT_EQ(scores.size(), 3u);
  EXPECT_LT(scores[0].mean_rel, scores[1].mean_rel);
  EXPECT_LT(scores[0].mean_rel, scores[2].mean_rel / (1.0 - kFieldModelMargin));
  // The same lookup as the conservative fit given.
  const GravityMap given = ballMap(curvedPotentialField, FieldModel::kConservative);
  for (const Eigen::Vector3d& p : scatteredPoints(100, 0.05, 12)) {
    EXPECT_EQ(map.gravityAt(p), given.gravityAt(p));
  }
}

// The corrected model asked for without a weight gets the weight a choice would give it.
TEST(FieldModelChoiceTest, TheCorrectedModelForcedChoosesItsWeight) {
  const GravityMap chosen = ballMap(curledField, FieldModel::kChoose);
  const GravityMap forced = ballMap(curledField, FieldModel::kCorrected);
  EXPECT_EQ(forced.fieldModel(), FieldModel::kCorrected);
  EXPECT_EQ(forced.curlWeight(), chosen.metadata().field_model_scores[2].curl_weight);
  ASSERT_EQ(forced.metadata().field_model_scores.size(), 1u);
  EXPECT_EQ(forced.metadata().field_model_scores[0].mean_rel,
            chosen.metadata().field_model_scores[2].mean_rel);
}

TEST(FieldModelChoiceTest, AFieldWithAKnownCurlIsRecoveredByTheCorrectedModel) {
  const GravityMap chosen = ballMap(curledField, FieldModel::kChoose);
  EXPECT_EQ(chosen.fieldModel(), FieldModel::kCorrected);
  EXPECT_GT(chosen.curlWeight(), 0.0);
  const double chosen_p99 = ballErrorP99(chosen, curledField);
  const double conservative_p99 =
      ballErrorP99(ballMap(curledField, FieldModel::kConservative), curledField);
  const double componentwise_p99 =
      ballErrorP99(ballMap(curledField, FieldModel::kComponentwise), curledField);
  RecordProperty("chosen_p99_percent", std::to_string(100.0 * chosen_p99));
  RecordProperty("conservative_p99_percent", std::to_string(100.0 * conservative_p99));
  RecordProperty("componentwise_p99_percent", std::to_string(100.0 * componentwise_p99));
  EXPECT_LT(chosen_p99, 0.5 * conservative_p99)
      << "chosen " << chosen_p99 << ", conservative " << conservative_p99;
  EXPECT_LE(chosen_p99, componentwise_p99 * 1.05)
      << "chosen " << chosen_p99 << ", componentwise " << componentwise_p99;
  // The choice is saved: the map loads with the same model, weight, scores and lookup.
  const testing::ScratchFolder folder("field-fit");
  const std::string path = folder.file("corrected_map.json");
  saveMap(chosen, path);
  const GravityMap loaded = loadMap(path);
  EXPECT_EQ(loaded.fieldModel(), FieldModel::kCorrected);
  EXPECT_EQ(loaded.curlWeight(), chosen.curlWeight());
  ASSERT_EQ(loaded.metadata().field_model_scores.size(), 3u);
  EXPECT_EQ(loaded.metadata().field_model_scores[2].mean_rel,
            chosen.metadata().field_model_scores[2].mean_rel);
  for (const Eigen::Vector3d& p : scatteredPoints(200, 0.06, 9)) {
    EXPECT_EQ(loaded.gravityAt(p), chosen.gravityAt(p)) << p.transpose();
  }
}

// Two eps_G of the default estimation parameters: what a calibration's measurements repeat to.
// Unit: [N]
constexpr double kFloor_n = kStandOutRepeatability * 0.5e-3 * 9.81;

TEST(FieldModelChoiceTest, OneMeasurementAStopHeldDoesNotChooseTheModel) {
  // Held 20 % short by a stop, one of 120 measurements: set aside, and the model is the one the
  // clean measurements choose (with every measurement counted, it chose the componentwise fit
  // for both fields).
  const std::vector<Eigen::Vector3d> points = scatteredPoints(120, 0.05, 21);
  // The measurement nearest the middle, among others that agree among themselves.
  int held_index = 0;
  for (std::size_t k = 1; k < points.size(); ++k) {
    if (points[k].cwiseAbs().maxCoeff() <
        points[static_cast<std::size_t>(held_index)].cwiseAbs().maxCoeff()) {
      held_index = static_cast<int>(k);
    }
  }
  for (auto field : {&curvedPotentialField, &curledField}) {
    std::vector<Eigen::Vector3d> values = valuesAt(points, field);
    const FieldModelChoice clean = chooseFieldModel(points, values, kFloor_n);
    EXPECT_TRUE(clean.set_aside.empty());
    values[static_cast<std::size_t>(held_index)] *= 0.8;
    const FieldModelChoice held = chooseFieldModel(points, values, kFloor_n);
    EXPECT_EQ(held.model, clean.model);
    EXPECT_EQ(held.set_aside, std::vector<int>{held_index});
  }
}

TEST(FieldModelChoiceTest, StandingOutFindsEachContradictedMeasurementAndNoneOfTheirNeighbours) {
  // Two measurements well inside the scatter (where the others surround them and agree among
  // themselves): one 15 % long, one knocked 5 % sideways.
  const std::vector<Eigen::Vector3d> points = scatteredPoints(120, 0.05, 22);
  std::vector<Eigen::Vector3d> values = valuesAt(points, curvedPotentialField);
  EXPECT_TRUE(findStandingOut(points, values, 0.0, 6, kFloor_n).empty());
  std::vector<int> by_depth(points.size());
  for (std::size_t k = 0; k < by_depth.size(); ++k) by_depth[k] = static_cast<int>(k);
  std::sort(by_depth.begin(), by_depth.end(), [&](int a, int b) {
    return points[static_cast<std::size_t>(a)].cwiseAbs().maxCoeff() <
           points[static_cast<std::size_t>(b)].cwiseAbs().maxCoeff();
  });
  const int longer = by_depth[0];
  int knocked = by_depth[1];
  for (std::size_t k = 1; k < by_depth.size(); ++k) {
    knocked = by_depth[k];
    if ((points[static_cast<std::size_t>(knocked)] - points[static_cast<std::size_t>(longer)])
            .norm() > 0.02) {
      break;
    }
  }
  values[static_cast<std::size_t>(longer)] *= 1.15;
  values[static_cast<std::size_t>(knocked)] += Eigen::Vector3d(0.05, 0.0, 0.0);
  std::vector<StandingOut> found = findStandingOut(points, values, 0.0, 6, kFloor_n);
  ASSERT_EQ(found.size(), 2u);
  EXPECT_EQ(found[0].index, longer);  // the most contradicted first
  EXPECT_EQ(found[1].index, knocked);
  for (const StandingOut& one : found) {
    EXPECT_GT(one.residual_rel, kStandOutLocalRatio * one.local_rel);
  }
  // At most `most`, and none among fewer than kStandOutMinMeasurements.
  EXPECT_EQ(findStandingOut(points, values, 0.0, 1, kFloor_n).size(), 1u);
  const std::vector<Eigen::Vector3d> few_points(points.begin(), points.begin() + 11);
  const std::vector<Eigen::Vector3d> few_values(values.begin(), values.begin() + 11);
  EXPECT_TRUE(findStandingOut(few_points, few_values, 0.0, 6, kFloor_n).empty());
}

}  // namespace
}  // namespace autograv
