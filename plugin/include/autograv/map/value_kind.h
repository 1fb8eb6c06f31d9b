#pragma once

#include <cstdint>

#include "autograv/map/gravity_map.h"

namespace autograv {

/// Where a vertex's value comes from, in the words every tool shows (inspect, the scene's legend,
/// the real-time view): one definition, so that they never disagree.
enum class ValueKind : std::uint8_t {
  kNone,       ///< No value to trust yet: not visited, or visited and not converged.
  kAtVertex,   ///< Measured at the vertex itself (converged there).
  kOffVertex,  ///< Measured just inside the stops for a vertex beyond them (measured_at_m,
               ///< converged there); the vertex's value is solved from every measurement.
  kSolved,     ///< Not measured (out of reach, or its point inside the stops could not be
               ///< held): solved from the measurements around it.
};

/// The kind of `vertex`'s value. Real-time safe.
inline ValueKind valueKind(const VertexEstimate& vertex) noexcept {
  const bool converged = vertex.outcome == VertexOutcome::kConverged;
  // A point inside the stops that could not be held gave no measurement (fillUnreachableVertices
  // uses converged ones only).
  if (vertex.measuredOffVertex() && converged) return ValueKind::kOffVertex;
  if (vertex.provenance == VertexProvenance::kFilled) return ValueKind::kSolved;
  if (vertex.measuredOffVertex()) return ValueKind::kNone;
  return converged ? ValueKind::kAtVertex : ValueKind::kNone;
}

/// "none", "at vertex", "off vertex", "solved". Real-time safe.
inline const char* toString(ValueKind kind) noexcept {
  switch (kind) {
    case ValueKind::kAtVertex:
      return "at vertex";
    case ValueKind::kOffVertex:
      return "off vertex";
    case ValueKind::kSolved:
      return "solved";
    case ValueKind::kNone:
      break;
  }
  return "none";
}

}  // namespace autograv
