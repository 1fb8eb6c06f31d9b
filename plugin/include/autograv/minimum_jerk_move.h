#pragma once

// Deprecated path, kept for one release: since autograv 0.2.0 this header is
// autograv/estimation/minimum_jerk_move.h. Include that one; this forwarding header goes away in
// autograv 0.3.0 (plugin/CHANGELOG.md).
#pragma message( \
    "autograv/minimum_jerk_move.h is deprecated: include autograv/estimation/minimum_jerk_move.h (moved in autograv 0.2.0)")
#include "autograv/estimation/minimum_jerk_move.h"
