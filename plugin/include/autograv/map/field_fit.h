#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "autograv/map/workspace_grid.h"
#include "autograv/types/vertex_estimate.h"

namespace autograv {

/// How a map reads the field between its measurements.
///
/// The apparent gravity of an ideal passive mechanism is the gradient of a potential (the links'
/// weights and any springs store energy U(q), and J^-T dU/dq = grad_x U), so it has no curl. What
/// a calibration measures is the force *command* that holds the stylus still, and that is the
/// gradient only on an ideal unit: each motor delivers its command times its own gain (torque
/// constant, amplifier, transmission), so the command is J^-T K^-1 dU/dq, which has a curl
/// wherever the gains differ and the potential couples the joints (a delta mechanism), and any
/// unmodelled cable or driver effect can add more. So a map does not assume either: it fits
/// several models to the measurements and keeps the one that predicts each measurement best from
/// the others (chooseFieldModel).
enum class FieldModel : std::uint8_t {
  /// Not a model but a request: the candidate whose leave-one-out error is smallest
  /// (chooseFieldModel). What calibrations ask for (kDefaultFieldModel).
  kChoose,
  /// The gradient of one potential through every measurement (FieldFit with curl weight 0): the
  /// components bend together, which fixes the field between scattered measurements where it
  /// holds.
  kConservative,
  /// Each component on its own (FieldFit with curl weight 1: a polyharmonic r^3 spline per
  /// component): no assumption about the field's curl.
  kComponentwise,
  /// A conservative field plus a smooth field without divergence, the second weighted by a curl
  /// weight chosen by cross-validation (FieldFit with that weight): close to the conservative fit
  /// where the measurements are conservative, following their curl where they are not.
  kCorrected,
  /// The discrete thin-plate lookup of each component (vertex_fill.h): the maps of schemas 1 to 3,
  /// and of grids with more measurements than FieldFit::kMaxMeasurements.
  kThinPlate,
};

/// Stable lower-case name used in files and reports: "choose", "conservative", "componentwise",
/// "corrected", "thin_plate". Real-time safe.
const char* toString(FieldModel model) noexcept;
/// Inverse of toString; returns false for an unknown name.
bool parseFieldModel(const std::string& name, FieldModel& model) noexcept;
/// Every name toString gives, in the enum's order.
std::vector<std::string> fieldModelNames();

/// A field fitted to measured values with matrix-valued polyharmonic kernels: a curl-free kernel
/// (the Hessian of |x|^5, whose fields are gradients) plus `curl_weight` times a
/// divergence-free one ((grad grad^T - Laplacian I) of -|x|^5), and an affine field. The two
/// kernels add up to 30 |x|^3 I, so weight 0 is the conservative fit (with the gradients of a
/// quadratic potential: G = A x + b, A symmetric) and weight 1 fits each component on its own
/// with the spline |x|^3 (with every affine field); weights in between and beyond trade how much
/// of the data's variation is told as curl. Every weight reproduces every measurement (to a
/// relative 1e-9 ridge) and, exactly, any field of its polynomial part. No kinematic model is
/// involved. Immutable once built.
class FieldFit {
 public:
  /// Fewest measurements a fit takes: three points in general position fix the quadratic
  /// potential's nine gradient coefficients (twelve affine ones need four).
  static constexpr int kMinMeasurements = 4;
  /// Most measurements a fit takes (an 8x8x8 grid's): the dense solve grows with their cube, to
  /// about a second at this many. Finer grids are dense enough for the thin-plate lookup.
  static constexpr int kMaxMeasurements = 512;
  /// Largest curl weight a fit takes: beyond it the divergence-free part explains everything and
  /// the fit no longer changes.
  static constexpr double kMaxCurlWeight = 1000.0;

  /// Fits `values_n[i]` measured at `points_m[i]` with `curl_weight` in [0, kMaxCurlWeight].
  /// Throws autograv::Error for a size mismatch, fewer than kMinMeasurements or more than
  /// kMaxMeasurements points, a non-finite point or value, a weight out of range, or points that
  /// do not determine the fit (coincident, or all on one line or, with a curl weight, in one
  /// plane). Not real-time safe: a dense solve of 3 n + 9 (or 3 n + 12) unknowns. Units: [m], [N]
  FieldFit(const std::vector<Eigen::Vector3d>& points_m,
           const std::vector<Eigen::Vector3d>& values_n, double curl_weight = 0.0);

  /// The fitted field at `position_m`: a sum over every measurement, so not for the servo path
  /// (GravityMap samples it onto its lookup grid once). Units: [m], [N]
  Eigen::Vector3d at(const Eigen::Vector3d& position_m) const noexcept;

  /// The number of measurements fitted.
  int measurementCount() const noexcept { return static_cast<int>(points_.size()); }
  /// The weight of the divergence-free kernel (0: conservative).
  double curlWeight() const noexcept { return curl_weight_; }

 private:
  // Positions are fitted in scaled coordinates (centred on the points' mean, divided by their
  // largest distance from it), which keeps the kernel's powers near 1.
  Eigen::Vector3d scaled(const Eigen::Vector3d& position_m) const noexcept;

  double curl_weight_ = 0.0;
  Eigen::Vector3d origin_m_ = Eigen::Vector3d::Zero();
  double scale_per_m_ = 1.0;
  std::vector<Eigen::Vector3d> points_;  ///< Scaled measurement points.
  Eigen::VectorXd kernel_weights_;       ///< Three per point. Unit: [N]
  Eigen::VectorXd polynomial_weights_;   ///< The affine field's 9 or 12. Unit: [N]
};

/// How far each measurement lies from what the others predict: the FieldFit of all the
/// measurements but measurement i, with `curl_weight`, evaluated at point i, minus value i
/// (leave-one-out). Large where the field bends faster than the measurements around it follow,
/// where a measurement disagrees with its neighbours, or where the model does not suit the
/// field: where more measurements, or another model, would help the map most. Needs no ground
/// truth. One dense factorization and inverse of the fit's system (Rippa's identity, per 3x3
/// block: residual i = -[(M^-1)_ii]^-1 c_i, with M the fit's system and c its kernel weights),
/// not n refits. Throws autograv::Error as the FieldFit constructor does, and when a measurement
/// cannot be left out (the others no longer determine a fit). Not real-time safe. Units: [m], [N]
std::vector<Eigen::Vector3d> leaveOneOutResiduals_n(const std::vector<Eigen::Vector3d>& points_m,
                                                    const std::vector<Eigen::Vector3d>& values_n,
                                                    double curl_weight = 0.0);

/// One candidate model's leave-one-out residuals, over |G| at each measurement.
struct FieldModelScore {
  FieldModel model = FieldModel::kConservative;  ///< The candidate.
  double curl_weight = 0.0;  ///< The fit's curl weight (the corrected model's chosen one).
  double median_rel = 0.0;   ///< Median of |residual| / |G|.
  double p90_rel = 0.0;      ///< 90th percentile.
  double mean_rel = 0.0;     ///< Mean: the score the choice compares.
};

/// The model chooseFieldModel keeps, and every candidate's score.
struct FieldModelChoice {
  FieldModel model = FieldModel::kConservative;  ///< The model kept.
  double curl_weight = 0.0;                      ///< Of the kept model.
  /// The conservative, componentwise and corrected candidates, in that order (scored without
  /// the measurements set aside).
  std::vector<FieldModelScore> scores;
  /// Indices of the measurements the scores leave out, because the others contradict them
  /// (findStandingOut under the choice made with every measurement); empty when none does.
  std::vector<int> set_aside;
};

/// A measurement that the others contradict, found by findStandingOut.
struct StandingOut {
  int index = -1;             ///< Into the measurements given.
  double residual_rel = 0.0;  ///< |leave-one-out residual| / |value| when it was found.
  /// The same figure of the measurements around it (the median of the kStandOutNeighbours
  /// nearest, judged with it left out): the scale it stands out from.
  double local_rel = 0.0;
};

/// findStandingOut looks at a measurement whose leave-one-out residual (relative) lies beyond
/// the others' median by this many robust spreads (1.4826 times their median absolute
/// deviation): a figure of the measurements themselves, not a fixed percentage.
inline constexpr double kStandOutSpreads = 6.0;
/// ... and it stands out when its residual is also this many times that of the measurements
/// around it, judged without it: a field that steepens near a stop leaves large residuals at
/// every measurement of its region, a stop's reaction or a slip at one.
inline constexpr double kStandOutLocalRatio = 5.0;
/// ... and when the measurements around it agree among themselves: their residuals (the median
/// of the kStandOutNeighbours nearest) within this many times the median of all, or within the
/// repeatability. Where they do not, the field bends faster there than the measurements follow,
/// and one more disagreement is no evidence against a measurement: sim:falcon's points by its -x
/// stop, 3.7-12 times the median around them, were each measured again alike (5 of them, 27-48 s
/// of device time for nothing), while a hold resting on a ceiling stood 20 % off among
/// neighbours at the median.
inline constexpr double kStandOutQuietRatio = 3.0;
/// Measurements around a candidate whose residuals make its local scale.
inline constexpr int kStandOutNeighbours = 6;
/// The measurements with the largest residuals that findStandingOut compares with the others,
/// each judged with it left out of the fit (one leave-one-out each), per measurement found.
inline constexpr std::size_t kStandOutCandidates = 3;
/// Most measurements chooseFieldModel sets aside, and the calibration's review finds standing
/// out, as a share of all (at least one): where more stand out, something no re-measure fixes is
/// wrong (a device that drifts, a wrong model), and every measurement is kept.
inline constexpr double kStandOutShare = 0.05;
/// Fewest measurements findStandingOut judges: with fewer, a residual is an extrapolation, not
/// one of a population to stand out from.
inline constexpr int kStandOutMinMeasurements = 12;
/// The repeatability of a calibration's measurements, in eps_G: the floor below which
/// findStandingOut finds nothing contradicted.
inline constexpr double kStandOutRepeatability = 2.0;

/// The measurements that the others contradict under the fit with `curl_weight` (kStandOutSpreads,
/// kStandOutLocalRatio; both judged with the candidate left out of the fit, so that its error does
/// not hide among the residuals it inflates), at most `most`, the most contradicted first; a
/// residual below `floor_n`, the measurements' own repeatability, never stands out
/// (kStandOutRepeatability eps_G for a calibration's: a hold converges when its updates fall below
/// eps_G, so two holds of one point differ by that much). Each one found is set aside before the
/// next is looked for, so that it does not make its neighbours look contradicted too. Empty for
/// fewer than kStandOutMinMeasurements measurements, or where they determine no fit. Not real-time
/// safe: one leave-one-out per measurement found and per candidate looked at. Units: [m], [N]
std::vector<StandingOut> findStandingOut(const std::vector<Eigen::Vector3d>& points_m,
                                         const std::vector<Eigen::Vector3d>& values_n,
                                         double curl_weight, int most, double floor_n);

/// Curl weights the corrected model tries (each a fit and a leave-one-out): a geometric ladder
/// from a correction that barely bends the conservative fit up to one that outweighs it (1, where
/// the two kernels weigh alike, is the componentwise fit).
const std::vector<double>& correctedCurlWeights();

/// A more flexible model must predict the measurements this much better (relative mean error)
/// than the conservative fit to be kept: the conservative fit's physics stays unless the data
/// speak against it, not on noise.
inline constexpr double kFieldModelMargin = 0.05;
/// ... and by at least this much of |G| in absolute terms: below a hundredth of a percent the
/// candidates differ by rounding and the measurements' last digits, not by the field. Relative.
inline constexpr double kFieldModelFloor = 1e-4;

/// The corrected candidate at its best curl weight: each of correctedCurlWeights scored, the
/// smallest mean leave-one-out error kept. Throws autograv::Error as leaveOneOutResiduals_n
/// does. Not real-time safe. Units: [m], [N]
FieldModelScore bestCorrectedScore(const std::vector<Eigen::Vector3d>& points_m,
                                   const std::vector<Eigen::Vector3d>& values_n);

/// Fits the conservative, componentwise and corrected candidates (the last at each of
/// correctedCurlWeights) and keeps the one whose leave-one-out residuals, relative to |G|, are
/// smallest in the mean; the conservative fit unless another beats it by kFieldModelMargin (and
/// kFieldModelFloor). The
/// mean, not the root mean square: a few measurements next to the stops, which every model
/// extrapolates to, would decide a root mean square alone, and the field between the others
/// would not count. The mean is not robust to one measurement that a stop held, so the
/// measurements that the others contradict under that first choice (findStandingOut, at most
/// one in twenty; none below `floor_n`, their repeatability) are set aside and the candidates
/// scored again without them (FieldModelChoice::set_aside). The default floor, infinite, sets
/// nothing aside. Throws autograv::Error as leaveOneOutResiduals_n does, for a conservative
/// fit that cannot be scored (the other candidates are skipped when they cannot be). Not real-time
/// safe: a few tenths of a second for a hundred measurements. Units: [m], [N]
FieldModelChoice chooseFieldModel(const std::vector<Eigen::Vector3d>& points_m,
                                  const std::vector<Eigen::Vector3d>& values_n,
                                  double floor_n = std::numeric_limits<double>::infinity());

/// How the measurements of a map agree with one another: each converged vertex's measurement
/// against the fit of all the others (leaveOneOutResiduals_n) in the map's own model, over |G_hat|
/// there.
struct MeasurementAgreement {
  /// A residual beyond the measurements' own error (up to about 1 % of |G_hat| next to an Omni's
  /// stops) says the field bends there faster than the measurements around it follow.
  static constexpr double kWorthMeasuring = 0.01;
  /// How many of the worst vertices least_sure_vertices lists at most.
  static constexpr int kListed = 3;
  /// The model the residuals are those of (a thin-plate map is judged by the componentwise fit,
  /// the continuous model of each component on its own).
  FieldModel model = FieldModel::kConservative;
  double curl_weight = 0.0;  ///< Of that model's fit.
  int measurements = 0;      ///< Converged vertices.
  double median_rel = 0.0;   ///< Median of |residual| / |G_hat|.
  double p90_rel = 0.0;      ///< 90th percentile.
  double max_rel = 0.0;      ///< Largest.
  /// Vertices whose residual passes kWorthMeasuring, largest first (at most kListed): where more
  /// measurements would help the map most.
  std::vector<int> least_sure_vertices;
};

/// The agreement of the converged vertices' measurements under `model` (kChoose and kThinPlate
/// read as kComponentwise) with `curl_weight` (the corrected model's; the others have their own).
/// Throws autograv::Error as leaveOneOutResiduals_n does (fewer than FieldFit::kMinMeasurements
/// or more than kMaxMeasurements of them, or points that do not determine a fit). Not real-time
/// safe.
MeasurementAgreement measurementAgreement(const WorkspaceGrid& grid,
                                          const std::vector<VertexEstimate>& vertices,
                                          FieldModel model = FieldModel::kConservative,
                                          double curl_weight = 0.0);

/// The curl weight `model`'s fit uses: 0 for the conservative fit, 1 for the componentwise one
/// (and for kThinPlate and kChoose, judged as componentwise), `corrected_weight` for the
/// corrected one.
double curlWeightOf(FieldModel model, double corrected_weight) noexcept;

/// The measurements of a map: every converged vertex, at the point it was measured
/// (VertexEstimate::measuredAt_m) with the value measured there, and, when `vertex_of` is given,
/// each measurement's vertex index. Units: [m], [N]
void collectMeasurements(const WorkspaceGrid& grid, const std::vector<VertexEstimate>& vertices,
                         std::vector<Eigen::Vector3d>& points_m,
                         std::vector<Eigen::Vector3d>& values_n,
                         std::vector<int>* vertex_of = nullptr);

}  // namespace autograv
