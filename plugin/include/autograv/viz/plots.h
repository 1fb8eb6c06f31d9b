#pragma once

#include <optional>
#include <string>
#include <vector>

#include "autograv/map/gravity_map.h"
#include "autograv/viz/common.h"
#include "autograv/viz/image.h"

namespace autograv::viz {

/// Size and style of a plot picture.
struct PlotOptions {
  /// Unit: [px]
  int width_px = 1280;
  /// Height of the picture. Unit: [px]
  int height_px = 960;
  /// White (print) or dark (screen) background.
  Background background = Background::kWhite;
  /// When set, the convergence plot draws the true mass |G_true(X_i)| / g as a dashed line, and
  /// the summary adds the histogram of the final relative error.
  GroundTruth ground_truth;
  /// Overlay title; empty makes one from the map.
  std::string title;
};

/// Counts in equal bins: bin k covers [first_lower + k * width, first_lower + (k + 1) * width).
struct Histogram {
  /// Lower edge of the first bin.
  double first_lower = 0.0;
  /// Width of every bin.
  double width = 1.0;
  /// Count of bin k.
  std::vector<int> counts;

  /// Sum of the counts. Real-time safe.
  int total() const noexcept;
};

/// Iterations per visited vertex, one bin per iteration count, split by outcome. Both histograms
/// share their bins. Not real-time safe.
struct IterationHistogram {
  /// Vertices that converged.
  Histogram converged;
  /// Vertices that did not.
  Histogram not_converged;
};

/// The inner-loop iterations of every visited (not kPending) vertex. Throws autograv::Error when
/// no vertex was visited. Not real-time safe.
IterationHistogram iterationHistogram(const GravityMap& map);

/// The final relative error 100 |G_hat - G_true| / |G_true| of every visited vertex, in `bins`
/// equal bins from 0 to a round number at or above the largest error. Unit: [%].
/// Throws autograv::Error when no vertex was visited or bins < 1. Not real-time safe.
Histogram relativeErrorHistogram(const GravityMap& map, const GroundTruth& ground_truth,
                                 int bins = 10);

/// The convergence at one vertex like the paper's Figs. 8 and 9, stacked: the steady-state
/// positioning error Delta_j [mm] and the estimated mass M_hat_j [g] over iterations j, with the
/// true mass dashed when ground truth is given. Needs an X display. Throws autograv::Error for
/// an index out of range, a vertex without iteration history, a bad size or no display.
/// Not real-time safe.
RgbImage renderConvergencePlot(const GravityMap& map, int vertex_index,
                               const PlotOptions& options = {});

/// Histogram of iterations per vertex and, with ground truth, of the final relative error, side
/// by side. Needs an X display. Throws autograv::Error like the histograms, on a bad size or
/// without a display. Not real-time safe.
RgbImage renderSummaryPlot(const GravityMap& map, const PlotOptions& options = {});

/// One line of a sweep plot: a named series of values, one per x label (NaN leaves a gap).
struct SweepSeries {
  /// Legend text.
  std::string name;
  /// One value per x label.
  std::vector<double> values;
  /// Index into the plot's eight colours; -1 takes the series' position in its panel. Series
  /// that belong together (one device, several methods) share a colour and differ in dashes.
  int colour = -1;
  /// Draws the line dashed.
  bool dashed = false;
};

/// One panel of a sweep plot.
struct SweepPanel {
  /// Title of the y axis.
  std::string y_title;
  /// The lines of the panel.
  std::vector<SweepSeries> series;
};

/// Panels side by side (two per row), each with one line per series over the same categorical
/// x axis (e.g. the friction levels none, low, typical, high). Needs an X display. Throws
/// autograv::Error when there is no panel, a series' length differs from the labels', the size
/// is bad or there is no display. Not real-time safe.
RgbImage renderSweepPlot(const std::vector<std::string>& x_labels, const std::string& x_title,
                         const std::vector<SweepPanel>& panels, const PlotOptions& options = {});

}  // namespace autograv::viz
