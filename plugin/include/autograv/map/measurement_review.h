#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "autograv/map/field_fit.h"
#include "autograv/map/workspace_grid.h"
#include "autograv/types/vertex_estimate.h"

namespace autograv {

/// A measurement that the others contradict (findStandingOut), by vertex.
struct StandingOutMeasurement {
  int vertex = -1;                                    ///< Grid index.
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();  ///< Where it was measured. Unit: [m]
  Eigen::Vector3d value_n = Eigen::Vector3d::Zero();  ///< What was measured. Unit: [N]
  double residual_rel = 0.0;                          ///< |leave-one-out residual| / |value|.
  /// The same figure of the measurements around it (StandingOut::local_rel).
  double local_rel = 0.0;
  /// The motors' thermal load when it was measured (VertexEstimate::thermal_load; in memory
  /// only), which a confirmed measurement takes back with its value.
  double thermal_load = 0.0;
};

/// What a calibration's review made of a measurement that stood out, once it was measured again.
enum class ReviewVerdict : std::uint8_t {
  kPending,    ///< Not concluded yet (planReview's entries).
  kConfirmed,  ///< The second measurement agrees with the first: the field is steep there, not
               ///< contradicted (a delta near its singular pose). The first, nearer the stops,
               ///< is kept.
  kReplaced,   ///< The two disagree and the second agrees with the others: the first was wrong
               ///< (a stop's reaction, a knock). The second is kept.
  kLeftOut,    ///< The two disagree and the second stands out too: neither is trusted, and the
               ///< vertex is left out of the fit (VertexOutcome::kLeftOut).
  kNotMeasuredAgain,  ///< The redo was skipped, or the second hold did not converge: the vertex
                      ///< keeps what it has (the first measurement, or the failed second hold).
};

/// Stable lower-case name used in files and reports ("confirmed", "replaced", "left_out",
/// "not_measured_again", "pending"). Real-time safe.
const char* toString(ReviewVerdict verdict) noexcept;
/// Inverse of toString; returns false for an unknown name.
bool parseReviewVerdict(const std::string& name, ReviewVerdict& verdict) noexcept;

/// A measurement that stood out, measured again, and what became of it: what a map keeps of its
/// calibration's review (MapMetadata::reviewed_measurements).
struct ReviewedMeasurement {
  /// As it stood out the first time (its vertex, point, value and residuals).
  StandingOutMeasurement first;
  /// Where it was measured again. Unit: [m]
  Eigen::Vector3d again_point_m = Eigen::Vector3d::Zero();
  /// What it measured there (zero when the second hold did not converge). Unit: [N]
  Eigen::Vector3d again_value_n = Eigen::Vector3d::Zero();
  /// |leave-one-out residual| / |value| of the second measurement (0 when it did not converge).
  double again_residual_rel = 0.0;
  /// What the review made of it.
  ReviewVerdict verdict = ReviewVerdict::kPending;
};

/// What judging every measurement against the others found.
struct MeasurementJudgement {
  FieldModel model = FieldModel::kConservative;  ///< The model the residuals are those of.
  double curl_weight = 0.0;                      ///< Of that model's fit.
  int measurements = 0;                          ///< Measurements judged.
  /// The measurements that stand out (findStandingOut, at most kStandOutShare of them), the most
  /// contradicted first.
  std::vector<StandingOutMeasurement> standing_out;
  /// Every judged measurement's vertex and residual / |value|, in vertex order.
  std::vector<std::pair<int, double>> residuals_rel;
};

/// Judges every converged measurement of `vertices` against the others (findStandingOut), under
/// the model chooseFieldModel keeps for them, with the repeatability kStandOutRepeatability times
/// `eps_g_n`, the calibration's eps_G (EstimationParameters::eps_g_n). Nothing stands out where
/// fewer than kStandOutMinMeasurements were made or they determine no fit. Needs no ground truth.
/// Not real-time safe: a few dense solves, about a second for a 5x5x5 plan.
MeasurementJudgement judgeMeasurements(const WorkspaceGrid& grid,
                                       const std::vector<VertexEstimate>& vertices, double eps_g_n);

/// The first half of a calibration's review, after its pass over the plan: the measurements of
/// `vertices` that stand out (judgeMeasurements; `eps_g_n` as it takes it), each to be measured
/// again where it was (again_point_m). There a knock or a slip is not repeated and the field is;
/// a stop that held the first hold is met by the second's stop watch (VertexEstimator's push
/// test: the second hold starts from what the neighbours predict, so the stop's reaction moves
/// its estimate toward the stop), which moves the point back from it. Measuring further inside
/// instead mistook a steep field for a contradiction: sim:falcon's points by its -x stop, 2.5 mm
/// further in, read 7-14 % apart, and the map lost its steep band (field p99 6.0-7.2 % against
/// 5.7-5.9 %). Measure them (AutoCalibrator::remeasureAt) in the pass that redoes the failed
/// vertices, then call concludeReview. Not real-time safe.
std::vector<ReviewedMeasurement> planReview(const WorkspaceGrid& grid,
                                            const std::vector<VertexEstimate>& vertices,
                                            double eps_g_n);

/// The second half: judges the measurements again (`eps_g_n` as judgeMeasurements takes it),
/// completes each entry of `reviewed` with what its vertex measured the second time, and gives
/// its verdict (ReviewVerdict). The two measurements agree when they differ by no more than
/// kStandOutLocalRatio times the residuals around the first (StandingOut::local_rel), nor than
/// their repeatability: a steep field is measured alike twice, a stop's reaction or a knock is
/// not. A confirmed vertex gets its first measurement back; one left out is marked (leaveOut).
/// Throws autograv::Error when `vertices` does not match `grid`. Not real-time safe.
void concludeReview(const WorkspaceGrid& grid, std::vector<VertexEstimate>& vertices,
                    std::vector<ReviewedMeasurement>& reviewed, double eps_g_n);

/// Marks `vertex` left out of the fit: its outcome kLeftOut, what it measured and where kept in
/// measured_at_m / measured_gravity_n (the fill then gives its value from the others).
void leaveOut(VertexEstimate& vertex, const Eigen::Vector3d& vertex_m) noexcept;

}  // namespace autograv
