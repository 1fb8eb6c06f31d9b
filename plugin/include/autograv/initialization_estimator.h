#pragma once

// Deprecated path, kept for one release: since autograv 0.2.0 this header is
// autograv/estimation/initialization_estimator.h. Include that one; this forwarding header goes
// away in autograv 0.3.0 (plugin/CHANGELOG.md).
#pragma message( \
    "autograv/initialization_estimator.h is deprecated: include autograv/estimation/initialization_estimator.h (moved in autograv 0.2.0)")
#include "autograv/estimation/initialization_estimator.h"
