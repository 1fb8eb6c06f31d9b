#include "autograv/viz/image.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <fstream>
#include <iterator>

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPNGWriter.h>
#include <vtkPointData.h>
#include <vtkUnsignedCharArray.h>

#include "autograv/error.h"
#include "autograv/map/map_io.h"
#include "vtk_support.h"

namespace autograv::viz {

namespace {

constexpr std::array<unsigned char, 8> kPngSignature = {0x89, 'P',  'N',  'G',
                                                        '\r', '\n', 0x1a, '\n'};

}  // namespace

RgbImage readPng(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("image " + path + ": cannot open the file for reading (does it exist?)");
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)),
                                   std::istreambuf_iterator<char>());
  if (bytes.size() < kPngSignature.size() ||
      !std::equal(kPngSignature.begin(), kPngSignature.end(), bytes.begin())) {
    throw Error("image " + path + ": not a PNG file (the PNG signature is missing)");
  }
  vtkNew<vtkPNGReader> reader;
  vtkNew<detail::ErrorCollector> errors;
  errors->watch(reader);
  reader->SetMemoryBuffer(bytes.data());
  reader->SetMemoryBufferLength(static_cast<vtkIdType>(bytes.size()));
  reader->Update();
  vtkImageData* data = reader->GetOutput();
  int dims[3] = {0, 0, 0};
  data->GetDimensions(dims);
  vtkDataArray* scalars = data->GetPointData()->GetScalars();
  if (errors->hasErrors() || scalars == nullptr || dims[0] <= 0 || dims[1] <= 0) {
    throw Error("image " + path + ": cannot decode the PNG" +
                (errors->hasErrors() ? " (" + errors->text() + ")" : std::string()));
  }
  const int components = scalars->GetNumberOfComponents();
  // 16-bit PNGs come as unsigned short; keep their high byte.
  const double scale = scalars->GetDataType() == VTK_UNSIGNED_CHAR ? 1.0 : 1.0 / 257.0;
  RgbImage image;
  image.width_px = dims[0];
  image.height_px = dims[1];
  image.rgb.resize(static_cast<std::size_t>(dims[0]) * dims[1] * 3);
  for (int y = 0; y < dims[1]; ++y) {
    for (int x = 0; x < dims[0]; ++x) {
      const vtkIdType id = static_cast<vtkIdType>(dims[1] - 1 - y) * dims[0] + x;
      std::uint8_t* out = image.pixel(x, y);
      for (int c = 0; c < 3; ++c) {
        // Grey (and grey + alpha) images repeat their one colour channel.
        const int source = components >= 3 ? c : 0;
        const double value = scalars->GetComponent(id, source) * scale;
        out[c] = static_cast<std::uint8_t>(std::clamp(value + 0.5, 0.0, 255.0));
      }
    }
  }
  return image;
}

void writePng(const RgbImage& image, const std::string& path) {
  if (image.empty() ||
      image.rgb.size() != static_cast<std::size_t>(image.width_px) * image.height_px * 3) {
    throw Error("image " + path + ": nothing to write (empty or inconsistent image)");
  }
  vtkNew<vtkImageData> data;
  data->SetDimensions(image.width_px, image.height_px, 1);
  data->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  auto* scalars = vtkUnsignedCharArray::SafeDownCast(data->GetPointData()->GetScalars());
  unsigned char* target = scalars->GetPointer(0);
  const std::size_t row_bytes = static_cast<std::size_t>(image.width_px) * 3;
  for (int y = 0; y < image.height_px; ++y) {
    std::memcpy(target + static_cast<std::size_t>(image.height_px - 1 - y) * row_bytes,
                image.pixel(0, y), row_bytes);
  }
  vtkNew<vtkPNGWriter> writer;
  vtkNew<detail::ErrorCollector> errors;
  errors->watch(writer);
  writer->SetInputData(data);
  writer->WriteToMemoryOn();
  writer->Write();
  vtkUnsignedCharArray* encoded = writer->GetResult();
  if (errors->hasErrors() || encoded == nullptr || encoded->GetNumberOfValues() == 0) {
    throw Error("image " + path + ": PNG encoding failed" +
                (errors->hasErrors() ? " (" + errors->text() + ")" : std::string()));
  }
  // Atomically, like maps and reports: a reader (or a crash) never sees half a picture.
  writeFileAtomically(path,
                      std::string(reinterpret_cast<const char*>(encoded->GetPointer(0)),
                                  static_cast<std::size_t>(encoded->GetNumberOfValues())),
                      "image");
}

}  // namespace autograv::viz
