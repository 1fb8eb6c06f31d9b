#include "autograv/map/map_summary.h"

#include <algorithm>

#include "autograv/map/value_kind.h"

namespace autograv {

namespace {

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
         vertex.outcome != VertexOutcome::kUnreachable;
}

bool holdsNoValue(const VertexEstimate& vertex) noexcept {
  return vertex.provenance != VertexProvenance::kFilled &&
         (isFailed(vertex) || vertex.outcome == VertexOutcome::kUnreachable);
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

}  // namespace autograv
