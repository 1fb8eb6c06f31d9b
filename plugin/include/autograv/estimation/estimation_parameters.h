#pragma once

/// \file
/// The estimation's parameters (EstimationParameters, EstimationMethod, kStandardGravity) are
/// defined in autograv/types/estimation_parameters.h, below both the estimation and the map
/// (every map records the parameters it was made with); this path names them by their use.
#include "autograv/types/estimation_parameters.h"
