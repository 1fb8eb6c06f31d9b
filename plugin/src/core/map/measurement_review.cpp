#include "autograv/map/measurement_review.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "autograv/error.h"

namespace autograv {

MeasurementJudgement judgeMeasurements(const WorkspaceGrid& grid,
                                       const std::vector<VertexEstimate>& vertices,
                                       double eps_g_n) {
  MeasurementJudgement judgement;
  std::vector<Eigen::Vector3d> points_m, values_n;
  std::vector<int> vertex_of;
  collectMeasurements(grid, vertices, points_m, values_n, &vertex_of);
  judgement.measurements = static_cast<int>(points_m.size());
  if (judgement.measurements < kStandOutMinMeasurements ||
      judgement.measurements > FieldFit::kMaxMeasurements) {
    return judgement;
  }
  try {
    const FieldModelChoice choice =
        chooseFieldModel(points_m, values_n, kStandOutRepeatability * eps_g_n);
    judgement.model = choice.model;
    judgement.curl_weight = curlWeightOf(choice.model, choice.curl_weight);
    const std::vector<Eigen::Vector3d> residuals_n =
        leaveOneOutResiduals_n(points_m, values_n, judgement.curl_weight);
    for (std::size_t k = 0; k < residuals_n.size(); ++k) {
      judgement.residuals_rel.emplace_back(
          vertex_of[k], residuals_n[k].norm() / std::max(values_n[k].norm(), 1e-12));
    }
  } catch (const Error&) {
    return judgement;  // measurements that determine no fit: nothing to judge them by
  }
  const int most = std::max(1, static_cast<int>(kStandOutShare * judgement.measurements));
  for (const StandingOut& found : findStandingOut(points_m, values_n, judgement.curl_weight, most,
                                                  kStandOutRepeatability * eps_g_n)) {
    const auto k = static_cast<std::size_t>(found.index);
    StandingOutMeasurement measurement;
    measurement.vertex = vertex_of[k];
    measurement.point_m = points_m[k];
    measurement.value_n = values_n[k];
    measurement.residual_rel = found.residual_rel;
    measurement.local_rel = found.local_rel;
    measurement.thermal_load = vertices[static_cast<std::size_t>(vertex_of[k])].thermal_load;
    judgement.standing_out.push_back(measurement);
  }
  return judgement;
}

const char* toString(ReviewVerdict verdict) noexcept {
  switch (verdict) {
    case ReviewVerdict::kPending:
      return "pending";
    case ReviewVerdict::kConfirmed:
      return "confirmed";
    case ReviewVerdict::kReplaced:
      return "replaced";
    case ReviewVerdict::kLeftOut:
      return "left_out";
    case ReviewVerdict::kNotMeasuredAgain:
      return "not_measured_again";
  }
  return "pending";
}

bool parseReviewVerdict(const std::string& name, ReviewVerdict& verdict) noexcept {
  for (const ReviewVerdict candidate :
       {ReviewVerdict::kPending, ReviewVerdict::kConfirmed, ReviewVerdict::kReplaced,
        ReviewVerdict::kLeftOut, ReviewVerdict::kNotMeasuredAgain}) {
    if (name == toString(candidate)) {
      verdict = candidate;
      return true;
    }
  }
  return false;
}

std::vector<ReviewedMeasurement> planReview(const WorkspaceGrid& grid,
                                            const std::vector<VertexEstimate>& vertices,
                                            double eps_g_n) {
  std::vector<ReviewedMeasurement> reviewed;
  for (const StandingOutMeasurement& found :
       judgeMeasurements(grid, vertices, eps_g_n).standing_out) {
    ReviewedMeasurement entry;
    entry.first = found;
    entry.again_point_m = found.point_m;
    reviewed.push_back(entry);
  }
  return reviewed;
}

void concludeReview(const WorkspaceGrid& grid, std::vector<VertexEstimate>& vertices,
                    std::vector<ReviewedMeasurement>& reviewed, double eps_g_n) {
  if (static_cast<int>(vertices.size()) != grid.vertexCount()) {
    throw Error("measurement review: " + std::to_string(vertices.size()) +
                " vertex estimates for a grid of " + std::to_string(grid.vertexCount()));
  }
  if (reviewed.empty()) return;
  const MeasurementJudgement judgement = judgeMeasurements(grid, vertices, eps_g_n);
  for (ReviewedMeasurement& entry : reviewed) {
    const int index = entry.first.vertex;
    if (index < 0 || index >= grid.vertexCount()) continue;
    VertexEstimate& vertex = vertices[static_cast<std::size_t>(index)];
    const Eigen::Vector3d vertex_m = grid.vertexPosition(index);
    if (vertex.outcome != VertexOutcome::kConverged) {
      entry.verdict = ReviewVerdict::kNotMeasuredAgain;  // the second hold failed
      continue;
    }
    entry.again_point_m = vertex.measuredAt_m(vertex_m);
    entry.again_value_n = vertex.measuredGravity_n();
    for (const auto& [judged, residual] : judgement.residuals_rel) {
      if (judged == index) entry.again_residual_rel = residual;
    }
    if (entry.again_point_m == entry.first.point_m && entry.again_value_n == entry.first.value_n) {
      entry.verdict = ReviewVerdict::kNotMeasuredAgain;  // the redo was skipped
      continue;
    }
    const double first_n = entry.first.value_n.norm();
    const double differ_n = (entry.again_value_n - entry.first.value_n).norm();
    const bool agree = differ_n <= std::max(kStandOutRepeatability * eps_g_n,
                                            kStandOutLocalRatio * entry.first.local_rel * first_n);
    const bool stands_out_again =
        std::any_of(judgement.standing_out.begin(), judgement.standing_out.end(),
                    [index](const StandingOutMeasurement& found) { return found.vertex == index; });
    if (agree) {
      // The field, measured alike twice: the first measurement, nearer the stops, goes back.
      entry.verdict = ReviewVerdict::kConfirmed;
      vertex.gravity_n = entry.first.value_n;
      vertex.thermal_load = entry.first.thermal_load;
      vertex.measured_at_m = VertexEstimate().measured_at_m;
      vertex.measured_gravity_n.setZero();
      if ((entry.first.point_m - vertex_m).norm() > 1e-9) {
        vertex.measured_at_m = entry.first.point_m;
        vertex.measured_gravity_n = entry.first.value_n;
      }
    } else if (stands_out_again) {
      entry.verdict = ReviewVerdict::kLeftOut;
      leaveOut(vertex, vertex_m);
    } else {
      entry.verdict = ReviewVerdict::kReplaced;
    }
  }
}

void leaveOut(VertexEstimate& vertex, const Eigen::Vector3d& vertex_m) noexcept {
  const Eigen::Vector3d at_m = vertex.measuredAt_m(vertex_m);
  const Eigen::Vector3d value_n = vertex.measuredGravity_n();
  vertex.measured_at_m = at_m;
  vertex.measured_gravity_n = value_n;
  vertex.outcome = VertexOutcome::kLeftOut;
}

}  // namespace autograv
