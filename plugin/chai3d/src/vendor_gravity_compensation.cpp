#include "autograv/chai3d/vendor_gravity_compensation.h"

#if defined(AUTOGRAV_CHAI3D_HAVE_DHD)
#include "dhdc.h"
#endif

namespace autograv::chai3d {

bool hasVendorGravityCompensation(const ::chai3d::cHapticDeviceInfo& info) {
  return info.m_manufacturerName == "Force Dimension";
}

bool applyVendorGravityCompensation(const ::chai3d::cHapticDeviceInfo& info,
                                    VendorGravityCompensation policy, std::string& error) {
  error.clear();
  if (policy == VendorGravityCompensation::kLeaveAsIs || !hasVendorGravityCompensation(info)) {
    return true;
  }
#if defined(AUTOGRAV_CHAI3D_HAVE_DHD)
  // ID -1 is the SDK's default device: the one opened last, i.e. this one, since open() was just
  // called. With several Force Dimension devices, open and wrap them one after the other.
  if (dhdSetGravityCompensation(DHD_OFF, -1) < 0) {
    error = "cannot switch off the gravity compensation of the Force Dimension SDK on the " +
            info.m_modelName + " (dhdSetGravityCompensation: " + dhdErrorGetLastStr() +
            "); it would add to autograv's";
    return false;
  }
  return true;
#else
  error = "the " + info.m_modelName +
          " runs Force Dimension's own gravity compensation, which would add to autograv's, and "
          "this build of the bridge cannot call the Force Dimension SDK (dhdc.h was not found in "
          "CHAI3D's externals/DHD/include); call dhdSetGravityCompensation(DHD_OFF) after open() "
          "and use VendorGravityCompensation::kLeaveAsIs";
  return false;
#endif
}

}  // namespace autograv::chai3d
