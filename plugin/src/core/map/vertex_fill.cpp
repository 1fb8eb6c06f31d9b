#include "autograv/map/vertex_fill.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include "autograv/error.h"

namespace autograv {

namespace {

// Weight of the membrane (first-difference) term relative to the thin-plate terms: small enough
// not to bend an affine field measurably, large enough to make the system positive definite
// whatever the measured set.
constexpr double kMembraneWeight = 1e-9;

/// One squared term of the energy: weight * (sum of coefficient * value)^2 over up to 4 vertices.
struct Stencil {
  std::array<int, 4> vertex{};
  std::array<double, 4> coefficient{};
  int size = 0;
  void add(int index, double c) {
    vertex[static_cast<std::size_t>(size)] = index;
    coefficient[static_cast<std::size_t>(size)] = c;
    ++size;
  }
};

/// Every term of the energy on `grid`, scaled so that each is a derivative estimate in
/// consistent units (second differences over h^2, mixed over ha hb, first over h times the
/// smallest cell edge).
std::vector<Stencil> energyStencils(const WorkspaceGrid& grid) {
  const Eigen::Vector3d h = grid.spacing_m();
  const double h_min = h.minCoeff();
  std::vector<Stencil> stencils;
  for (int index = 0; index < grid.vertexCount(); ++index) {
    const Eigen::Vector3i here = grid.vertexCoordinates(index);
    const auto at = [&](const Eigen::Vector3i& c) { return grid.vertexIndex(c.x(), c.y(), c.z()); };
    for (int a = 0; a < 3; ++a) {
      const Eigen::Vector3i step_a = Eigen::Vector3i::Unit(a);
      // Second difference centred here along a.
      if (grid.hasVertex(here - step_a) && grid.hasVertex(here + step_a)) {
        Stencil s;
        const double c = 1.0 / (h[a] * h[a]);
        s.add(at(here - step_a), c);
        s.add(index, -2.0 * c);
        s.add(at(here + step_a), c);
        stencils.push_back(s);
      }
      if (!grid.hasVertex(here + step_a)) continue;
      // First difference towards +a (the vanishing membrane term).
      {
        Stencil s;
        const double c = std::sqrt(kMembraneWeight) / (h[a] * h_min);
        s.add(index, -c);
        s.add(at(here + step_a), c);
        stencils.push_back(s);
      }
      // Mixed difference across the cell face spanned by +a and +b.
      for (int b = a + 1; b < 3; ++b) {
        const Eigen::Vector3i step_b = Eigen::Vector3i::Unit(b);
        if (!grid.hasVertex(here + step_b)) continue;
        Stencil s;
        const double c = 1.0 / (h[a] * h[b]);
        s.add(index, c);
        s.add(at(here + step_a), -c);
        s.add(at(here + step_b), -c);
        s.add(at(here + step_a + step_b), c);
        stencils.push_back(s);
      }
    }
  }
  return stencils;
}

}  // namespace

int fillUnreachableVertices(const WorkspaceGrid& grid, std::vector<VertexEstimate>& vertices) {
  if (static_cast<int>(vertices.size()) != grid.vertexCount()) {
    std::ostringstream message;
    message << "vertex fill: " << vertices.size() << " vertex estimates for a grid of "
            << grid.vertexCount() << " vertices";
    throw Error(message.str());
  }
  const auto is_known = [&](int index) {
    return vertices[static_cast<std::size_t>(index)].outcome == VertexOutcome::kConverged;
  };
  const bool any_known = std::any_of(vertices.begin(), vertices.end(), [](const auto& v) {
    return v.outcome == VertexOutcome::kConverged;
  });
  const bool any_to_fill = std::any_of(vertices.begin(), vertices.end(), [](const auto& v) {
    return v.outcome == VertexOutcome::kUnreachable;
  });
  if (!any_known || !any_to_fill) return 0;

  // Unknowns: every vertex that is not converged (a failed vertex's value is not trusted as data
  // either), numbered densely.
  std::vector<int> unknown_of(vertices.size(), -1);
  int unknown_count = 0;
  for (int index = 0; index < grid.vertexCount(); ++index) {
    if (!is_known(index)) unknown_of[static_cast<std::size_t>(index)] = unknown_count++;
  }

  // Normal equations of the quadratic energy in the unknowns: H x = r, one column per force axis.
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(unknown_count, 3);
  for (const Stencil& s : energyStencils(grid)) {
    Eigen::RowVector3d known_sum = Eigen::RowVector3d::Zero();
    for (int k = 0; k < s.size; ++k) {
      const int vertex = s.vertex[static_cast<std::size_t>(k)];
      if (is_known(vertex)) {
        known_sum += s.coefficient[static_cast<std::size_t>(k)] *
                     vertices[static_cast<std::size_t>(vertex)].gravity_n.transpose();
      }
    }
    for (int k = 0; k < s.size; ++k) {
      const int row = unknown_of[static_cast<std::size_t>(s.vertex[static_cast<std::size_t>(k)])];
      if (row < 0) continue;
      const double ck = s.coefficient[static_cast<std::size_t>(k)];
      rhs.row(row) -= ck * known_sum;
      for (int l = 0; l < s.size; ++l) {
        const int column =
            unknown_of[static_cast<std::size_t>(s.vertex[static_cast<std::size_t>(l)])];
        if (column >= 0)
          triplets.emplace_back(row, column, ck * s.coefficient[static_cast<std::size_t>(l)]);
      }
    }
  }
  Eigen::SparseMatrix<double> hessian(unknown_count, unknown_count);
  hessian.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(hessian);
  if (solver.info() != Eigen::Success) {
    throw Error("vertex fill: the smoothness system could not be factorised (grid " +
                grid.describe() + ")");
  }
  const Eigen::MatrixXd solution = solver.solve(rhs);
  if (solver.info() != Eigen::Success || !solution.allFinite()) {
    throw Error("vertex fill: the smoothness system has no finite solution (grid " +
                grid.describe() + ")");
  }

  int filled = 0;
  for (int index = 0; index < grid.vertexCount(); ++index) {
    VertexEstimate& vertex = vertices[static_cast<std::size_t>(index)];
    if (vertex.outcome != VertexOutcome::kUnreachable) continue;
    vertex.gravity_n = solution.row(unknown_of[static_cast<std::size_t>(index)]).transpose();
    vertex.provenance = VertexProvenance::kFilled;
    ++filled;
  }
  return filled;
}

}  // namespace autograv
