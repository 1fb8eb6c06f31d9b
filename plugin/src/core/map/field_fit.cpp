#include "autograv/map/field_fit.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include <Eigen/LU>

#include "autograv/error.h"

namespace autograv {

namespace {

// The affine fields: three constants, the six gradients of x^2, y^2, z^2, xy, xz, yz, and the
// three rotations, which only fits with a curl weight use (a conservative fit has no curl).
constexpr int kAffineTerms = 12;
constexpr int kGradientTerms = 9;
// Ridge on the kernel block, relative to the largest kernel entry: keeps the solve regular when
// two points nearly coincide and moves no measurement by a measurable amount.
constexpr double kRelativeRidge = 1e-9;

int polynomialTerms(double curl_weight) noexcept {
  return curl_weight > 0.0 ? kAffineTerms : kGradientTerms;
}

/// The 3x3 block that ties a value measured at one point to the value at another, v apart
/// (scaled units): the Hessian of |v|^5, 5 r (r^2 I + 3 v v^T), plus curl_weight times the
/// divergence-free 5 r (5 r^2 I - 3 v v^T).
Eigen::Matrix3d kernelBlock(const Eigen::Vector3d& v, double curl_weight) noexcept {
  const double r = v.norm();
  return 5.0 * r *
         ((1.0 + 5.0 * curl_weight) * r * r * Eigen::Matrix3d::Identity() +
          (3.0 * (1.0 - curl_weight)) * v * v.transpose());
}

/// The affine fields at v (scaled), one per column: see kAffineTerms.
Eigen::Matrix<double, 3, kAffineTerms> polynomialBlock(const Eigen::Vector3d& v) noexcept {
  Eigen::Matrix<double, 3, kAffineTerms> block = Eigen::Matrix<double, 3, kAffineTerms>::Zero();
  block.leftCols<3>().setIdentity();
  for (int a = 0; a < 3; ++a) block(a, 3 + a) = 2.0 * v[a];
  block(0, 6) = v.y();
  block(1, 6) = v.x();
  block(0, 7) = v.z();
  block(2, 7) = v.x();
  block(1, 8) = v.z();
  block(2, 8) = v.y();
  // Rotations about x, y and z: e_a x v.
  block(1, 9) = -v.z();
  block(2, 9) = v.y();
  block(0, 10) = v.z();
  block(2, 10) = -v.x();
  block(0, 11) = -v.y();
  block(1, 11) = v.x();
  return block;
}

/// The fit's linear system in scaled coordinates: the kernel blocks between every pair of
/// measurements, bordered by the affine fields, with the measured values on the right (kernel
/// weights first, three per point, then the polynomial weights).
struct FitSystem {
  double curl_weight = 0.0;
  Eigen::Vector3d origin_m = Eigen::Vector3d::Zero();
  double scale_per_m = 1.0;
  std::vector<Eigen::Vector3d> points;  ///< Scaled.
  Eigen::MatrixXd matrix;
  Eigen::VectorXd rhs;
};

FitSystem buildSystem(const std::vector<Eigen::Vector3d>& points_m,
                      const std::vector<Eigen::Vector3d>& values_n, double curl_weight) {
  if (points_m.size() != values_n.size()) {
    throw Error("field fit: " + std::to_string(points_m.size()) + " points but " +
                std::to_string(values_n.size()) + " values");
  }
  const int n = static_cast<int>(points_m.size());
  if (n > FieldFit::kMaxMeasurements) {
    throw Error("field fit: " + std::to_string(n) + " measurements; it takes at most " +
                std::to_string(FieldFit::kMaxMeasurements));
  }
  if (n < FieldFit::kMinMeasurements) {
    throw Error("field fit: " + std::to_string(n) + " measurements; it needs at least " +
                std::to_string(FieldFit::kMinMeasurements));
  }
  if (!(curl_weight >= 0.0 && curl_weight <= FieldFit::kMaxCurlWeight)) {
    throw Error("field fit: the curl weight must lie in [0, " +
                std::to_string(FieldFit::kMaxCurlWeight) + "], got " + std::to_string(curl_weight));
  }
  for (int i = 0; i < n; ++i) {
    const auto at = static_cast<std::size_t>(i);
    if (!points_m[at].allFinite() || !values_n[at].allFinite()) {
      throw Error("field fit: measurement " + std::to_string(i) + " is not finite");
    }
  }
  FitSystem fit;
  fit.curl_weight = curl_weight;
  for (const Eigen::Vector3d& p : points_m) fit.origin_m += p;
  fit.origin_m /= n;
  double extent_m = 0.0;
  for (const Eigen::Vector3d& p : points_m)
    extent_m = std::max(extent_m, (p - fit.origin_m).norm());
  if (!(extent_m > 0.0)) throw Error("field fit: every measurement is at one point");
  fit.scale_per_m = 1.0 / extent_m;
  fit.points.reserve(points_m.size());
  for (const Eigen::Vector3d& p : points_m)
    fit.points.push_back((p - fit.origin_m) * fit.scale_per_m);

  const int terms = polynomialTerms(curl_weight);
  const int size = 3 * n + terms;
  fit.matrix = Eigen::MatrixXd::Zero(size, size);
  fit.rhs = Eigen::VectorXd::Zero(size);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d& xi = fit.points[static_cast<std::size_t>(i)];
    for (int j = 0; j < n; ++j) {
      fit.matrix.block<3, 3>(3 * i, 3 * j) =
          kernelBlock(xi - fit.points[static_cast<std::size_t>(j)], curl_weight);
    }
    const Eigen::MatrixXd polynomial = polynomialBlock(xi).leftCols(terms);
    fit.matrix.block(3 * i, 3 * n, 3, terms) = polynomial;
    fit.matrix.block(3 * n, 3 * i, terms, 3) = polynomial.transpose();
    fit.rhs.segment<3>(3 * i) = values_n[static_cast<std::size_t>(i)];
  }
  const double ridge =
      kRelativeRidge * fit.matrix.topLeftCorner(3 * n, 3 * n).cwiseAbs().maxCoeff();
  fit.matrix.topLeftCorner(3 * n, 3 * n).diagonal().array() += ridge;
  return fit;
}

/// Solves `fit`, and refuses a system its points leave singular: points on a line (or, with the
/// rotations, in a plane) leave the affine part undetermined, which shows as a solution that is
/// not finite or does not solve the system.
Eigen::VectorXd solveSystem(const FitSystem& fit, const Eigen::PartialPivLU<Eigen::MatrixXd>& lu) {
  const Eigen::VectorXd solution = lu.solve(fit.rhs);
  const double residual = (fit.matrix * solution - fit.rhs).norm();
  if (!solution.allFinite() || !(residual <= 1e-8 * std::max(fit.rhs.norm(), 1e-300))) {
    throw Error("field fit: the " + std::to_string(fit.points.size()) +
                " measurement points do not determine the field (they lie on a line or in a "
                "plane, or coincide)");
  }
  return solution;
}

/// |residual| / |G| at each measurement.
std::vector<double> relativeResiduals(const std::vector<Eigen::Vector3d>& residuals_n,
                                      const std::vector<Eigen::Vector3d>& values_n) {
  std::vector<double> ratios;
  ratios.reserve(residuals_n.size());
  for (std::size_t k = 0; k < residuals_n.size(); ++k) {
    ratios.push_back(residuals_n[k].norm() / std::max(values_n[k].norm(), 1e-12));
  }
  return ratios;
}

/// The value below which a fraction q of the sorted `values` lie (the lower of the two around).
double quantileOfSorted(const std::vector<double>& sorted, double q) {
  return sorted[static_cast<std::size_t>(q * static_cast<double>(sorted.size() - 1))];
}

double medianOf(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

/// The measurements `kept` of `all`.
std::vector<Eigen::Vector3d> subset(const std::vector<Eigen::Vector3d>& all,
                                    const std::vector<int>& kept) {
  std::vector<Eigen::Vector3d> chosen;
  chosen.reserve(kept.size());
  for (const int k : kept) chosen.push_back(all[static_cast<std::size_t>(k)]);
  return chosen;
}

/// How measurement `candidate` (one of `active`) compares with the others, judged with it left
/// out of the fit: so that a large error, which bends the fit toward itself and so inflates the
/// others' residuals, does not hide among them.
struct Comparison {
  double median_rel = 0.0;  ///< Median residual of the others.
  double spread_rel = 0.0;  ///< 1.4826 times their median absolute deviation.
  double local_rel = 0.0;   ///< Median residual of the kStandOutNeighbours nearest the candidate.
};

Comparison compareWithTheOthers(const std::vector<Eigen::Vector3d>& points_m,
                                const std::vector<Eigen::Vector3d>& values_n, double curl_weight,
                                const std::vector<int>& active, int candidate) {
  std::vector<int> others;
  for (const int k : active) {
    if (k != candidate) others.push_back(k);
  }
  const std::vector<Eigen::Vector3d> others_m = subset(points_m, others);
  const std::vector<Eigen::Vector3d> others_n = subset(values_n, others);
  const std::vector<double> residuals =
      relativeResiduals(leaveOneOutResiduals_n(others_m, others_n, curl_weight), others_n);
  Comparison comparison;
  comparison.median_rel = medianOf(residuals);
  std::vector<double> deviations;
  for (const double residual : residuals) {
    deviations.push_back(std::abs(residual - comparison.median_rel));
  }
  comparison.spread_rel = 1.4826 * medianOf(deviations);
  const Eigen::Vector3d& at_m = points_m[static_cast<std::size_t>(candidate)];
  std::vector<std::pair<double, double>> by_distance;  // distance [m], residual
  for (std::size_t k = 0; k < others_m.size(); ++k) {
    by_distance.emplace_back((others_m[k] - at_m).norm(), residuals[k]);
  }
  const auto count = std::min<std::size_t>(kStandOutNeighbours, by_distance.size());
  std::partial_sort(by_distance.begin(), by_distance.begin() + static_cast<std::ptrdiff_t>(count),
                    by_distance.end());
  std::vector<double> nearest;
  for (std::size_t k = 0; k < count; ++k) nearest.push_back(by_distance[k].second);
  comparison.local_rel = medianOf(nearest);
  return comparison;
}

FieldModelScore scoreOf(FieldModel model, double curl_weight,
                        const std::vector<Eigen::Vector3d>& points_m,
                        const std::vector<Eigen::Vector3d>& values_n) {
  std::vector<double> ratios =
      relativeResiduals(leaveOneOutResiduals_n(points_m, values_n, curl_weight), values_n);
  double sum = 0.0;
  for (const double ratio : ratios) sum += ratio;
  std::sort(ratios.begin(), ratios.end());
  FieldModelScore score;
  score.model = model;
  score.curl_weight = curl_weight;
  score.median_rel = quantileOfSorted(ratios, 0.5);
  score.p90_rel = quantileOfSorted(ratios, 0.9);
  score.mean_rel = sum / static_cast<double>(ratios.size());
  return score;
}

}  // namespace

const char* toString(FieldModel model) noexcept {
  switch (model) {
    case FieldModel::kChoose:
      return "choose";
    case FieldModel::kConservative:
      return "conservative";
    case FieldModel::kComponentwise:
      return "componentwise";
    case FieldModel::kCorrected:
      return "corrected";
    case FieldModel::kThinPlate:
      return "thin_plate";
  }
  return "thin_plate";
}

std::vector<std::string> fieldModelNames() {
  return {"choose", "conservative", "componentwise", "corrected", "thin_plate"};
}

bool parseFieldModel(const std::string& name, FieldModel& model) noexcept {
  for (const FieldModel candidate :
       {FieldModel::kChoose, FieldModel::kConservative, FieldModel::kComponentwise,
        FieldModel::kCorrected, FieldModel::kThinPlate}) {
    if (name == toString(candidate)) {
      model = candidate;
      return true;
    }
  }
  return false;
}

FieldFit::FieldFit(const std::vector<Eigen::Vector3d>& points_m,
                   const std::vector<Eigen::Vector3d>& values_n, double curl_weight) {
  FitSystem fit = buildSystem(points_m, values_n, curl_weight);
  const Eigen::VectorXd solution =
      solveSystem(fit, Eigen::PartialPivLU<Eigen::MatrixXd>(fit.matrix));
  curl_weight_ = curl_weight;
  origin_m_ = fit.origin_m;
  scale_per_m_ = fit.scale_per_m;
  points_ = std::move(fit.points);
  kernel_weights_ = solution.head(3 * measurementCount());
  polynomial_weights_ = solution.tail(polynomialTerms(curl_weight));
}

std::vector<Eigen::Vector3d> leaveOneOutResiduals_n(const std::vector<Eigen::Vector3d>& points_m,
                                                    const std::vector<Eigen::Vector3d>& values_n,
                                                    double curl_weight) {
  const FitSystem fit = buildSystem(points_m, values_n, curl_weight);
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(fit.matrix);
  const Eigen::VectorXd solution = solveSystem(fit, lu);
  const Eigen::MatrixXd inverse = lu.inverse();
  std::vector<Eigen::Vector3d> residuals_n;
  residuals_n.reserve(points_m.size());
  for (std::size_t i = 0; i < points_m.size(); ++i) {
    const int row = 3 * static_cast<int>(i);
    const Eigen::Matrix3d block = inverse.block<3, 3>(row, row);
    const Eigen::FullPivLU<Eigen::Matrix3d> block_lu(block);
    const Eigen::Vector3d residual_n = -block_lu.solve(solution.segment<3>(row).eval());
    if (!block_lu.isInvertible() || !residual_n.allFinite()) {
      throw Error("field fit: measurement " + std::to_string(i) +
                  " cannot be left out: the others do not determine the field");
    }
    residuals_n.push_back(residual_n);
  }
  return residuals_n;
}

Eigen::Vector3d FieldFit::scaled(const Eigen::Vector3d& position_m) const noexcept {
  return (position_m - origin_m_) * scale_per_m_;
}

Eigen::Vector3d FieldFit::at(const Eigen::Vector3d& position_m) const noexcept {
  const Eigen::Vector3d v = scaled(position_m);
  const int terms = static_cast<int>(polynomial_weights_.size());
  Eigen::Vector3d value_n = polynomialBlock(v).leftCols(terms) * polynomial_weights_;
  for (std::size_t j = 0; j < points_.size(); ++j) {
    value_n += kernelBlock(v - points_[j], curl_weight_) *
               kernel_weights_.segment<3>(3 * static_cast<int>(j));
  }
  return value_n;
}

const std::vector<double>& correctedCurlWeights() {
  static const std::vector<double> weights{0.0003, 0.001, 0.003, 0.01, 0.03, 0.1, 0.3, 3.0};
  return weights;
}

double curlWeightOf(FieldModel model, double corrected_weight) noexcept {
  switch (model) {
    case FieldModel::kConservative:
      return 0.0;
    case FieldModel::kCorrected:
      return corrected_weight;
    case FieldModel::kChoose:
    case FieldModel::kComponentwise:
    case FieldModel::kThinPlate:
      break;
  }
  return 1.0;
}

FieldModelScore bestCorrectedScore(const std::vector<Eigen::Vector3d>& points_m,
                                   const std::vector<Eigen::Vector3d>& values_n) {
  FieldModelScore best;
  best.mean_rel = -1.0;
  for (const double weight : correctedCurlWeights()) {
    const FieldModelScore tried = scoreOf(FieldModel::kCorrected, weight, points_m, values_n);
    if (best.mean_rel < 0.0 || tried.mean_rel < best.mean_rel) best = tried;
  }
  return best;
}

std::vector<StandingOut> findStandingOut(const std::vector<Eigen::Vector3d>& points_m,
                                         const std::vector<Eigen::Vector3d>& values_n,
                                         double curl_weight, int most, double floor_n) {
  std::vector<StandingOut> found;
  const int count = static_cast<int>(points_m.size());
  if (count < kStandOutMinMeasurements || values_n.size() != points_m.size()) return found;
  std::vector<int> active(static_cast<std::size_t>(count));
  for (int k = 0; k < count; ++k) active[static_cast<std::size_t>(k)] = k;
  try {
    while (static_cast<int>(found.size()) < most) {
      const std::vector<Eigen::Vector3d> active_n = subset(values_n, active);
      const std::vector<double> residuals = relativeResiduals(
          leaveOneOutResiduals_n(subset(points_m, active), active_n, curl_weight), active_n);
      std::vector<std::size_t> order(residuals.size());  // positions in `active`, largest first
      for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
      std::sort(order.begin(), order.end(),
                [&](std::size_t a, std::size_t b) { return residuals[a] > residuals[b]; });
      bool more = false;
      for (std::size_t rank = 0; rank < order.size() && rank < kStandOutCandidates; ++rank) {
        const std::size_t k = order[rank];
        const int index = active[k];
        if (!(residuals[k] * values_n[static_cast<std::size_t>(index)].norm() > floor_n)) {
          continue;  // within the measurements' repeatability
        }
        Comparison others;
        try {
          others = compareWithTheOthers(points_m, values_n, curl_weight, active, index);
        } catch (const Error&) {
          continue;  // without it the others determine no fit: it is needed, not contradicted
        }
        const double value_n = values_n[static_cast<std::size_t>(index)].norm();
        const bool quiet_around =
            others.local_rel * value_n <=
            std::max(kStandOutQuietRatio * others.median_rel * value_n, floor_n);
        if (residuals[k] <= others.median_rel + kStandOutSpreads * others.spread_rel ||
            residuals[k] < kStandOutLocalRatio * std::max(others.local_rel, others.median_rel) ||
            !quiet_around) {
          continue;
        }
        found.push_back(StandingOut{index, residuals[k], others.local_rel});
        active.erase(active.begin() + static_cast<std::ptrdiff_t>(k));
        more = true;
        break;
      }
      if (!more) break;
    }
  } catch (const Error&) {
    // The measurements left determine no fit: what was found so far stands.
  }
  return found;
}

namespace {

/// chooseFieldModel's comparison of the candidates' scores over every measurement given.
FieldModelChoice chooseAmongCandidates(const std::vector<Eigen::Vector3d>& points_m,
                                       const std::vector<Eigen::Vector3d>& values_n) {
  FieldModelChoice choice;
  const FieldModelScore conservative = scoreOf(FieldModel::kConservative, 0.0, points_m, values_n);
  choice.scores.push_back(conservative);
  // The other candidates need the rotations determined too (points in no plane); without them,
  // the conservative fit is the only one.
  try {
    choice.scores.push_back(scoreOf(FieldModel::kComponentwise, 1.0, points_m, values_n));
    choice.scores.push_back(bestCorrectedScore(points_m, values_n));
  } catch (const Error&) {
    choice.scores.resize(1);
  }
  const FieldModelScore* best = &choice.scores.front();
  const double to_beat = std::min((1.0 - kFieldModelMargin) * conservative.mean_rel,
                                  conservative.mean_rel - kFieldModelFloor);
  for (const FieldModelScore& score : choice.scores) {
    if (score.mean_rel < to_beat && score.mean_rel < best->mean_rel) {
      best = &score;
    }
  }
  choice.model = best->model;
  choice.curl_weight = best->curl_weight;
  return choice;
}

}  // namespace

FieldModelChoice chooseFieldModel(const std::vector<Eigen::Vector3d>& points_m,
                                  const std::vector<Eigen::Vector3d>& values_n, double floor_n) {
  const FieldModelChoice first = chooseAmongCandidates(points_m, values_n);
  if (!(floor_n < std::numeric_limits<double>::infinity())) return first;
  const int most =
      std::max(1, static_cast<int>(kStandOutShare * static_cast<double>(points_m.size())));
  const std::vector<StandingOut> standing = findStandingOut(
      points_m, values_n, curlWeightOf(first.model, first.curl_weight), most, floor_n);
  if (standing.empty()) return first;
  std::vector<bool> aside(points_m.size(), false);
  for (const StandingOut& found : standing) aside[static_cast<std::size_t>(found.index)] = true;
  std::vector<int> kept;
  for (int k = 0; k < static_cast<int>(points_m.size()); ++k) {
    if (!aside[static_cast<std::size_t>(k)]) kept.push_back(k);
  }
  try {
    FieldModelChoice choice = chooseAmongCandidates(subset(points_m, kept), subset(values_n, kept));
    for (const StandingOut& found : standing) choice.set_aside.push_back(found.index);
    std::sort(choice.set_aside.begin(), choice.set_aside.end());
    return choice;
  } catch (const Error&) {
    return first;  // the others alone determine no fit
  }
}

MeasurementAgreement measurementAgreement(const WorkspaceGrid& grid,
                                          const std::vector<VertexEstimate>& vertices,
                                          FieldModel model, double curl_weight) {
  std::vector<Eigen::Vector3d> points_m;
  std::vector<Eigen::Vector3d> values_n;
  std::vector<int> vertex_of;
  collectMeasurements(grid, vertices, points_m, values_n, &vertex_of);
  const FieldModel judged = model == FieldModel::kChoose || model == FieldModel::kThinPlate
                                ? FieldModel::kComponentwise
                                : model;
  const double weight = curlWeightOf(judged, curl_weight);
  const std::vector<double> relative =
      relativeResiduals(leaveOneOutResiduals_n(points_m, values_n, weight), values_n);
  std::vector<std::pair<double, int>> ratios;  // |residual| / |G_hat|, vertex
  for (std::size_t k = 0; k < relative.size(); ++k) ratios.emplace_back(relative[k], vertex_of[k]);
  std::sort(ratios.begin(), ratios.end());
  std::vector<double> sorted;
  for (const auto& ratio : ratios) sorted.push_back(ratio.first);
  MeasurementAgreement agreement;
  agreement.model = judged;
  agreement.curl_weight = weight;
  agreement.measurements = static_cast<int>(ratios.size());
  agreement.median_rel = quantileOfSorted(sorted, 0.5);
  agreement.p90_rel = quantileOfSorted(sorted, 0.9);
  agreement.max_rel = sorted.back();
  for (auto worst = ratios.rbegin();
       worst != ratios.rend() && worst->first > MeasurementAgreement::kWorthMeasuring &&
       static_cast<int>(agreement.least_sure_vertices.size()) < MeasurementAgreement::kListed;
       ++worst) {
    agreement.least_sure_vertices.push_back(worst->second);
  }
  return agreement;
}

void collectMeasurements(const WorkspaceGrid& grid, const std::vector<VertexEstimate>& vertices,
                         std::vector<Eigen::Vector3d>& points_m,
                         std::vector<Eigen::Vector3d>& values_n, std::vector<int>* vertex_of) {
  points_m.clear();
  values_n.clear();
  if (vertex_of != nullptr) vertex_of->clear();
  const int count = std::min(grid.vertexCount(), static_cast<int>(vertices.size()));
  for (int index = 0; index < count; ++index) {
    const VertexEstimate& vertex = vertices[static_cast<std::size_t>(index)];
    if (vertex.outcome != VertexOutcome::kConverged) continue;
    points_m.push_back(vertex.measuredAt_m(grid.vertexPosition(index)));
    values_n.push_back(vertex.measuredGravity_n());
    if (vertex_of != nullptr) vertex_of->push_back(index);
  }
}

}  // namespace autograv
