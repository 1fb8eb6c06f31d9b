#include "autograv/map/vertex_fill.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
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
// Weight of a measurement made off its vertex relative to the thin-plate terms, both in N after
// scaling by the smallest cell edge squared: the map follows the measurements to a small fraction
// of the field's curvature over a cell, and the smoothness decides only what they leave open.
constexpr double kMeasurementWeight = 100.0;

/// One squared term of the energy: (sum of coefficient * value - target)^2 over up to N vertices.
template <int N>
struct StencilOf {
  std::array<int, N> vertex{};
  std::array<double, N> coefficient{};
  int size = N;
  Eigen::RowVector3d target = Eigen::RowVector3d::Zero();  ///< Unit: [N], scaled as the terms
  void add(int index, double c) {
    vertex[static_cast<std::size_t>(size)] = index;
    coefficient[static_cast<std::size_t>(size)] = c;
    ++size;
  }
};
struct Stencil : StencilOf<4> {
  Stencil() { size = 0; }
};
using Stencil8 = StencilOf<8>;

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

/// The eight trilinear weights of `position_m` in its grid cell (clamped to the grid's box), and
/// the vertices they belong to.
Stencil8 trilinearStencil(const WorkspaceGrid& grid, const Eigen::Vector3d& position_m) {
  const Eigen::Vector3d cells = (position_m - grid.minCorner_m()).cwiseQuotient(grid.spacing_m());
  Eigen::Vector3i cell;
  Eigen::Vector3d fraction;
  for (int a = 0; a < 3; ++a) {
    const int count = grid.resolution()[a];
    const double clamped = std::clamp(cells[a], 0.0, static_cast<double>(count - 1));
    cell[a] = std::min(static_cast<int>(std::floor(clamped)), count - 2);
    fraction[a] = clamped - cell[a];
  }
  Stencil8 stencil;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3i offset(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
    double weight = 1.0;
    for (int a = 0; a < 3; ++a) weight *= offset[a] ? fraction[a] : 1.0 - fraction[a];
    const Eigen::Vector3i c = cell + offset;
    stencil.vertex[static_cast<std::size_t>(corner)] = grid.vertexIndex(c.x(), c.y(), c.z());
    stencil.coefficient[static_cast<std::size_t>(corner)] = weight;
  }
  return stencil;
}

}  // namespace

int fillUnreachableVertices(const WorkspaceGrid& grid, std::vector<VertexEstimate>& vertices) {
  if (static_cast<int>(vertices.size()) != grid.vertexCount()) {
    std::ostringstream message;
    message << "vertex fill: " << vertices.size() << " vertex estimates for a grid of "
            << grid.vertexCount() << " vertices";
    throw Error(message.str());
  }
  const auto measured = [](const VertexEstimate& v) {
    return v.outcome == VertexOutcome::kConverged;
  };
  const auto measured_here = [&](const VertexEstimate& v) {
    return measured(v) && !v.measuredOffVertex();
  };
  const auto to_fill = [&](const VertexEstimate& v) {
    return v.outcome == VertexOutcome::kUnreachable || v.outcome == VertexOutcome::kLeftOut ||
           (measured(v) && v.measuredOffVertex());
  };
  const auto is_known = [&](int index) {
    return measured_here(vertices[static_cast<std::size_t>(index)]);
  };
  const bool any_measured = std::any_of(vertices.begin(), vertices.end(), measured);
  const bool any_to_fill = std::any_of(vertices.begin(), vertices.end(), to_fill);
  if (!any_measured || !any_to_fill) return 0;

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
  const auto add_term = [&](const auto& s) {
    Eigen::RowVector3d known_sum = -s.target;
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
  };
  for (const Stencil& s : energyStencils(grid)) add_term(s);
  // Each measurement made off its vertex: the interpolant there should equal it.
  const double h_min = grid.spacing_m().minCoeff();
  const double measurement_scale = std::sqrt(kMeasurementWeight) / (h_min * h_min);
  for (const VertexEstimate& v : vertices) {
    if (!(measured(v) && v.measuredOffVertex())) continue;
    Stencil8 s = trilinearStencil(grid, v.measured_at_m);
    for (double& c : s.coefficient) c *= measurement_scale;
    s.target = measurement_scale * v.measured_gravity_n.transpose();
    add_term(s);
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
    if (!to_fill(vertex)) continue;
    vertex.gravity_n = solution.row(unknown_of[static_cast<std::size_t>(index)]).transpose();
    vertex.provenance = VertexProvenance::kFilled;
    ++filled;
  }
  return filled;
}

std::vector<Eigen::Vector3d> refinedVertexValues(const WorkspaceGrid& grid,
                                                 const std::vector<VertexEstimate>& vertices,
                                                 int factor) {
  if (factor < 1) throw Error("refinedVertexValues: the factor must be at least 1");
  if (static_cast<int>(vertices.size()) != grid.vertexCount()) {
    throw Error("refinedVertexValues: " + std::to_string(vertices.size()) +
                " vertex estimates for a grid of " + std::to_string(grid.vertexCount()));
  }
  const Eigen::Vector3i resolution = lookupResolution(grid, factor, FieldModel::kThinPlate);
  if (resolution.maxCoeff() > 64) {
    throw Error("refinedVertexValues: " + std::to_string(factor) + " times the cells of " +
                grid.describe() + " exceeds 64 vertices per axis");
  }
  const WorkspaceGrid fine(grid.center_m(), grid.size_m(), resolution);
  // The coarse vertices keep their place and value; the others are solved as if unreachable.
  std::vector<VertexEstimate> slots(static_cast<std::size_t>(fine.vertexCount()));
  for (VertexEstimate& slot : slots) slot.outcome = VertexOutcome::kUnreachable;
  for (int index = 0; index < grid.vertexCount(); ++index) {
    const Eigen::Vector3i at = grid.vertexCoordinates(index) * factor;
    VertexEstimate& slot =
        slots[static_cast<std::size_t>(fine.vertexIndex(at.x(), at.y(), at.z()))];
    const VertexEstimate& vertex = vertices[static_cast<std::size_t>(index)];
    // Measured at the vertex: held; measured off it: a soft measurement; anything else (filled,
    // failed, never visited) is solved from the measurements on the finer grid.
    if (vertex.outcome != VertexOutcome::kConverged) continue;
    slot.outcome = VertexOutcome::kConverged;
    slot.gravity_n = vertex.gravity_n;
    slot.measured_at_m = vertex.measured_at_m;
    slot.measured_gravity_n = vertex.measured_gravity_n;
  }
  fillUnreachableVertices(fine, slots);
  std::vector<Eigen::Vector3d> values;
  values.reserve(slots.size());
  for (const VertexEstimate& slot : slots) values.push_back(slot.gravity_n);
  return values;
}

}  // namespace autograv
