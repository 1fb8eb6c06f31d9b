#include "autograv/viz/plots.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <sstream>

#include <vtkAxis.h>
#include <vtkBrush.h>
#include <vtkChartLegend.h>
#include <vtkChartMatrix.h>
#include <vtkChartXY.h>
#include <vtkColorSeries.h>
#include <vtkContextScene.h>
#include <vtkContextView.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkPlotBar.h>
#include <vtkPlotPoints.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkStringArray.h>
#include <vtkTable.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkVector.h>

#include "autograv/error.h"
#include "viz/vtk_support.h"

namespace autograv::viz {

namespace {

constexpr double kGramsPerKg = 1000.0;
constexpr double kMmPerM = 1000.0;

// Line colours that read on white and on dark backgrounds.
constexpr detail::Rgb kBlue = {0.12, 0.47, 0.71};
constexpr detail::Rgb kOrange = {0.90, 0.45, 0.05};
constexpr detail::Rgb kGreen = {0.20, 0.63, 0.17};
constexpr detail::Rgb kRed = {0.84, 0.15, 0.16};

bool visited(const VertexEstimate& vertex) noexcept {
  return vertex.outcome != VertexOutcome::kPending;
}

// The smallest of 1, 2, 2.5, 5 (times a power of ten) at or above `value`.
double roundUp(double value) {
  if (!(value > 0.0)) return 1e-3;
  const double magnitude = std::pow(10.0, std::floor(std::log10(value)));
  for (const double step : {1.0, 2.0, 2.5, 5.0, 10.0}) {
    if (step * magnitude >= value * (1.0 - 1e-12)) return step * magnitude;
  }
  return 10.0 * magnitude;
}

void checkOptions(const PlotOptions& options) {
  detail::checkImageSize(options.width_px, options.height_px, "plot");
}

vtkSmartPointer<vtkDoubleArray> column(const char* name) {
  auto array = vtkSmartPointer<vtkDoubleArray>::New();
  array->SetName(name);
  return array;
}

void styleAxis(vtkAxis* axis, const std::string& title, const detail::Palette& palette,
               int font_px) {
  axis->SetTitle(title);
  detail::styleText(axis->GetTitleProperties(), palette.text, font_px);
  detail::styleText(axis->GetLabelProperties(), palette.text, font_px - font_px / 6);
  axis->GetPen()->SetColorF(palette.text[0], palette.text[1], palette.text[2]);
  axis->GetGridPen()->SetColorF(palette.grid_lines[0], palette.grid_lines[1],
                                palette.grid_lines[2]);
}

void styleChart(vtkChartXY* chart, const std::string& title, const std::string& x_title,
                const std::string& y_title, const detail::Palette& palette, int font_px) {
  chart->SetTitle(title);
  detail::styleText(chart->GetTitleProperties(), palette.text, font_px + font_px / 6, true);
  styleAxis(chart->GetAxis(vtkAxis::BOTTOM), x_title, palette, font_px);
  styleAxis(chart->GetAxis(vtkAxis::LEFT), y_title, palette, font_px);
  vtkChartLegend* legend = chart->GetLegend();
  detail::styleText(legend->GetLabelProperties(), palette.text, font_px - font_px / 6);
  legend->SetLabelSize(font_px - font_px / 6);
  legend->GetBrush()->SetColorF(palette.background[0], palette.background[1], palette.background[2],
                                0.85);
  legend->GetPen()->SetColorF(palette.grid_lines[0], palette.grid_lines[1], palette.grid_lines[2]);
}

void setColor(vtkPlot* plot, const detail::Rgb& rgb) {
  plot->SetColor(static_cast<unsigned char>(255 * rgb[0]), static_cast<unsigned char>(255 * rgb[1]),
                 static_cast<unsigned char>(255 * rgb[2]), 255);
}

// Integer ticks 1..n (every k-th when there are many) on a fixed range.
void iterationAxis(vtkAxis* axis, int first, int last) {
  axis->SetBehavior(vtkAxis::FIXED);
  axis->SetRange(first - 0.5, last + 0.5);
  const int count = last - first + 1;
  const int every = count <= 15 ? 1 : (count <= 30 ? 2 : (count <= 75 ? 5 : 10));
  vtkNew<vtkDoubleArray> ticks;
  for (int j = first; j <= last; ++j) {
    if (j % every == 0 || count <= 15) ticks->InsertNextValue(j);
  }
  axis->SetCustomTickPositions(ticks);
  axis->SetNotation(vtkAxis::FIXED_NOTATION);
  axis->SetPrecision(0);
}

void fixedRange(vtkAxis* axis, double lo, double hi) {
  axis->SetBehavior(vtkAxis::FIXED);
  axis->SetRange(lo, hi);
}

// A chart matrix of `columns` x `rows` in an offscreen context view, rendered into an image.
class ChartPicture {
 public:
  ChartPicture(const PlotOptions& options, int columns, int rows)
      : palette_(detail::paletteFor(options.background)),
        width_px_(options.width_px),
        height_px_(options.height_px) {
    detail::prepareOffscreen(view_->GetRenderWindow(), display_, options.width_px,
                             options.height_px);
    view_->GetRenderer()->SetBackground(palette_.background[0], palette_.background[1],
                                        palette_.background[2]);
    matrix_->SetSize(vtkVector2i(columns, rows));
    // Room for the tick labels, the axis titles and the chart title, in units of the text size.
    const float font_px = static_cast<float>(detail::baseFontPx(options.height_px));
    left_px_ = static_cast<int>(4.5f * font_px);
    bottom_px_ = static_cast<int>(3.4f * font_px);
    right_px_ = static_cast<int>(1.5f * font_px);
    top_px_ = static_cast<int>(2.8f * font_px);
    matrix_->SetBorders(left_px_, bottom_px_, right_px_, top_px_);
    matrix_->SetGutter(vtkVector2f(5.5f * font_px, 5.5f * font_px));
    view_->GetScene()->AddItem(matrix_);
  }
  /// A title over the whole picture, left-aligned above the charts. A chart's own title is
  /// centred on its chart and ran into the tick labels beside it when longer than the chart.
  void setTitle(const std::string& title, int font_px) {
    if (title.empty()) return;
    top_px_ += static_cast<int>(1.2f * static_cast<float>(font_px));
    matrix_->SetBorders(left_px_, bottom_px_, right_px_, top_px_);
    title_->SetInput(title.c_str());
    detail::styleText(title_->GetTextProperty(), palette_.text, font_px + font_px / 6, true);
    title_->GetTextProperty()->SetJustificationToLeft();
    title_->GetTextProperty()->SetVerticalJustificationToTop();
    title_->SetDisplayPosition(font_px, height_px_ - font_px / 2);
    view_->GetRenderer()->AddActor2D(title_);
  }
  /// Widens the right margin by `width_px`, for a legend beside the charts; returns the screen
  /// point (x of the column's left edge, y of the top of the charts). Unit: [px]
  vtkVector2f reserveRightColumn(int width_px) {
    right_px_ += width_px;
    matrix_->SetBorders(left_px_, bottom_px_, right_px_, top_px_);
    return vtkVector2f(static_cast<float>(width_px_ - right_px_ + right_px_ / 8),
                       static_cast<float>(height_px_ - top_px_));
  }
  /// Chart (column, row), row 0 at the bottom.
  vtkChartXY* chart(int column, int row) {
    return vtkChartXY::SafeDownCast(matrix_->GetChart(vtkVector2i(column, row)));
  }
  const detail::Palette& palette() const { return palette_; }
  RgbImage render() { return detail::captureWindow(view_->GetRenderWindow()); }

 private:
  detail::Palette palette_;
  int width_px_ = 0;
  int height_px_ = 0;
  int left_px_ = 0;
  int bottom_px_ = 0;
  int right_px_ = 0;
  int top_px_ = 0;
  detail::XDisplay display_;  // declared before the view: destroyed after it
  vtkNew<vtkContextView> view_;
  vtkNew<vtkChartMatrix> matrix_;
  vtkNew<vtkTextActor> title_;
};

}  // namespace

int Histogram::total() const noexcept { return std::accumulate(counts.begin(), counts.end(), 0); }

IterationHistogram iterationHistogram(const GravityMap& map) {
  int lo = 0;
  int hi = -1;
  for (const VertexEstimate& vertex : map.vertices()) {
    if (!visited(vertex)) continue;
    lo = hi < lo ? vertex.iterations : std::min(lo, vertex.iterations);
    hi = std::max(hi, vertex.iterations);
  }
  if (hi < lo) throw Error("iteration histogram: no vertex of the map was visited");
  IterationHistogram histogram;
  for (Histogram* h : {&histogram.converged, &histogram.not_converged}) {
    h->first_lower = lo;
    h->width = 1.0;
    h->counts.assign(static_cast<std::size_t>(hi - lo + 1), 0);
  }
  for (const VertexEstimate& vertex : map.vertices()) {
    if (!visited(vertex)) continue;
    Histogram& h =
        vertex.outcome == VertexOutcome::kConverged ? histogram.converged : histogram.not_converged;
    ++h.counts[static_cast<std::size_t>(vertex.iterations - lo)];
  }
  return histogram;
}

Histogram relativeErrorHistogram(const GravityMap& map, const GroundTruth& ground_truth, int bins) {
  if (!ground_truth) throw Error("relative error histogram: no ground truth given");
  if (bins < 1) throw Error("relative error histogram: bins must be >= 1");
  std::vector<double> errors_percent;
  for (int i = 0; i < map.grid().vertexCount(); ++i) {
    const VertexEstimate& vertex = map.vertices()[static_cast<std::size_t>(i)];
    // A filled vertex was not measured (and may lie where the device has no truth).
    if (!visited(vertex) || vertex.provenance == VertexProvenance::kFilled) continue;
    const Eigen::Vector3d truth_n = ground_truth(map.grid().vertexPosition(i));
    if (!truth_n.allFinite() || truth_n.norm() <= 0.0) {
      throw Error("relative error histogram: the ground truth is zero or not finite at vertex " +
                  std::to_string(i));
    }
    errors_percent.push_back(100.0 * (vertex.gravity_n - truth_n).norm() / truth_n.norm());
  }
  if (errors_percent.empty()) throw Error("relative error histogram: no vertex was visited");
  Histogram histogram;
  const double top = roundUp(*std::max_element(errors_percent.begin(), errors_percent.end()));
  histogram.first_lower = 0.0;
  histogram.width = top / bins;
  histogram.counts.assign(static_cast<std::size_t>(bins), 0);
  for (const double error : errors_percent) {
    const int bin = std::min(bins - 1, static_cast<int>(error / histogram.width));
    ++histogram.counts[static_cast<std::size_t>(bin)];
  }
  return histogram;
}

RgbImage renderConvergencePlot(const GravityMap& map, int vertex_index,
                               const PlotOptions& options) {
  checkOptions(options);
  if (vertex_index < 0 || vertex_index >= map.grid().vertexCount()) {
    throw Error("convergence plot: vertex " + std::to_string(vertex_index) +
                " does not exist; the map has vertices 0 to " +
                std::to_string(map.grid().vertexCount() - 1));
  }
  const VertexEstimate& vertex = map.vertices()[static_cast<std::size_t>(vertex_index)];
  if (vertex.history.empty()) {
    throw Error("convergence plot: vertex " + std::to_string(vertex_index) + " (" +
                toString(vertex.outcome) + ") has no iteration history to plot");
  }
  const Eigen::Vector3d position_m = map.grid().vertexPosition(vertex_index);
  double true_mass_g = std::numeric_limits<double>::quiet_NaN();
  if (options.ground_truth) {
    const Eigen::Vector3d truth_n = options.ground_truth(position_m);
    if (!truth_n.allFinite()) throw Error("convergence plot: the ground truth is not finite");
    true_mass_g = truth_n.norm() / kStandardGravity * kGramsPerKg;
  }
  requireDisplay();

  const int n = static_cast<int>(vertex.history.size());
  vtkNew<vtkTable> table;
  auto iteration = column("iteration");
  auto delta_mm = column("delta_mm");
  auto mass_g = column("mass_g");
  auto truth_g = column("true_mass_g");
  double delta_max = 0.0;
  double mass_lo = std::isfinite(true_mass_g) ? true_mass_g : 1e300;
  double mass_hi = std::isfinite(true_mass_g) ? true_mass_g : -1e300;
  for (int j = 0; j < n; ++j) {
    const IterationRecord& record = vertex.history[static_cast<std::size_t>(j)];
    iteration->InsertNextValue(j + 1);
    delta_mm->InsertNextValue(record.position_error_m * kMmPerM);
    mass_g->InsertNextValue(record.mass_estimate_kg * kGramsPerKg);
    truth_g->InsertNextValue(true_mass_g);
    delta_max = std::max(delta_max, record.position_error_m * kMmPerM);
    mass_lo = std::min(mass_lo, record.mass_estimate_kg * kGramsPerKg);
    mass_hi = std::max(mass_hi, record.mass_estimate_kg * kGramsPerKg);
  }
  table->AddColumn(iteration);
  table->AddColumn(delta_mm);
  table->AddColumn(mass_g);
  table->AddColumn(truth_g);

  ChartPicture picture(options, 1, 2);
  const detail::Palette& palette = picture.palette();
  const int font_px = detail::baseFontPx(options.height_px);
  std::string title = options.title;
  if (title.empty()) {
    char text[200];
    std::snprintf(text, sizeof text, "Vertex %d at (%.1f, %.1f, %.1f) mm: %s after %d iterations",
                  vertex_index, position_m.x() * kMmPerM, position_m.y() * kMmPerM,
                  position_m.z() * kMmPerM, toString(vertex.outcome), vertex.iterations);
    title = text;
  }

  // Top: the steady-state positioning error (the paper's Fig. 8).
  vtkChartXY* top = picture.chart(0, 1);
  styleChart(top, title, detail::pickText("iteration j", "iteration j"),
             detail::pickText("\u0394_j [mm]", "Delta_j [mm]"), palette, font_px);
  vtkPlot* delta = top->AddPlot(vtkChart::LINE);
  delta->SetInputData(table, "iteration", "delta_mm");
  delta->SetLabel(detail::pickText("\u0394_j", "Delta_j"));
  setColor(delta, kBlue);
  delta->SetWidth(2.5f);
  if (auto* points = vtkPlotPoints::SafeDownCast(delta)) {
    points->SetMarkerStyle(vtkPlotPoints::CIRCLE);
    points->SetMarkerSize(std::max(6.0f, font_px * 0.45f));
  }
  iterationAxis(top->GetAxis(vtkAxis::BOTTOM), 1, n);
  fixedRange(top->GetAxis(vtkAxis::LEFT), 0.0, delta_max > 0.0 ? 1.1 * delta_max : 1.0);

  // Bottom: the estimated mass (the paper's Fig. 9), with the true mass dashed.
  vtkChartXY* bottom = picture.chart(0, 0);
  styleChart(bottom, "", "iteration j", "estimated mass M_j [g]", palette, font_px);
  vtkPlot* mass = bottom->AddPlot(vtkChart::LINE);
  mass->SetInputData(table, "iteration", "mass_g");
  mass->SetLabel("estimate M_j");
  setColor(mass, kOrange);
  mass->SetWidth(2.5f);
  if (auto* points = vtkPlotPoints::SafeDownCast(mass)) {
    points->SetMarkerStyle(vtkPlotPoints::CIRCLE);
    points->SetMarkerSize(std::max(6.0f, font_px * 0.45f));
  }
  if (std::isfinite(true_mass_g)) {
    vtkPlot* truth = bottom->AddPlot(vtkChart::LINE);
    truth->SetInputData(table, "iteration", "true_mass_g");
    char label[64];
    std::snprintf(label, sizeof label, "true mass %.1f g", true_mass_g);
    truth->SetLabel(label);
    setColor(truth, palette.text);
    truth->SetWidth(2.0f);
    truth->GetPen()->SetLineType(vtkPen::DASH_LINE);
    if (auto* points = vtkPlotPoints::SafeDownCast(truth))
      points->SetMarkerStyle(vtkPlotPoints::NONE);
  }
  bottom->SetShowLegend(true);
  bottom->GetLegend()->SetHorizontalAlignment(vtkChartLegend::RIGHT);
  bottom->GetLegend()->SetVerticalAlignment(vtkChartLegend::BOTTOM);
  iterationAxis(bottom->GetAxis(vtkAxis::BOTTOM), 1, n);
  const double pad = std::max(1.0, 0.08 * (mass_hi - mass_lo));
  fixedRange(bottom->GetAxis(vtkAxis::LEFT), std::max(0.0, mass_lo - pad), mass_hi + pad);
  return picture.render();
}

RgbImage renderSummaryPlot(const GravityMap& map, const PlotOptions& options) {
  checkOptions(options);
  const IterationHistogram iterations = iterationHistogram(map);
  Histogram errors;
  if (options.ground_truth) errors = relativeErrorHistogram(map, options.ground_truth);
  requireDisplay();

  const bool with_errors = static_cast<bool>(options.ground_truth);
  ChartPicture picture(options, with_errors ? 2 : 1, 1);
  const detail::Palette& palette = picture.palette();
  const int font_px = detail::baseFontPx(options.height_px);

  // Iterations per vertex, converged and not converged stacked.
  vtkNew<vtkTable> table;
  auto count = column("iterations");
  auto converged = column("converged");
  auto failed = column("not converged");
  int tallest = 0;
  for (std::size_t k = 0; k < iterations.converged.counts.size(); ++k) {
    count->InsertNextValue(iterations.converged.first_lower + static_cast<double>(k));
    converged->InsertNextValue(iterations.converged.counts[k]);
    failed->InsertNextValue(iterations.not_converged.counts[k]);
    tallest =
        std::max(tallest, iterations.converged.counts[k] + iterations.not_converged.counts[k]);
  }
  table->AddColumn(count);
  table->AddColumn(converged);
  table->AddColumn(failed);
  const int visited_count = iterations.converged.total() + iterations.not_converged.total();
  std::string title = options.title;
  if (title.empty()) {
    std::ostringstream text;
    const std::string& model = map.metadata().device_model;
    text << (model.empty() ? std::string("map") : model) << ": " << iterations.converged.total()
         << "/" << map.grid().vertexCount() << " vertices converged";
    if (visited_count < map.grid().vertexCount()) {
      text << ", " << map.grid().vertexCount() - visited_count << " not visited";
    }
    title = text.str();
  }
  vtkChartXY* left = picture.chart(0, 0);
  styleChart(left, title, "inner-loop iterations at the vertex", "vertices", palette, font_px);
  auto* bars = vtkPlotBar::SafeDownCast(left->AddPlot(vtkChart::BAR));
  bars->SetInputData(table, "iterations", "converged");
  const bool any_failed = iterations.not_converged.total() > 0;
  if (any_failed) bars->SetInputArray(2, "not converged");
  vtkNew<vtkColorSeries> colors;
  colors->SetNumberOfColors(2);
  colors->SetColor(0, vtkColor3ub(static_cast<unsigned char>(255 * kBlue[0]),
                                  static_cast<unsigned char>(255 * kBlue[1]),
                                  static_cast<unsigned char>(255 * kBlue[2])));
  colors->SetColor(1, vtkColor3ub(static_cast<unsigned char>(255 * kRed[0]),
                                  static_cast<unsigned char>(255 * kRed[1]),
                                  static_cast<unsigned char>(255 * kRed[2])));
  bars->SetColorSeries(colors);
  vtkNew<vtkStringArray> labels;
  labels->InsertNextValue("converged");
  if (any_failed) labels->InsertNextValue("not converged");
  bars->SetLabels(labels);
  bars->SetWidth(0.8f);
  left->SetShowLegend(true);
  left->GetLegend()->SetHorizontalAlignment(vtkChartLegend::RIGHT);
  left->GetLegend()->SetVerticalAlignment(vtkChartLegend::TOP);
  iterationAxis(left->GetAxis(vtkAxis::BOTTOM), static_cast<int>(iterations.converged.first_lower),
                static_cast<int>(iterations.converged.first_lower) +
                    static_cast<int>(iterations.converged.counts.size()) - 1);
  fixedRange(left->GetAxis(vtkAxis::LEFT), 0.0, std::max(1.0, 1.15 * tallest));

  if (with_errors) {
    vtkNew<vtkTable> error_table;
    auto centre = column("error_percent");
    auto vertices = column("vertices");
    int highest = 0;
    for (std::size_t k = 0; k < errors.counts.size(); ++k) {
      centre->InsertNextValue(errors.first_lower + (k + 0.5) * errors.width);
      vertices->InsertNextValue(errors.counts[k]);
      highest = std::max(highest, errors.counts[k]);
    }
    error_table->AddColumn(centre);
    error_table->AddColumn(vertices);
    vtkChartXY* right = picture.chart(1, 0);
    styleChart(right, "final error against ground truth",
               detail::pickText("100 |\u011c \u2212 G_true| / |G_true| [%]",
                                "100 |G_hat - G_true| / |G_true| [%]"),
               "vertices", palette, font_px);
    auto* error_bars = vtkPlotBar::SafeDownCast(right->AddPlot(vtkChart::BAR));
    error_bars->SetInputData(error_table, "error_percent", "vertices");
    setColor(error_bars, kGreen);
    error_bars->SetWidth(static_cast<float>(0.9 * errors.width));
    fixedRange(right->GetAxis(vtkAxis::BOTTOM), 0.0,
               errors.first_lower + errors.width * static_cast<double>(errors.counts.size()));
    fixedRange(right->GetAxis(vtkAxis::LEFT), 0.0, std::max(1.0, 1.15 * highest));
  }
  return picture.render();
}

RgbImage renderSweepPlot(const std::vector<std::string>& x_labels, const std::string& x_title,
                         const std::vector<SweepPanel>& panels, const PlotOptions& options) {
  checkOptions(options);
  if (panels.empty() || x_labels.empty()) throw Error("sweep plot: nothing to plot");
  for (const SweepPanel& panel : panels) {
    for (const SweepSeries& series : panel.series) {
      if (series.values.size() != x_labels.size()) {
        throw Error("sweep plot: series '" + series.name + "' has " +
                    std::to_string(series.values.size()) + " values for " +
                    std::to_string(x_labels.size()) + " labels");
      }
    }
  }
  requireDisplay();

  const int columns = panels.size() > 1 ? 2 : 1;
  const int rows = static_cast<int>((panels.size() + 1) / 2);
  ChartPicture picture(options, columns, rows);
  const detail::Palette& palette = picture.palette();
  const int font_px = detail::baseFontPx(options.height_px);
  // Okabe and Ito's eight colours, told apart also by readers with a colour vision deficiency.
  constexpr detail::Rgb kColours[] = {kBlue,
                                      kOrange,
                                      kGreen,
                                      kRed,
                                      {0.34, 0.71, 0.91},
                                      {0.80, 0.47, 0.65},
                                      {0.60, 0.60, 0.0},
                                      {0.35, 0.35, 0.35}};
  constexpr int kColourCount = static_cast<int>(sizeof kColours / sizeof kColours[0]);
  // The legend gets a column of its own right of the panels: inside a panel it covered the
  // lines and the title as soon as there were more than a few series. Its size is estimated
  // from the text: about 0.6 em per character, a marker of 3 em, 1.3 em per line.
  const int legend_font_px = font_px - font_px / 6;
  std::size_t longest_name = 0;
  for (const SweepSeries& series : panels.front().series) {
    longest_name = std::max(longest_name, series.name.size());
  }
  const int legend_width_px =
      static_cast<int>((0.62 * static_cast<double>(longest_name) + 4.0) * legend_font_px);
  picture.setTitle(options.title, font_px);
  const vtkVector2f legend_top_left = picture.reserveRightColumn(legend_width_px);
  const float legend_height_px =
      1.3f * static_cast<float>(panels.front().series.size() * legend_font_px) + 10.0f;
  vtkNew<vtkDoubleArray> tick_positions;
  vtkNew<vtkStringArray> tick_labels;
  for (std::size_t k = 0; k < x_labels.size(); ++k) {
    tick_positions->InsertNextValue(static_cast<double>(k));
    tick_labels->InsertNextValue(x_labels[k]);
  }
  for (std::size_t p = 0; p < panels.size(); ++p) {
    const SweepPanel& panel = panels[p];
    vtkNew<vtkTable> table;
    auto x = column("x");
    for (std::size_t k = 0; k < x_labels.size(); ++k) x->InsertNextValue(static_cast<double>(k));
    table->AddColumn(x);
    double highest = 0.0;
    for (const SweepSeries& series : panel.series) {
      auto values = column(series.name.c_str());
      for (const double value : series.values) {
        values->InsertNextValue(value);
        if (std::isfinite(value)) highest = std::max(highest, value);
      }
      table->AddColumn(values);
    }
    // Row 0 is the bottom one: the first panels go on top.
    vtkChartXY* chart = picture.chart(static_cast<int>(p % 2), rows - 1 - static_cast<int>(p / 2));
    styleChart(chart, "", x_title, panel.y_title, palette, font_px);
    for (std::size_t s = 0; s < panel.series.size(); ++s) {
      vtkPlot* line = chart->AddPlot(vtkChart::LINE);
      line->SetInputData(table, "x", panel.series[s].name);
      line->SetLabel(panel.series[s].name);
      const int colour = panel.series[s].colour >= 0 ? panel.series[s].colour : static_cast<int>(s);
      setColor(line, kColours[colour % kColourCount]);
      line->SetWidth(2.5f);
      // Past the eighth colour, lines are told apart by their dashes too.
      if (panel.series[s].dashed || colour / kColourCount % 2 == 1) {
        line->GetPen()->SetLineType(vtkPen::DASH_LINE);
      }
      if (auto* points = vtkPlotPoints::SafeDownCast(line)) {
        points->SetMarkerStyle(vtkPlotPoints::CIRCLE);
        points->SetMarkerSize(std::max(6.0f, font_px * 0.45f));
      }
    }
    vtkAxis* bottom = chart->GetAxis(vtkAxis::BOTTOM);
    fixedRange(bottom, -0.3, static_cast<double>(x_labels.size()) - 0.7);
    bottom->SetCustomTickPositions(tick_positions, tick_labels);
    // Five or six round ticks above the highest value, not the next power-of-ten-ish number.
    const double tick = roundUp(highest / 5.0);
    fixedRange(chart->GetAxis(vtkAxis::LEFT), 0.0,
               highest > 0.0 ? tick * std::ceil(1.05 * highest / tick) : 1.0);
    chart->SetShowLegend(p == 0);
    chart->GetLegend()->SetHorizontalAlignment(vtkChartLegend::CUSTOM);
    chart->GetLegend()->SetVerticalAlignment(vtkChartLegend::CUSTOM);
    // The legend's point is its bottom-left corner.
    chart->GetLegend()->SetPoint(
        vtkVector2f(legend_top_left.GetX(), legend_top_left.GetY() - legend_height_px));
  }
  return picture.render();
}

}  // namespace autograv::viz
