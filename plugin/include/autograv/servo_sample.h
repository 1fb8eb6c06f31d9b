#pragma once

// Deprecated path, kept for one release: since autograv 0.2.0 this header is
// autograv/device/servo_sample.h. Include that one; this forwarding header goes away in autograv
// 0.3.0 (plugin/CHANGELOG.md).
#pragma message( \
    "autograv/servo_sample.h is deprecated: include autograv/device/servo_sample.h (moved in autograv 0.2.0)")
#include "autograv/device/servo_sample.h"
