#include "viz/vtk_support.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <vtkColorTransferFunction.h>
#include <vtkImageData.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkObject.h>
#include <vtkPointData.h>
#include <vtkRenderWindow.h>
#include <vtkTextProperty.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>

#include "autograv/error.h"

namespace autograv::viz::detail {

Palette paletteFor(Background background) noexcept {
  if (background == Background::kDark) {
    return Palette{{0.09, 0.10, 0.13}, {0.93, 0.93, 0.93}, {0.55, 0.57, 0.62}, {0.45, 0.65, 0.95},
                   {1.00, 0.25, 0.25}, {0.70, 0.70, 0.70}, {1.00, 0.60, 0.05}, {0.30, 0.31, 0.36},
                   {0.75, 0.45, 0.95}, {0.95, 0.55, 0.78}};
  }
  return Palette{{1.0, 1.0, 1.0},    {0.05, 0.05, 0.05}, {0.62, 0.62, 0.62}, {0.35, 0.55, 0.85},
                 {0.85, 0.05, 0.05}, {0.45, 0.45, 0.45}, {0.95, 0.50, 0.00}, {0.85, 0.85, 0.85},
                 {0.55, 0.20, 0.75}, {0.93, 0.42, 0.68}};
}

void checkImageSize(int width_px, int height_px, const char* what) {
  constexpr int kMin = 16;
  constexpr int kMax = 8192;
  if (width_px < kMin || height_px < kMin || width_px > kMax || height_px > kMax) {
    std::ostringstream message;
    message << what << ": image size " << width_px << "x" << height_px
            << " px is out of range; use " << kMin << " to " << kMax << " px per side";
    throw Error(message.str());
  }
}

int baseFontPx(int height_px) noexcept { return std::max(11, (height_px + 24) / 48); }

namespace {

constexpr const char* kDejaVuSans = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
constexpr const char* kDejaVuSansBold = "/usr/share/fonts/truetype/dejavu/DejaVuSans-Bold.ttf";

bool fileExists(const char* path) {
  std::ifstream in(path, std::ios::binary);
  return static_cast<bool>(in);
}

}  // namespace

bool haveUnicodeFont() {
  static const bool present = fileExists(kDejaVuSans) && fileExists(kDejaVuSansBold);
  return present;
}

const char* pickText(const char* unicode, const char* ascii) {
  return haveUnicodeFont() ? unicode : ascii;
}

void styleText(vtkTextProperty* text, const Rgb& color, int size_px, bool bold) {
  text->SetColor(color[0], color[1], color[2]);
  text->SetFontSize(size_px);
  if (haveUnicodeFont()) {
    text->SetFontFamily(VTK_FONT_FILE);
    text->SetFontFile(bold ? kDejaVuSansBold : kDejaVuSans);
  } else {
    text->SetFontFamilyToArial();
  }
  text->SetBold(bold ? 1 : 0);
  text->SetItalic(0);
  text->SetShadow(0);
}

namespace {

struct ColorStop {
  double t;
  Rgb rgb;
};

// Control points sampled from the published colour maps (viridis by van der Walt and Smith,
// cool-warm by Moreland); the transfer function interpolates between them.
const std::vector<ColorStop>& stopsFor(ColorMap color_map) {
  static const std::vector<ColorStop> kViridis = {
      {0.000, {0.267, 0.005, 0.329}}, {0.125, {0.283, 0.141, 0.458}},
      {0.250, {0.254, 0.265, 0.530}}, {0.375, {0.207, 0.372, 0.553}},
      {0.500, {0.164, 0.471, 0.558}}, {0.625, {0.128, 0.567, 0.551}},
      {0.750, {0.135, 0.659, 0.518}}, {0.875, {0.478, 0.821, 0.318}},
      {1.000, {0.993, 0.906, 0.144}}};
  static const std::vector<ColorStop> kCoolWarm = {
      {0.0, {0.230, 0.299, 0.754}}, {0.5, {0.865, 0.865, 0.865}}, {1.0, {0.706, 0.016, 0.150}}};
  static const std::vector<ColorStop> kGrayscale = {{0.0, {0.15, 0.15, 0.15}},
                                                    {1.0, {0.85, 0.85, 0.85}}};
  switch (color_map) {
    case ColorMap::kCoolWarm:
      return kCoolWarm;
    case ColorMap::kGrayscale:
      return kGrayscale;
    case ColorMap::kViridis:
      break;
  }
  return kViridis;
}

vtkSmartPointer<vtkLookupTable> tableFromStops(const std::vector<ColorStop>& stops, double lo,
                                               double hi, bool diverging) {
  vtkNew<vtkColorTransferFunction> transfer;
  transfer->SetColorSpaceToRGB();
  if (diverging) transfer->SetColorSpaceToDiverging();
  for (const auto& stop : stops)
    transfer->AddRGBPoint(stop.t, stop.rgb[0], stop.rgb[1], stop.rgb[2]);
  constexpr int kEntries = 256;
  auto table = vtkSmartPointer<vtkLookupTable>::New();
  table->SetNumberOfTableValues(kEntries);
  for (int i = 0; i < kEntries; ++i) {
    double rgb[3];
    transfer->GetColor(static_cast<double>(i) / (kEntries - 1), rgb);
    table->SetTableValue(i, rgb[0], rgb[1], rgb[2], 1.0);
  }
  table->SetRange(lo, hi);
  return table;
}

}  // namespace

vtkSmartPointer<vtkLookupTable> makeLookupTable(ColorMap color_map, double lo, double hi) {
  return tableFromStops(stopsFor(color_map), lo, hi, color_map == ColorMap::kCoolWarm);
}

vtkSmartPointer<vtkLookupTable> makeResidualLookupTable(double hi) {
  static const std::vector<ColorStop> kReds = {{0.0, {1.000, 0.960, 0.940}},
                                               {0.35, {0.988, 0.573, 0.447}},
                                               {0.7, {0.871, 0.176, 0.149}},
                                               {1.0, {0.404, 0.000, 0.051}}};
  return tableFromStops(kReds, 0.0, hi, false);
}

XDisplay::XDisplay() {
  std::string reason;
  display_ = openXDisplay(&reason);
  if (display_ == nullptr) throw Error(reason);
}

void prepareOffscreen(vtkRenderWindow* window, const XDisplay& display, int width_px,
                      int height_px) {
  window->SetDisplayId(display.get());
  window->SetOffScreenRendering(1);
  window->SetMultiSamples(0);
  window->SetSize(width_px, height_px);
}

OffscreenWindow::OffscreenWindow(int width_px, int height_px)
    : window_(vtkSmartPointer<vtkRenderWindow>::New()) {
  prepareOffscreen(window_, display_, width_px, height_px);
}

RgbImage captureWindow(vtkRenderWindow* window) {
  window->Render();
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->ShouldRerenderOff();
  grab->Update();
  vtkImageData* data = grab->GetOutput();
  int dims[3];
  data->GetDimensions(dims);
  auto* scalars = vtkUnsignedCharArray::SafeDownCast(data->GetPointData()->GetScalars());
  if (scalars == nullptr || scalars->GetNumberOfComponents() < 3 || dims[0] <= 0 || dims[1] <= 0) {
    throw Error("render: could not read the rendered picture back from the OpenGL window");
  }
  const int components = scalars->GetNumberOfComponents();
  RgbImage image;
  image.width_px = dims[0];
  image.height_px = dims[1];
  image.rgb.resize(static_cast<std::size_t>(dims[0]) * dims[1] * 3);
  const unsigned char* source = scalars->GetPointer(0);
  for (int y = 0; y < dims[1]; ++y) {
    // VTK's rows go bottom-up; PNG rows go top-down.
    const unsigned char* row =
        source + static_cast<std::size_t>(dims[1] - 1 - y) * dims[0] * components;
    std::uint8_t* out = image.pixel(0, y);
    for (int x = 0; x < dims[0]; ++x) {
      out[3 * x + 0] = row[components * x + 0];
      out[3 * x + 1] = row[components * x + 1];
      out[3 * x + 2] = row[components * x + 2];
    }
  }
  return image;
}

std::string labelFormat(double lo, double hi) {
  const double span = std::abs(hi - lo);
  int decimals = 2;
  if (span > 0.0) decimals = std::clamp(static_cast<int>(std::ceil(-std::log10(span))) + 1, 0, 6);
  char format[16];
  std::snprintf(format, sizeof format, "%%.%df", decimals);
  return format;
}

void ErrorCollector::Execute(vtkObject* /*caller*/, unsigned long event, void* data) {
  if (event != vtkCommand::ErrorEvent && event != vtkCommand::WarningEvent) return;
  std::string message = data != nullptr ? static_cast<const char*>(data) : "unknown VTK error";
  while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) message.pop_back();
  messages_.push_back(message);
}

void ErrorCollector::watch(vtkObject* object) {
  object->AddObserver(vtkCommand::ErrorEvent, this);
  object->AddObserver(vtkCommand::WarningEvent, this);
}

std::string ErrorCollector::text() const {
  std::string joined;
  for (const auto& message : messages_) {
    if (!joined.empty()) joined += "; ";
    joined += message;
  }
  return joined;
}

}  // namespace autograv::viz::detail
