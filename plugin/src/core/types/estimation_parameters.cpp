#include "autograv/types/estimation_parameters.h"

#include "autograv/error.h"

namespace autograv {

const char* toString(EstimationMethod method) noexcept {
  if (method == EstimationMethod::kPaper) return "paper";
  if (method == EstimationMethod::kDither) return "dither";
  return "unknown";
}

EstimationMethod parseEstimationMethod(const std::string& name) {
  for (const EstimationMethod method : {EstimationMethod::kPaper, EstimationMethod::kDither}) {
    if (name == toString(method)) return method;
  }
  throw Error("unknown estimation method '" + name + "'; valid: paper, dither");
}

}  // namespace autograv
