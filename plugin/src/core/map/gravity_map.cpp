#include "autograv/map/gravity_map.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <optional>
#include <sstream>
#include <utility>

#include "autograv/error.h"
#include "autograv/map/field_fit.h"
#include "autograv/map/vertex_fill.h"
#include "core/map/trilinear.h"

namespace autograv {

GravityMap::GravityMap(WorkspaceGrid grid, std::vector<VertexEstimate> vertices,
                       MapMetadata metadata)
    : grid_(std::move(grid)),
      vertices_(std::move(vertices)),
      metadata_(std::move(metadata)),
      lookup_resolution_(grid_.resolution()),
      lookup_min_corner_m_(grid_.minCorner_m()),
      inverse_spacing_per_m_(grid_.spacing_m().cwiseInverse()),
      grid_low_m_(grid_.minCorner_m()),
      grid_high_m_(grid_.minCorner_m() + grid_.size_m()) {
  if (static_cast<int>(vertices_.size()) != grid_.vertexCount()) {
    std::ostringstream message;
    message << "gravity map: " << vertices_.size() << " vertex estimates for a grid of "
            << grid_.vertexCount() << " vertices (" << grid_.describe() << ")";
    throw Error(message.str());
  }
  for (std::size_t i = 0; i < vertices_.size(); ++i) checkEstimate(vertices_[i].gravity_n, i);
  int refinement = metadata_.lookup_refinement;
  if (refinement < 1 || refinement > kMaxLookupRefinement) {
    throw Error("gravity map: MapMetadata::lookup_refinement must lie in 1.." +
                std::to_string(kMaxLookupRefinement) + ", got " + std::to_string(refinement));
  }
  if (!(metadata_.curl_weight >= 0.0 && metadata_.curl_weight <= FieldFit::kMaxCurlWeight)) {
    throw Error("gravity map: MapMetadata::curl_weight must lie in [0, " +
                std::to_string(FieldFit::kMaxCurlWeight) + "], got " +
                std::to_string(metadata_.curl_weight));
  }
  std::optional<FieldFit> fit;
  if (metadata_.field_model != FieldModel::kThinPlate) {
    if (lookupResolution(grid_, refinement, metadata_.field_model).cast<long>().prod() <=
        kMaxLookupVertices) {
      fit = fieldFit();
    }
    if (fit) {
      field_model_ = metadata_.field_model;
      curl_weight_ = fit->curlWeight();
    } else {
      refinement = std::min(refinement, kThinPlateRefinement);
      // A choice that could not be made is no choice: the map is, and is saved as, thin plate.
      if (metadata_.field_model == FieldModel::kChoose) {
        metadata_.field_model = FieldModel::kThinPlate;
      }
    }
  }
  lookup_refinement_ = refinement;
  const Eigen::Vector3i fine = lookupResolution(grid_, refinement, field_model_);
  // The finer grid's values are one solve and a sum per vertex: bounded so that a map file
  // cannot ask for minutes of it.
  const long most_vertices = fit ? kMaxLookupVertices : kMaxThinPlateLookupVertices;
  if ((refinement > 1 || fit) && fine.cast<long>().prod() > most_vertices) {
    throw Error("gravity map: MapMetadata::lookup_refinement " + std::to_string(refinement) +
                " on a grid of " + grid_.describe() + " makes more than " +
                std::to_string(most_vertices) +
                " lookup vertices; use a smaller refinement for so fine a grid");
  }
  std::vector<Eigen::Vector3d> values;
  if (fit) {
    // The values not measured where they stand follow the fit, so that the vertices shown and
    // saved are the field the lookup gives there.
    for (int index = 0; index < grid_.vertexCount(); ++index) {
      VertexEstimate& vertex = vertices_[static_cast<std::size_t>(index)];
      if (vertex.provenance != VertexProvenance::kFilled) continue;
      vertex.gravity_n = fit->at(grid_.vertexPosition(index));
      checkEstimate(vertex.gravity_n, static_cast<std::size_t>(index));
    }
    // The lookup grid reaches one grid cell beyond the box, where the fit still holds far better
    // than a boundary cell's slope: on the simulated devices 8-12 mm outside a 5x5x5 cube the
    // conservative fit errs by 0.2-0.7 % of |G|, the extended slope by 1.2-2.7 %.
    const WorkspaceGrid lookup(grid_.center_m(), grid_.size_m() + 2.0 * grid_.spacing_m(), fine);
    lookup_resolution_ = fine;
    lookup_min_corner_m_ = lookup.minCorner_m();
    inverse_spacing_per_m_ = lookup.spacing_m().cwiseInverse();
    values.reserve(static_cast<std::size_t>(lookup.vertexCount()));
    for (int index = 0; index < lookup.vertexCount(); ++index) {
      values.push_back(fit->at(lookup.vertexPosition(index)));
      checkEstimate(values.back(), static_cast<std::size_t>(index), "lookup vertex");
    }
  } else if (refinement == 1) {
    values.reserve(vertices_.size());
    for (const VertexEstimate& vertex : vertices_) values.push_back(vertex.gravity_n);
  } else {
    lookup_resolution_ = fine;
    inverse_spacing_per_m_ *= refinement;
    values = refinedVertexValues(grid_, vertices_, refinement);
  }
  packed_gravity_n_.reserve(values.size());
  for (const Eigen::Vector3d& gravity_n : values) {
    packed_gravity_n_.emplace_back(gravity_n.x(), gravity_n.y(), gravity_n.z(), 0.0);
  }
}

std::optional<FieldFit> GravityMap::fieldFit() {
  std::vector<Eigen::Vector3d> points_m;
  std::vector<Eigen::Vector3d> values_n;
  collectMeasurements(grid_, vertices_, points_m, values_n);
  const int count = static_cast<int>(points_m.size());
  if (count < FieldFit::kMinMeasurements || count > FieldFit::kMaxMeasurements) return {};
  try {
    if (metadata_.field_model == FieldModel::kChoose) {
      // Set aside what the others contradict beyond the measurements' repeatability.
      const FieldModelChoice choice = chooseFieldModel(
          points_m, values_n, kStandOutRepeatability * metadata_.parameters.eps_g_n);
      metadata_.field_model = choice.model;
      metadata_.curl_weight = choice.model == FieldModel::kCorrected ? choice.curl_weight : 0.0;
      metadata_.field_model_scores = choice.scores;
    } else if (metadata_.field_model == FieldModel::kCorrected && metadata_.curl_weight == 0.0) {
      // The corrected model asked for without its weight: the weight is chosen as a choice
      // would (a weight of 0 would be the conservative fit under another name).
      const FieldModelScore corrected = bestCorrectedScore(points_m, values_n);
      metadata_.curl_weight = corrected.curl_weight;
      metadata_.field_model_scores = {corrected};
    }
    return FieldFit(points_m, values_n, curlWeightOf(metadata_.field_model, metadata_.curl_weight));
  } catch (const Error&) {
    // Measurements on a line determine no fit: the thin-plate lookup still gives a map.
    return {};
  }
}

void GravityMap::checkEstimate(const Eigen::Vector3d& gravity_n, std::size_t index,
                               const char* what) {
  if (!gravity_n.allFinite()) {
    std::ostringstream message;
    message << "gravity map: " << what << " " << index << " has a non-finite gravity estimate";
    throw Error(message.str());
  }
  if (gravity_n.cwiseAbs().maxCoeff() > kMaxGravityEstimate_n) {
    std::ostringstream message;
    message << "gravity map: " << what << " " << index << " has a gravity estimate of ["
            << gravity_n.x() << ", " << gravity_n.y() << ", " << gravity_n.z() << "] N, beyond the "
            << kMaxGravityEstimate_n << " N that any device could need";
    throw Error(message.str());
  }
}

MapMetadata checkpointMetadata(MapMetadata metadata) {
  metadata.lookup_refinement = 1;
  metadata.field_model = FieldModel::kThinPlate;
  metadata.curl_weight = 0.0;
  metadata.field_model_scores.clear();
  return metadata;
}

Eigen::Vector3i lookupResolution(const WorkspaceGrid& grid, int refinement,
                                 FieldModel model) noexcept {
  const int padding = model != FieldModel::kThinPlate ? 2 * refinement : 0;
  return (grid.resolution() - Eigen::Vector3i::Ones()) * refinement +
         Eigen::Vector3i::Constant(1 + padding);
}

int lookupRefinementFor(const WorkspaceGrid& grid, int wanted, FieldModel model) noexcept {
  int refinement = std::clamp(wanted, 1, kMaxLookupRefinement);
  const bool thin_plate =
      model == FieldModel::kThinPlate || grid.vertexCount() > FieldFit::kMaxMeasurements;
  if (thin_plate) refinement = std::min(refinement, kThinPlateRefinement);
  const FieldModel read = thin_plate ? FieldModel::kThinPlate : model;
  const long most_vertices = thin_plate ? kToolsThinPlateLookupVertices : kMaxLookupVertices;
  for (; refinement > 1; --refinement) {
    if (lookupResolution(grid, refinement, read).cast<long>().prod() <= most_vertices) break;
  }
  return refinement;
}

Eigen::Vector3d GravityMap::gravityAt(const Eigen::Vector3d& position_m) const noexcept {
  const Eigen::Vector3d cells =
      (position_m - lookup_min_corner_m_).cwiseProduct(inverse_spacing_per_m_);
  return detail::interpolateTrilinear(lookup_resolution_, cells, packed_gravity_n_.data());
}

Eigen::Vector3d GravityMap::gravityAt(const Eigen::Vector3d& position_m, double margin_m,
                                      bool& inside) const noexcept {
  // Against the calibration grid's box, not the lookup grid's (which may reach beyond it).
  inside = (position_m.array() >= grid_low_m_.array() - margin_m).all() &&
           (position_m.array() <= grid_high_m_.array() + margin_m).all();
  return gravityAt(position_m);
}

int GravityMap::convergedCount() const noexcept {
  return static_cast<int>(std::count_if(vertices_.begin(), vertices_.end(), [](const auto& v) {
    return v.outcome == VertexOutcome::kConverged;
  }));
}

bool GravityMap::isComplete() const noexcept {
  return std::all_of(vertices_.begin(), vertices_.end(), [](const auto& v) {
    return v.outcome == VertexOutcome::kConverged ||
           ((v.outcome == VertexOutcome::kUnreachable || v.outcome == VertexOutcome::kLeftOut) &&
            v.provenance == VertexProvenance::kFilled);
  });
}

int GravityMap::unreachableCount() const noexcept {
  return static_cast<int>(std::count_if(vertices_.begin(), vertices_.end(), [](const auto& v) {
    return v.outcome == VertexOutcome::kUnreachable;
  }));
}

int GravityMap::filledCount() const noexcept {
  return static_cast<int>(std::count_if(vertices_.begin(), vertices_.end(), [](const auto& v) {
    return v.provenance == VertexProvenance::kFilled;
  }));
}

}  // namespace autograv
