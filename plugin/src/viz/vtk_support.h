#pragma once

// Private helpers shared by the VTK-based parts of autograv::viz.

#include <array>
#include <string>
#include <vector>

#include <vtkCommand.h>
#include <vtkRenderWindow.h>
#include <vtkSmartPointer.h>

#include "autograv/viz/common.h"
#include "autograv/viz/image.h"

class vtkLookupTable;
class vtkObject;
class vtkTextProperty;

namespace autograv::viz::detail {

using Rgb = std::array<double, 3>;

/// Colours that go with a background.
struct Palette {
  Rgb background;
  Rgb text;
  Rgb lattice;
  Rgb workspace;
  Rgb failed;
  Rgb not_visited;
  Rgb device;
  Rgb grid_lines;  ///< Chart grid.
  Rgb filled;      ///< Vertices out of reach whose values were solved from the measurements.
  Rgb off_vertex;  ///< Points measured inside the stops for a vertex beyond them.
};

Palette paletteFor(Background background) noexcept;

/// Throws autograv::Error unless 16 <= width, height <= 8192.
void checkImageSize(int width_px, int height_px, const char* what);

/// Base text height for a picture `height_px` tall: 20 px at 960 px, never below 11 px.
int baseFontPx(int height_px) noexcept;

/// True when DejaVu Sans is installed (fonts-dejavu-core). VTK's built-in font in Debian lacks
/// glyphs such as '[' and Greek letters, so text uses DejaVu when it can.
bool haveUnicodeFont();

/// `unicode` when haveUnicodeFont(), else the plain-ASCII spelling.
const char* pickText(const char* unicode, const char* ascii);

/// Plain (no shadow, not bold unless asked) text of `size_px` in `color`.
void styleText(vtkTextProperty* text, const Rgb& color, int size_px, bool bold = false);

/// A 256-entry lookup table of `color_map` over [lo, hi].
vtkSmartPointer<vtkLookupTable> makeLookupTable(ColorMap color_map, double lo, double hi);

/// A sequential white-to-dark-red table for residuals over [0, hi].
vtkSmartPointer<vtkLookupTable> makeResidualLookupTable(double hi);

/// Opens the X display named by DISPLAY, retrying briefly; nullptr (and `reason`) on failure.
void* openXDisplay(std::string* reason);
/// Closes a display from openXDisplay; nullptr is ignored.
void closeXDisplay(void* display) noexcept;

/// An X display connection owned by autograv, handed to VTK's windows: VTK 9.1 aborts the process
/// when its own XOpenDisplay fails, whereas this throws autograv::Error with the reason.
class XDisplay {
 public:
  XDisplay();
  ~XDisplay() { closeXDisplay(display_); }
  XDisplay(const XDisplay&) = delete;
  XDisplay& operator=(const XDisplay&) = delete;
  void* get() const noexcept { return display_; }

 private:
  void* display_ = nullptr;
};

/// An offscreen render window with no multisampling (renders must be reproducible), on a display
/// connection that outlives it.
class OffscreenWindow {
 public:
  OffscreenWindow(int width_px, int height_px);
  vtkRenderWindow* get() const noexcept { return window_.Get(); }

 private:
  XDisplay display_;  // declared first: destroyed after the window
  vtkSmartPointer<vtkRenderWindow> window_;
};

/// Prepares a render window that VTK made (e.g. a context view's) like OffscreenWindow does.
void prepareOffscreen(vtkRenderWindow* window, const XDisplay& display, int width_px,
                      int height_px);

/// Renders `window` and reads its back buffer into an RgbImage (top row first).
RgbImage captureWindow(vtkRenderWindow* window);

/// printf-style label format with enough decimals to tell the ends of [lo, hi] apart.
std::string labelFormat(double lo, double hi);

/// Collects VTK error events of the objects it observes, so they can become autograv::Error
/// messages instead of lines on stderr.
class ErrorCollector : public vtkCommand {
 public:
  static ErrorCollector* New() { return new ErrorCollector; }
  void Execute(vtkObject* caller, unsigned long event, void* data) override;
  /// Observes the ErrorEvent and WarningEvent of `object`.
  void watch(vtkObject* object);
  bool hasErrors() const noexcept { return !messages_.empty(); }
  std::string text() const;

 private:
  std::vector<std::string> messages_;
};

}  // namespace autograv::viz::detail
