#include "autograv/viz/vtk_export.h"

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "autograv/error.h"
#include "viz_test_support.h"

// Export writes ASCII VTK XML; these tests read it back as text (no VTK, no display).
namespace autograv::viz {
namespace {

using testing::analyticGravity;
using testing::FixtureSpec;
using testing::makeFixtureMap;

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string scratchPath(const std::string& name) {
  return std::string(AUTOGRAV_BINARY_DIR) + "/vtk_export_test_" + name;
}

// The numbers of the <DataArray ... Name="name" ...> element.
std::vector<double> dataArray(const std::string& xml, const std::string& name) {
  const auto tag = xml.find("Name=\"" + name + "\"");
  if (tag == std::string::npos) return {};
  const auto start = xml.find('>', tag) + 1;
  const auto end = xml.find("</DataArray>", start);
  std::istringstream numbers(xml.substr(start, end - start));
  std::vector<double> values;
  double value = 0.0;
  while (numbers >> value) values.push_back(value);
  return values;
}

GravityMap exportFixture() {
  FixtureSpec spec;
  spec.failed = {5};
  spec.not_visited = {100};
  return makeFixtureMap(analyticGravity, spec);
}

TEST(VtkExportTest, ImageDataHoldsTheGridAndEveryArray) {
  const GravityMap map = exportFixture();
  const std::string path = scratchPath("map.vti");
  exportMap(map, path);
  const std::string xml = readText(path);
  EXPECT_NE(xml.find("<VTKFile type=\"ImageData\""), std::string::npos);
  EXPECT_NE(xml.find("WholeExtent=\"0 4 0 4 0 4\""), std::string::npos);
  EXPECT_NE(xml.find("Origin=\"-0.04 -0.04 -0.04\""), std::string::npos) << xml.substr(0, 400);
  EXPECT_NE(xml.find("Spacing=\"0.02 0.02 0.02\""), std::string::npos);
  EXPECT_NE(xml.find("Vectors=\"gravity_N\""), std::string::npos);
  const std::vector<double> gravity = dataArray(xml, "gravity_N");
  ASSERT_EQ(gravity.size(), 375u);
  for (int i = 0; i < 125; ++i) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(gravity[3 * i + c], map.vertices()[i].gravity_n[c], 1e-9) << i;
    }
  }
  const std::vector<double> outcome = dataArray(xml, "outcome");
  ASSERT_EQ(outcome.size(), 125u);
  EXPECT_EQ(outcome[5], static_cast<int>(VertexOutcome::kIterationCap));
  EXPECT_EQ(outcome[100], static_cast<int>(VertexOutcome::kPending));
  EXPECT_EQ(outcome[0], static_cast<int>(VertexOutcome::kConverged));
  const std::vector<double> iterations = dataArray(xml, "iterations");
  ASSERT_EQ(iterations.size(), 125u);
  EXPECT_EQ(iterations[3], map.vertices()[3].iterations);
  const std::vector<double> mass = dataArray(xml, "apparent_mass_kg");
  ASSERT_EQ(mass.size(), 125u);
  EXPECT_NEAR(mass[7], map.vertices()[7].gravity_n.norm() / kStandardGravity, 1e-9);
  EXPECT_EQ(dataArray(xml, "seconds_s").size(), 125u);
  EXPECT_EQ(dataArray(xml, "gravity_magnitude_N").size(), 125u);
  EXPECT_TRUE(dataArray(xml, "residual_N").empty());  // no truth given
  EXPECT_NE(xml.find("Name=\"outcome_names\""), std::string::npos);
  EXPECT_NE(xml.find("Name=\"device_model\""), std::string::npos);
  std::remove(path.c_str());
}

TEST(VtkExportTest, UnstructuredGridHasHexahedraAndTheResidual) {
  const GravityMap map = exportFixture();
  const std::string path = scratchPath("map.vtu");
  ExportOptions options;
  options.ground_truth = analyticGravity;
  exportMap(map, path, options);
  const std::string xml = readText(path);
  EXPECT_NE(xml.find("<VTKFile type=\"UnstructuredGrid\""), std::string::npos);
  EXPECT_NE(xml.find("NumberOfPoints=\"125\" NumberOfCells=\"64\""), std::string::npos);
  const std::vector<double> connectivity = dataArray(xml, "connectivity");
  ASSERT_EQ(connectivity.size(), 64u * 8u);
  const std::vector<double> first = {0, 1, 6, 5, 25, 26, 31, 30};
  for (int k = 0; k < 8; ++k) EXPECT_EQ(connectivity[k], first[k]);
  const std::vector<double> types = dataArray(xml, "types");
  ASSERT_EQ(types.size(), 64u);
  EXPECT_EQ(types[0], 12);  // VTK_HEXAHEDRON
  const std::vector<double> points = dataArray(xml, "Points");
  ASSERT_EQ(points.size(), 375u);
  const Eigen::Vector3d p31 = map.grid().vertexPosition(31);
  EXPECT_NEAR(points[93], p31.x(), 1e-12);
  EXPECT_NEAR(points[94], p31.y(), 1e-12);
  EXPECT_NEAR(points[95], p31.z(), 1e-12);
  const std::vector<double> residual = dataArray(xml, "residual_N");
  const std::vector<double> truth = dataArray(xml, "true_gravity_N");
  ASSERT_EQ(residual.size(), 125u);
  ASSERT_EQ(truth.size(), 375u);
  for (int i : {0, 17, 124}) {
    const Eigen::Vector3d t = analyticGravity(map.grid().vertexPosition(i));
    EXPECT_NEAR(residual[i], (map.vertices()[i].gravity_n - t).norm(), 1e-9);
    EXPECT_NEAR(truth[3 * i + 2], t.z(), 1e-9);
  }
  std::remove(path.c_str());
}

TEST(VtkExportTest, RefusesOtherExtensionsAndUnwritablePlaces) {
  const GravityMap map = exportFixture();
  try {
    exportMap(map, scratchPath("map.vtk"));
    FAIL() << "expected autograv::Error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("use .vti"), std::string::npos) << error.what();
  }
  EXPECT_THROW(exportMap(map, scratchPath("map")), Error);
  EXPECT_THROW(exportMap(map, "/nonexistent/folder/map.vti"), Error);
}

}  // namespace
}  // namespace autograv::viz
