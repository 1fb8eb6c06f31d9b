#pragma once

#include <string>

#include "chai3d.h"

namespace autograv::chai3d {

/// What to do about gravity compensation the device vendor's SDK applies by itself.
///
/// Force Dimension's SDK (omega.x, delta.x, sigma.x, ...) adds its own model-based gravity
/// compensation to every force command, and it is ON by default. Ours would add on top of it, and a
/// map calibrated with one setting is wrong under the other. kDisable switches the vendor's off
/// (dhdSetGravityCompensation(DHD_OFF)) right after open(), in the calibration adapter and in the
/// bridge alike, so that the map learns, and later adds, the whole apparent gravity.
enum class VendorGravityCompensation {
  kDisable,    ///< Switch the vendor's compensation off after open() (default).
  kLeaveAsIs,  ///< Touch nothing: the application manages it. Use the same state when calibrating.
};

/// True for devices driven by Force Dimension's SDK with its gravity compensation: CHAI3D's
/// cDeltaDevice reports manufacturer "Force Dimension" for all of them.
bool hasVendorGravityCompensation(const ::chai3d::cHapticDeviceInfo& info);

/// Applies `policy` to a device that has just been opened. Returns false and explains in `error`
/// when the vendor compensation should be switched off but cannot be (the SDK call failed, or this
/// build has no access to the Force Dimension SDK). Not real-time safe.
bool applyVendorGravityCompensation(const ::chai3d::cHapticDeviceInfo& info,
                                    VendorGravityCompensation policy, std::string& error);

}  // namespace autograv::chai3d
