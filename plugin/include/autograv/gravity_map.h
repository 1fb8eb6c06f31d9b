#pragma once

// Deprecated path, kept for one release: since autograv 0.2.0 this header is
// autograv/map/gravity_map.h. Include that one; this forwarding header goes away in autograv 0.3.0
// (plugin/CHANGELOG.md).
#pragma message( \
    "autograv/gravity_map.h is deprecated: include autograv/map/gravity_map.h (moved in autograv 0.2.0)")
#include "autograv/map/gravity_map.h"
