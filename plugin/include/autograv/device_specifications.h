#pragma once

// Deprecated path, kept for one release: since autograv 0.2.0 this header is
// autograv/device/device_specifications.h. Include that one; this forwarding header goes away in
// autograv 0.3.0 (plugin/CHANGELOG.md).
#pragma message( \
    "autograv/device_specifications.h is deprecated: include autograv/device/device_specifications.h (moved in autograv 0.2.0)")
#include "autograv/device/device_specifications.h"
