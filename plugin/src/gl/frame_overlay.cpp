// The overlay of one frame: the readout panel top-left, the legend under it, the status line at
// the bottom and the axis letters next to the triad, as quads of the bitmap font.
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "gl/font.h"
#include "gl/frame_lists.h"

namespace autograv::gl::detail {

namespace {

// A line of the legend's key of the kinds of value, in the colour of their marks.
struct KeyLine {
  std::string text;
  Rgba color;
};

// Where the text goes: one scale of the font for the whole overlay, chosen by the height.
struct TextLayout {
  explicit TextLayout(int height_px)
      : scale(height_px >= 700 ? 3 : (height_px >= 360 ? 2 : 1)),
        line_px((kCellHeight + 3) * scale),
        margin(4.0 * scale) {}

  const int scale;
  const double line_px;
  const double margin;
};

std::string formatNewtons(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.2f N", value);
  return text;
}

void addRect(FrameLists& lists, double x, double y, double w, double h, Rgba color,
             float kind = -1.0f) {
  lists.overlay.push_back(
      {{static_cast<float>(x), static_cast<float>(y), static_cast<float>(w), static_cast<float>(h)},
       {color.r, color.g, color.b, color.a},
       kind});
}

void addText(FrameLists& lists, double x, double y, int scale, const std::string& text,
             Rgba color) {
  const double advance = kCellWidth * scale;
  double pen = x;
  for (const char c : text) {
    if (c != ' ') {
      addRect(lists, pen, y, kCellWidth * scale, kCellHeight * scale, color,
              static_cast<float>(glyphIndex(c)));
    }
    pen += advance;
  }
}

// The key of the kinds of value; only the kinds present.
std::vector<KeyLine> legendKey(const Scene& scene, const ValueCounts& counts) {
  std::vector<KeyLine> key;
  if (counts.off_vertex > 0 || counts.solved > 0) {
    key.push_back({"MEASURED AT THE VERTEX " + std::to_string(counts.at_vertex), kTextColor});
  }
  if (counts.off_vertex > 0 && scene.show_measurements) {
    key.push_back(
        {"MEASURED INSIDE THE STOPS " + std::to_string(counts.off_vertex), kOffVertexColor});
  }
  if (counts.solved > 0) {
    key.push_back(
        {"SOLVED FROM THE MEASUREMENTS " + std::to_string(counts.solved), kSolvedVertexColor});
  }
  if (counts.workspace_stops > 0 && scene.show_workspace) {
    key.push_back({"EXPLORED WORKSPACE " + std::to_string(counts.workspace_stops) + " STOPS",
                   kWorkspaceStopColor});
  }
  return key;
}

// The readout, then the |G| colour bar between its two ends and the key under it, on one panel
// as wide as the longest line.
void addReadoutAndLegend(const Scene& scene, const FrameMeasures& frame, const TextLayout& text,
                         FrameLists& lists) {
  const int scale = text.scale;
  std::size_t longest = 0;
  for (const std::string& line : scene.readout) longest = std::max(longest, line.size());
  const bool legend = scene.show_legend && frame.map != nullptr && scene.show_arrows;
  const std::string legend_low = "|G| " + formatNewtons(frame.min_magnitude_n);
  const std::string legend_high = formatNewtons(frame.max_magnitude_n);
  if (legend) longest = std::max<std::size_t>(longest, legend_low.size() + legend_high.size() + 12);
  std::vector<KeyLine> key;
  if (legend) {
    key = legendKey(scene, frame.counts);
    for (const KeyLine& line : key) longest = std::max(longest, line.text.size());
  }
  if (!scene.readout.empty() || legend) {
    double panel_height =
        text.line_px * static_cast<double>(scene.readout.size()) + 2 * text.margin;
    if (legend) panel_height += text.line_px * (2.0 + static_cast<double>(key.size()));
    addRect(lists, 0, 0, static_cast<double>(longest) * kCellWidth * scale + 2 * text.margin,
            panel_height, kPanelColor);
  }
  double y = text.margin;
  for (const std::string& line : scene.readout) {
    addText(lists, text.margin, y, scale, line, kTextColor);
    y += text.line_px;
  }
  if (!legend) return;
  y += 0.5 * text.line_px;
  const double text_w = static_cast<double>(legend_low.size()) * kCellWidth * scale;
  const double bar_w = 10.0 * kCellWidth * scale;
  addText(lists, text.margin, y, scale, legend_low, kTextColor);
  addRect(lists, text.margin + text_w + kCellWidth * scale, y, bar_w, kGlyphHeight * scale,
          {1, 1, 1, 1}, -2.0f);
  addText(lists, text.margin + text_w + bar_w + 2.0 * kCellWidth * scale, y, scale, legend_high,
          kTextColor);
  for (const KeyLine& line : key) {
    y += text.line_px;
    addText(lists, text.margin, y, scale, line.text, line.color);
  }
}

void addStatusLine(const Scene& scene, const TextLayout& text, int width_px, int height_px,
                   FrameLists& lists) {
  if (scene.status_line.empty()) return;
  const double bar_h = text.line_px + 2 * text.margin;
  addRect(lists, 0, height_px - bar_h, width_px, bar_h, kPanelColor);
  addText(lists, text.margin, height_px - bar_h + text.margin + 0.15 * text.line_px, text.scale,
          scene.status_line, kTextColor);
}

// Axis letters next to the triad, projected to the screen.
void addAxisLetters(const FrameMeasures& frame, const Eigen::Matrix4d& view_projection,
                    const TextLayout& text, int width_px, int height_px, FrameLists& lists) {
  const int scale = text.scale;
  const Eigen::Vector3d lo = frame.lattice->minCorner_m();
  const char* names[] = {"X", "Y", "Z"};
  const Rgba colors[] = {{1.0f, 0.45f, 0.45f, 1}, {0.45f, 1.0f, 0.45f, 1}, {0.55f, 0.65f, 1.0f, 1}};
  for (int axis = 0; axis < 3; ++axis) {
    const Eigen::Vector3d tip = lo + 0.75 * frame.cell_m * Eigen::Vector3d::Unit(axis);
    const Eigen::Vector4d clip = view_projection * tip.homogeneous();
    if (clip.w() <= 0.0) continue;
    const double px = (clip.x() / clip.w() * 0.5 + 0.5) * width_px;
    const double py = (0.5 - clip.y() / clip.w() * 0.5) * height_px;
    addText(lists, px - 0.5 * kCellWidth * scale, py - 0.5 * kCellHeight * scale, scale,
            names[axis], colors[axis]);
  }
}

}  // namespace

void addOverlay(const Scene& scene, const FrameMeasures& frame,
                const Eigen::Matrix4d& view_projection, int width_px, int height_px,
                FrameLists& lists) {
  const TextLayout text(height_px);
  addReadoutAndLegend(scene, frame, text, lists);
  addStatusLine(scene, text, width_px, height_px, lists);
  if (frame.lattice != nullptr && scene.show_grid) {
    addAxisLetters(frame, view_projection, text, width_px, height_px, lists);
  }
}

}  // namespace autograv::gl::detail
