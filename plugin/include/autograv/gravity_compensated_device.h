#pragma once

// Deprecated path, kept for one release: since autograv 0.2.0 this header is
// autograv/compensation/gravity_compensated_device.h. Include that one; this forwarding header goes
// away in autograv 0.3.0 (plugin/CHANGELOG.md).
#pragma message( \
    "autograv/gravity_compensated_device.h is deprecated: include autograv/compensation/gravity_compensated_device.h (moved in autograv 0.2.0)")
#include "autograv/compensation/gravity_compensated_device.h"
