#pragma once

// Deprecated path, kept for one release: since autograv 0.2.0 this header is
// autograv/estimation/steady_state_detector.h. Include that one; this forwarding header goes away
// in autograv 0.3.0 (plugin/CHANGELOG.md).
#pragma message( \
    "autograv/steady_state_detector.h is deprecated: include autograv/estimation/steady_state_detector.h (moved in autograv 0.2.0)")
#include "autograv/estimation/steady_state_detector.h"
