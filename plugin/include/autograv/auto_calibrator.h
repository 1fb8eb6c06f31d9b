#pragma once

// Deprecated path, kept for one release: since autograv 0.2.0 this header is
// autograv/estimation/auto_calibrator.h. Include that one; this forwarding header goes away in
// autograv 0.3.0 (plugin/CHANGELOG.md).
#pragma message( \
    "autograv/auto_calibrator.h is deprecated: include autograv/estimation/auto_calibrator.h (moved in autograv 0.2.0)")
#include "autograv/estimation/auto_calibrator.h"
