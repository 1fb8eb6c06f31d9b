#include "autograv/map/map_summary.h"

#include <algorithm>
#include <cstdio>

#include "autograv/map/value_kind.h"

namespace autograv {

namespace {

std::string count(std::size_t n, const char* noun) {
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

IterationSpread spreadOf(const std::vector<int>& iterations) {
  IterationSpread spread;
  if (iterations.empty()) return spread;
  const auto [fewest, most] = std::minmax_element(iterations.begin(), iterations.end());
  spread.min = *fewest;
  spread.max = *most;
  spread.median = median(std::vector<double>(iterations.begin(), iterations.end()));
  return spread;
}

}  // namespace

bool isFailed(const VertexEstimate& vertex) noexcept {
  return vertex.outcome != VertexOutcome::kConverged && vertex.outcome != VertexOutcome::kPending &&
         vertex.outcome != VertexOutcome::kUnreachable && vertex.outcome != VertexOutcome::kLeftOut;
}

bool holdsNoValue(const VertexEstimate& vertex) noexcept {
  return vertex.provenance != VertexProvenance::kFilled &&
         (isFailed(vertex) || vertex.outcome == VertexOutcome::kUnreachable ||
          vertex.outcome == VertexOutcome::kLeftOut);
}

bool needsAnotherVisit(const VertexEstimate& vertex) noexcept {
  return isFailed(vertex) || vertex.outcome == VertexOutcome::kPending;
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

MapSummary summarizeVertices(const std::vector<VertexEstimate>& vertices) {
  MapSummary summary;
  summary.vertices = static_cast<int>(vertices.size());
  std::vector<int> iterations, converged_iterations;
  for (int i = 0; i < summary.vertices; ++i) {
    const VertexEstimate& vertex = vertices[static_cast<std::size_t>(i)];
    iterations.push_back(vertex.iterations);
    summary.seconds += vertex.seconds;
    summary.pending += vertex.outcome == VertexOutcome::kPending;
    summary.unreachable += vertex.outcome == VertexOutcome::kUnreachable;
    summary.left_out += vertex.outcome == VertexOutcome::kLeftOut;
    summary.filled += vertex.provenance == VertexProvenance::kFilled;
    const ValueKind kind = valueKind(vertex);
    summary.at_vertex += kind == ValueKind::kAtVertex;
    summary.off_vertex += kind == ValueKind::kOffVertex;
    summary.solved += kind == ValueKind::kSolved;
    if (isFailed(vertex)) summary.failed.push_back(i);
    if (needsAnotherVisit(vertex)) summary.to_visit_again.push_back(i);
    if (vertex.outcome != VertexOutcome::kConverged) continue;
    const double norm_n = vertex.gravity_n.norm();
    ConvergedVertexStats& converged = summary.converged_only;
    converged.gravity_min_n =
        summary.converged == 0 ? norm_n : std::min(converged.gravity_min_n, norm_n);
    converged.gravity_max_n = std::max(converged.gravity_max_n, norm_n);
    ++summary.converged;
    converged_iterations.push_back(vertex.iterations);
    converged.seconds += vertex.seconds;
  }
  summary.iterations = spreadOf(iterations);
  summary.converged_only.iterations = spreadOf(converged_iterations);
  return summary;
}

PriorText describePrior(const MapPrior& prior) {
  PriorText text;
  text.made_from = "map of unit " +
                   (prior.device_serial.empty() ? "(no serial)" : prior.device_serial) + " made " +
                   (prior.created_utc.empty() ? "at an unknown time" : prior.created_utc) +
                   (prior.source.empty() ? "" : " (" + prior.source + ")");
  char line[256];
  const Eigen::Vector3d offset_mn = prior.offset_n * 1e3;
  if (!prior.residuals_n.empty()) {
    // A field fitted through the differences: no gain or offset to show.
    std::snprintf(line, sizeof line, ", a field through the differences there");
  } else if (prior.correction_model == "shift") {
    std::snprintf(line, sizeof line, "; shift [%.1f, %.1f, %.1f] mN", offset_mn.x(), offset_mn.y(),
                  offset_mn.z());
  } else {
    std::snprintf(line, sizeof line, "; gain diag %.3f / %.3f / %.3f, offset [%.1f, %.1f, %.1f] mN",
                  prior.gain(0, 0), prior.gain(1, 1), prior.gain(2, 2), offset_mn.x(),
                  offset_mn.y(), offset_mn.z());
  }
  text.correction =
      prior.correction_model + " from " + count(prior.points_m.size(), "point") + line;
  if (prior.check_points > 0) {
    std::snprintf(line, sizeof line, ": mean %.2f %%, largest %.2f %%",
                  100.0 * prior.check_mean_rel, 100.0 * prior.check_max_rel);
    text.correction +=
        "; checked on " + count(static_cast<std::size_t>(prior.check_points), "point") + line;
  } else {
    text.correction += "; not checked (no point left out of the fit)";
  }
  std::snprintf(line, sizeof line, "; workspace within %.1f mm",
                prior.workspace_difference_m * 1e3);
  text.correction += line;
  return text;
}

}  // namespace autograv
