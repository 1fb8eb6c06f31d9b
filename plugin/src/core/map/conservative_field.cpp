#include "autograv/map/conservative_field.h"

#include <algorithm>
#include <string>
#include <utility>

#include <Eigen/LU>

#include "autograv/error.h"

namespace autograv {

namespace {

constexpr int kPolynomialTerms = 9;
// Ridge on the kernel block, relative to the largest kernel entry: keeps the solve regular when
// two points nearly coincide and moves no measurement by a measurable amount.
constexpr double kRelativeRidge = 1e-9;

/// The Hessian of |v|^5: the 3x3 block that ties a gradient measured at one point to the
/// gradient at another, v apart (scaled units).
Eigen::Matrix3d kernelBlock(const Eigen::Vector3d& v) noexcept {
  const double r = v.norm();
  return 5.0 * r * (r * r * Eigen::Matrix3d::Identity() + 3.0 * v * v.transpose());
}

/// Gradients of the quadratic potential's terms x, y, z, x^2, y^2, z^2, xy, xz, yz at v.
Eigen::Matrix<double, 3, kPolynomialTerms> polynomialBlock(const Eigen::Vector3d& v) noexcept {
  Eigen::Matrix<double, 3, kPolynomialTerms> block =
      Eigen::Matrix<double, 3, kPolynomialTerms>::Zero();
  block.leftCols<3>().setIdentity();
  for (int a = 0; a < 3; ++a) block(a, 3 + a) = 2.0 * v[a];
  block(0, 6) = v.y();
  block(1, 6) = v.x();
  block(0, 7) = v.z();
  block(2, 7) = v.x();
  block(1, 8) = v.z();
  block(2, 8) = v.y();
  return block;
}

/// The fit's linear system in scaled coordinates: the kernel blocks between every pair of
/// measurements, bordered by the quadratic potential's gradients, with the measured values on the
/// right (kernel weights first, three per point, then the nine polynomial weights).
struct FitSystem {
  Eigen::Vector3d origin_m = Eigen::Vector3d::Zero();
  double scale_per_m = 1.0;
  std::vector<Eigen::Vector3d> points;  ///< Scaled.
  Eigen::MatrixXd matrix;
  Eigen::VectorXd rhs;
};

FitSystem buildSystem(const std::vector<Eigen::Vector3d>& points_m,
                      const std::vector<Eigen::Vector3d>& values_n) {
  if (points_m.size() != values_n.size()) {
    throw Error("conservative field fit: " + std::to_string(points_m.size()) + " points but " +
                std::to_string(values_n.size()) + " values");
  }
  const int n = static_cast<int>(points_m.size());
  if (n > ConservativeFieldFit::kMaxMeasurements) {
    throw Error("conservative field fit: " + std::to_string(n) +
                " measurements; it takes at most " +
                std::to_string(ConservativeFieldFit::kMaxMeasurements));
  }
  if (n < ConservativeFieldFit::kMinMeasurements) {
    throw Error("conservative field fit: " + std::to_string(n) +
                " measurements; it needs at least " +
                std::to_string(ConservativeFieldFit::kMinMeasurements));
  }
  for (int i = 0; i < n; ++i) {
    const auto at = static_cast<std::size_t>(i);
    if (!points_m[at].allFinite() || !values_n[at].allFinite()) {
      throw Error("conservative field fit: measurement " + std::to_string(i) + " is not finite");
    }
  }
  FitSystem fit;
  for (const Eigen::Vector3d& p : points_m) fit.origin_m += p;
  fit.origin_m /= n;
  double extent_m = 0.0;
  for (const Eigen::Vector3d& p : points_m)
    extent_m = std::max(extent_m, (p - fit.origin_m).norm());
  if (!(extent_m > 0.0)) throw Error("conservative field fit: every measurement is at one point");
  fit.scale_per_m = 1.0 / extent_m;
  fit.points.reserve(points_m.size());
  for (const Eigen::Vector3d& p : points_m)
    fit.points.push_back((p - fit.origin_m) * fit.scale_per_m);

  const int size = 3 * n + kPolynomialTerms;
  fit.matrix = Eigen::MatrixXd::Zero(size, size);
  fit.rhs = Eigen::VectorXd::Zero(size);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d& xi = fit.points[static_cast<std::size_t>(i)];
    for (int j = 0; j < n; ++j) {
      fit.matrix.block<3, 3>(3 * i, 3 * j) =
          kernelBlock(xi - fit.points[static_cast<std::size_t>(j)]);
    }
    const auto polynomial = polynomialBlock(xi);
    fit.matrix.block<3, kPolynomialTerms>(3 * i, 3 * n) = polynomial;
    fit.matrix.block<kPolynomialTerms, 3>(3 * n, 3 * i) = polynomial.transpose();
    fit.rhs.segment<3>(3 * i) = values_n[static_cast<std::size_t>(i)];
  }
  const double ridge =
      kRelativeRidge * fit.matrix.topLeftCorner(3 * n, 3 * n).cwiseAbs().maxCoeff();
  fit.matrix.topLeftCorner(3 * n, 3 * n).diagonal().array() += ridge;
  return fit;
}

/// Solves `fit`, and refuses a system its points leave singular: points on a line leave the
/// quadratic potential undetermined, which shows as a solution that is not finite or does not
/// solve the system.
Eigen::VectorXd solveSystem(const FitSystem& fit, const Eigen::PartialPivLU<Eigen::MatrixXd>& lu) {
  const Eigen::VectorXd solution = lu.solve(fit.rhs);
  const double residual = (fit.matrix * solution - fit.rhs).norm();
  if (!solution.allFinite() || !(residual <= 1e-8 * std::max(fit.rhs.norm(), 1e-300))) {
    throw Error("conservative field fit: the " + std::to_string(fit.points.size()) +
                " measurement points do not determine the field (they lie on a line, or "
                "coincide)");
  }
  return solution;
}

}  // namespace

ConservativeFieldFit::ConservativeFieldFit(const std::vector<Eigen::Vector3d>& points_m,
                                           const std::vector<Eigen::Vector3d>& values_n) {
  FitSystem fit = buildSystem(points_m, values_n);
  const Eigen::VectorXd solution =
      solveSystem(fit, Eigen::PartialPivLU<Eigen::MatrixXd>(fit.matrix));
  origin_m_ = fit.origin_m;
  scale_per_m_ = fit.scale_per_m;
  points_ = std::move(fit.points);
  kernel_weights_ = solution.head(3 * measurementCount());
  polynomial_weights_ = solution.tail(kPolynomialTerms);
}

std::vector<Eigen::Vector3d> leaveOneOutResiduals_n(const std::vector<Eigen::Vector3d>& points_m,
                                                    const std::vector<Eigen::Vector3d>& values_n) {
  const FitSystem fit = buildSystem(points_m, values_n);
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
      throw Error("conservative field fit: measurement " + std::to_string(i) +
                  " cannot be left out: the others do not determine the field");
    }
    residuals_n.push_back(residual_n);
  }
  return residuals_n;
}

Eigen::Vector3d ConservativeFieldFit::scaled(const Eigen::Vector3d& position_m) const noexcept {
  return (position_m - origin_m_) * scale_per_m_;
}

Eigen::Vector3d ConservativeFieldFit::at(const Eigen::Vector3d& position_m) const noexcept {
  const Eigen::Vector3d v = scaled(position_m);
  Eigen::Vector3d value_n = polynomialBlock(v) * polynomial_weights_;
  for (std::size_t j = 0; j < points_.size(); ++j) {
    value_n += kernelBlock(v - points_[j]) * kernel_weights_.segment<3>(3 * static_cast<int>(j));
  }
  return value_n;
}

MeasurementAgreement measurementAgreement(const WorkspaceGrid& grid,
                                          const std::vector<VertexEstimate>& vertices) {
  std::vector<Eigen::Vector3d> points_m;
  std::vector<Eigen::Vector3d> values_n;
  std::vector<int> vertex_of;
  collectMeasurements(grid, vertices, points_m, values_n, &vertex_of);
  const std::vector<Eigen::Vector3d> residuals_n = leaveOneOutResiduals_n(points_m, values_n);
  std::vector<std::pair<double, int>> ratios;  // |residual| / |G_hat|, vertex
  for (std::size_t k = 0; k < residuals_n.size(); ++k) {
    ratios.emplace_back(residuals_n[k].norm() / std::max(values_n[k].norm(), 1e-12), vertex_of[k]);
  }
  std::sort(ratios.begin(), ratios.end());
  const auto quantile = [&ratios](double q) {
    return ratios[static_cast<std::size_t>(q * static_cast<double>(ratios.size() - 1))].first;
  };
  MeasurementAgreement agreement;
  agreement.measurements = static_cast<int>(ratios.size());
  agreement.median_rel = quantile(0.5);
  agreement.p90_rel = quantile(0.9);
  agreement.max_rel = ratios.back().first;
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
