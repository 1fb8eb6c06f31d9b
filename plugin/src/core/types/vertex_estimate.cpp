#include "autograv/types/vertex_estimate.h"

#include <array>

namespace autograv {

namespace {

struct OutcomeName {
  VertexOutcome outcome;
  const char* name;
};

constexpr std::array<OutcomeName, 8> kOutcomeNames{{
    {VertexOutcome::kPending, "pending"},
    {VertexOutcome::kConverged, "converged"},
    {VertexOutcome::kIterationCap, "iteration_cap"},
    {VertexOutcome::kNoSteadyState, "no_steady_state"},
    {VertexOutcome::kSaturated, "saturated"},
    {VertexOutcome::kDeviceFault, "device_fault"},
    {VertexOutcome::kUnreachable, "unreachable"},
    {VertexOutcome::kLeftOut, "left_out"},
}};

}  // namespace

const char* toString(VertexOutcome outcome) noexcept {
  for (const auto& entry : kOutcomeNames) {
    if (entry.outcome == outcome) return entry.name;
  }
  return "unknown";
}

bool parseVertexOutcome(const std::string& name, VertexOutcome& outcome) noexcept {
  for (const auto& entry : kOutcomeNames) {
    if (name == entry.name) {
      outcome = entry.outcome;
      return true;
    }
  }
  return false;
}

const char* toString(VertexProvenance provenance) noexcept {
  return provenance == VertexProvenance::kFilled ? "filled" : "measured";
}

bool parseVertexProvenance(const std::string& name, VertexProvenance& provenance) noexcept {
  if (name == "measured") {
    provenance = VertexProvenance::kMeasured;
  } else if (name == "filled") {
    provenance = VertexProvenance::kFilled;
  } else {
    return false;
  }
  return true;
}

}  // namespace autograv
