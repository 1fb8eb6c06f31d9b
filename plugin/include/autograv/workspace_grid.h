#pragma once

// Deprecated path, kept for one release: since autograv 0.2.0 this header is
// autograv/map/workspace_grid.h. Include that one; this forwarding header goes away in autograv
// 0.3.0 (plugin/CHANGELOG.md).
#pragma message( \
    "autograv/workspace_grid.h is deprecated: include autograv/map/workspace_grid.h (moved in autograv 0.2.0)")
#include "autograv/map/workspace_grid.h"
