#pragma once

#include <memory>
#include <string>
#include <utility>

#include <Eigen/Core>

#include "autograv/device/device_specifications.h"
#include "autograv/device/haptic_device.h"
#include "autograv/error.h"

namespace autograv {

/// Base of a decorator that changes a few calls of a HapticDevice and passes the rest through.
///
/// Forwards every virtual method of HapticDevice to the inner device unchanged, arguments and
/// return value alike: open, close, calibrate, getPosition, getLinearVelocity, getUserSwitch,
/// setForce and specifications. A decorator derives from it, overrides only what it changes
/// (calling ForwardingDevice::method or inner() for the rest of the work) and is itself `final`.
/// A method added to HapticDevice must be forwarded here too: then every decorator passes it on.
///
/// Real-time safety: each forwarded call adds one virtual call and nothing else (no allocation, no
/// lock, no throw), so it is exactly as real-time safe as the inner device's call.
///
/// Ownership: shares the inner device, which therefore lives at least as long as the decorator.
class ForwardingDevice : public HapticDevice {
 public:
  /// Not real-time safe.
  bool open() override { return inner_->open(); }
  /// Not real-time safe.
  bool close() override { return inner_->close(); }
  /// Not real-time safe.
  bool calibrate(bool force = false) override { return inner_->calibrate(force); }
  /// Real-time safe when the inner device's is. Unit: [m]
  bool getPosition(Eigen::Vector3d& position_m) override { return inner_->getPosition(position_m); }
  /// Real-time safe when the inner device's is. Unit: [m/s]
  bool getLinearVelocity(Eigen::Vector3d& velocity_m_per_s) override {
    return inner_->getLinearVelocity(velocity_m_per_s);
  }
  /// Real-time safe when the inner device's is.
  bool getUserSwitch(int index, bool& pressed) override {
    return inner_->getUserSwitch(index, pressed);
  }
  /// Real-time safe when the inner device's is. Unit: [N]
  bool setForce(const Eigen::Vector3d& force_n) override { return inner_->setForce(force_n); }
  /// Real-time safe when the inner device's is.
  const DeviceSpecifications& specifications() const override { return inner_->specifications(); }

 protected:
  /// Throws autograv::Error for a null device; the message names `decorator_name`.
  /// Not real-time safe.
  explicit ForwardingDevice(std::shared_ptr<HapticDevice> inner,
                            const char* decorator_name = "ForwardingDevice")
      : inner_(std::move(inner)) {
    if (!inner_) throw Error(std::string(decorator_name) + ": the inner device is null");
  }
  ForwardingDevice(const ForwardingDevice&) = delete;
  ForwardingDevice& operator=(const ForwardingDevice&) = delete;

  /// The decorated device. Real-time safe.
  HapticDevice& inner() noexcept { return *inner_; }
  /// The wrapped device, read-only. Real-time safe.
  const HapticDevice& inner() const noexcept { return *inner_; }

 private:
  std::shared_ptr<HapticDevice> inner_;
};

}  // namespace autograv
