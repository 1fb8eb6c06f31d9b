#include "autograv/viz/vtk_export.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <limits>

#include <vtkCellArray.h>
#include <vtkCellType.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkImageData.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkStringArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLImageDataWriter.h>
#include <vtkXMLUnstructuredGridWriter.h>
#include <vtkXMLWriter.h>

#include "autograv/error.h"
#include "autograv/map/map_io.h"
#include "viz/vtk_support.h"

namespace autograv::viz {

namespace {

std::string lowerExtension(const std::string& path) {
  const auto dot = path.find_last_of('.');
  const auto slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string extension = path.substr(dot);
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

// Point arrays, in vertex-index order (x fastest), which is also VTK's image-data point order.
void addPointArrays(const GravityMap& map, const ExportOptions& options, vtkPointData* data) {
  const int count = map.grid().vertexCount();
  vtkNew<vtkDoubleArray> gravity;
  gravity->SetName("gravity_N");
  gravity->SetNumberOfComponents(3);
  gravity->SetNumberOfTuples(count);
  vtkNew<vtkDoubleArray> magnitude;
  magnitude->SetName("gravity_magnitude_N");
  magnitude->SetNumberOfValues(count);
  vtkNew<vtkDoubleArray> mass;
  mass->SetName("apparent_mass_kg");
  mass->SetNumberOfValues(count);
  vtkNew<vtkIntArray> outcome;
  outcome->SetName("outcome");
  outcome->SetNumberOfValues(count);
  vtkNew<vtkIntArray> filled;  // 1 where the value was filled from measured neighbours
  filled->SetName("filled");
  filled->SetNumberOfValues(count);
  vtkNew<vtkIntArray> iterations;
  iterations->SetName("iterations");
  iterations->SetNumberOfValues(count);
  vtkNew<vtkDoubleArray> seconds;
  seconds->SetName("seconds_s");
  seconds->SetNumberOfValues(count);
  vtkNew<vtkDoubleArray> truth;
  truth->SetName("true_gravity_N");
  truth->SetNumberOfComponents(3);
  vtkNew<vtkDoubleArray> residual;
  residual->SetName("residual_N");
  if (options.ground_truth) {
    truth->SetNumberOfTuples(count);
    residual->SetNumberOfValues(count);
  }
  for (int i = 0; i < count; ++i) {
    const VertexEstimate& vertex = map.vertices()[static_cast<std::size_t>(i)];
    const Eigen::Vector3d& g = vertex.gravity_n;
    gravity->SetTuple3(i, g.x(), g.y(), g.z());
    magnitude->SetValue(i, g.norm());
    mass->SetValue(i, g.norm() / kStandardGravity);
    outcome->SetValue(i, static_cast<int>(vertex.outcome));
    filled->SetValue(i, vertex.provenance == VertexProvenance::kFilled ? 1 : 0);
    iterations->SetValue(i, vertex.iterations);
    seconds->SetValue(i, vertex.seconds);
    if (options.ground_truth && vertex.provenance == VertexProvenance::kFilled) {
      // Out of the device's reach: no truth to compare with ("no data" in ParaView).
      const double nan = std::numeric_limits<double>::quiet_NaN();
      truth->SetTuple3(i, nan, nan, nan);
      residual->SetValue(i, nan);
    } else if (options.ground_truth) {
      const Eigen::Vector3d t = options.ground_truth(map.grid().vertexPosition(i));
      if (!t.allFinite()) {
        throw Error("export: the ground truth is not finite at vertex " + std::to_string(i));
      }
      truth->SetTuple3(i, t.x(), t.y(), t.z());
      residual->SetValue(i, (g - t).norm());
    }
  }
  data->AddArray(gravity);
  data->SetActiveVectors("gravity_N");
  data->AddArray(magnitude);
  data->SetActiveScalars("gravity_magnitude_N");
  data->AddArray(mass);
  data->AddArray(outcome);
  data->AddArray(filled);
  data->AddArray(iterations);
  data->AddArray(seconds);
  if (options.ground_truth) {
    data->AddArray(truth);
    data->AddArray(residual);
  }
}

void addFieldData(const GravityMap& map, vtkFieldData* field) {
  vtkNew<vtkStringArray> model;
  model->SetName("device_model");
  model->InsertNextValue(map.metadata().device_model);
  vtkNew<vtkStringArray> unit;
  unit->SetName("length_unit");
  unit->InsertNextValue("m");
  // "outcome" codes are the VertexOutcome values: entry k names code k.
  vtkNew<vtkStringArray> names;
  names->SetName("outcome_names");
  for (const VertexOutcome o :
       {VertexOutcome::kPending, VertexOutcome::kConverged, VertexOutcome::kIterationCap,
        VertexOutcome::kNoSteadyState, VertexOutcome::kSaturated, VertexOutcome::kDeviceFault,
        VertexOutcome::kUnreachable, VertexOutcome::kLeftOut}) {
    names->InsertNextValue(toString(o));
  }
  field->AddArray(model);
  field->AddArray(unit);
  field->AddArray(names);
}

void write(vtkXMLWriter* writer, vtkDataObject* data, const std::string& path) {
  vtkNew<detail::ErrorCollector> errors;
  errors->watch(writer);
  writer->SetInputData(data);
  writer->SetDataModeToAscii();
  // Into memory, then atomically like maps and pictures: VTK's own file output would truncate an
  // earlier export first and leave half a file on a full disk.
  writer->WriteToOutputStringOn();
  const int ok = writer->Write();
  if (ok != 1 || errors->hasErrors()) {
    throw Error("export " + path + ": cannot write the file" +
                (errors->hasErrors() ? " (" + errors->text() + ")" : std::string()));
  }
  writeFileAtomically(path, writer->GetOutputString(), "export");
}

}  // namespace

void exportMap(const GravityMap& map, const std::string& path, const ExportOptions& options) {
  const std::string extension = lowerExtension(path);
  if (extension != ".vti" && extension != ".vtu") {
    throw Error("export " + path + ": unknown file type '" + extension +
                "'; use .vti (image data) or .vtu (unstructured grid)");
  }
  const WorkspaceGrid& grid = map.grid();
  const Eigen::Vector3i& n = grid.resolution();
  if (extension == ".vti") {
    vtkNew<vtkImageData> image;
    image->SetDimensions(n.x(), n.y(), n.z());
    const Eigen::Vector3d origin = grid.minCorner_m();
    image->SetOrigin(origin.x(), origin.y(), origin.z());
    const Eigen::Vector3d spacing = grid.spacing_m();
    image->SetSpacing(spacing.x(), spacing.y(), spacing.z());
    addPointArrays(map, options, image->GetPointData());
    addFieldData(map, image->GetFieldData());
    vtkNew<vtkXMLImageDataWriter> writer;
    write(writer, image, path);
    return;
  }
  vtkNew<vtkUnstructuredGrid> mesh;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(grid.vertexCount());
  for (int i = 0; i < grid.vertexCount(); ++i) {
    const Eigen::Vector3d p = grid.vertexPosition(i);
    points->SetPoint(i, p.x(), p.y(), p.z());
  }
  mesh->SetPoints(points);
  mesh->Allocate(static_cast<vtkIdType>(n.x() - 1) * (n.y() - 1) * (n.z() - 1));
  for (int iz = 0; iz + 1 < n.z(); ++iz) {
    for (int iy = 0; iy + 1 < n.y(); ++iy) {
      for (int ix = 0; ix + 1 < n.x(); ++ix) {
        // VTK's hexahedron order: the bottom face counter-clockwise, then the top face.
        const std::array<vtkIdType, 8> corners = {grid.vertexIndex(ix, iy, iz),
                                                  grid.vertexIndex(ix + 1, iy, iz),
                                                  grid.vertexIndex(ix + 1, iy + 1, iz),
                                                  grid.vertexIndex(ix, iy + 1, iz),
                                                  grid.vertexIndex(ix, iy, iz + 1),
                                                  grid.vertexIndex(ix + 1, iy, iz + 1),
                                                  grid.vertexIndex(ix + 1, iy + 1, iz + 1),
                                                  grid.vertexIndex(ix, iy + 1, iz + 1)};
        mesh->InsertNextCell(VTK_HEXAHEDRON, 8, corners.data());
      }
    }
  }
  addPointArrays(map, options, mesh->GetPointData());
  addFieldData(map, mesh->GetFieldData());
  vtkNew<vtkXMLUnstructuredGridWriter> writer;
  write(writer, mesh, path);
}

}  // namespace autograv::viz
