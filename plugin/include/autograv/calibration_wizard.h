#pragma once

// Deprecated path, kept for one release: since autograv 0.2.0 this header is
// autograv/wizard/calibration_wizard.h. Include that one; this forwarding header goes away in
// autograv 0.3.0 (plugin/CHANGELOG.md).
#pragma message( \
    "autograv/calibration_wizard.h is deprecated: include autograv/wizard/calibration_wizard.h (moved in autograv 0.2.0)")
#include "autograv/wizard/calibration_wizard.h"
