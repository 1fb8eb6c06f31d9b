#pragma once

// Deprecated path, kept for one release: since autograv 0.2.0 this header is autograv/map/map_io.h.
// Include that one; this forwarding header goes away in autograv 0.3.0 (plugin/CHANGELOG.md).
#pragma message( \
    "autograv/map_io.h is deprecated: include autograv/map/map_io.h (moved in autograv 0.2.0)")
#include "autograv/map/map_io.h"
