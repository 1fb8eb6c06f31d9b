#pragma once

// Deprecated path, kept for one release: since autograv 0.2.0 this header is
// autograv/estimation/pd_design.h. Include that one; this forwarding header goes away in autograv
// 0.3.0 (plugin/CHANGELOG.md).
#pragma message( \
    "autograv/pd_design.h is deprecated: include autograv/estimation/pd_design.h (moved in autograv 0.2.0)")
#include "autograv/estimation/pd_design.h"
