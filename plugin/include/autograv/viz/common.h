#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include <Eigen/Core>

namespace autograv::viz {

/// Ground-truth apparent gravity G(X) of a device, e.g. a simulated device's trueGravity.
/// Argument unit: [m]; result unit: [N].
using GroundTruth = std::function<Eigen::Vector3d(const Eigen::Vector3d&)>;

/// Whether a device can reach a position, e.g. a simulated device's isReachable: where the
/// ground truth may be asked. Argument unit: [m].
using Reachability = std::function<bool(const Eigen::Vector3d&)>;

/// Background of rendered scenes and plots; text and lines take the contrasting colour.
enum class Background : std::uint8_t { kWhite, kDark };

/// Colour maps for scalar fields. Viridis is the default: perceptually uniform and readable by
/// colour-blind users.
enum class ColorMap : std::uint8_t { kViridis, kCoolWarm, kGrayscale };

/// "white", "dark". Real-time safe.
const char* toString(Background background) noexcept;
/// Inverse of toString; false for an unknown name. Real-time safe.
bool parseBackground(const std::string& name, Background& background) noexcept;
/// "viridis", "coolwarm", "grayscale". Real-time safe.
const char* toString(ColorMap color_map) noexcept;
/// Inverse of toString; false for an unknown name. Real-time safe.
bool parseColorMap(const std::string& name, ColorMap& color_map) noexcept;

/// True when an X display can be opened. Debian's VTK 9.1 renders through X even offscreen, so
/// every render needs one (a real one or `xvfb-run -a`). When false, `reason` (if given) says why
/// and what to do. Not real-time safe.
bool displayAvailable(std::string* reason = nullptr);

/// Throws autograv::Error with the reason of displayAvailable() when no display can be opened.
/// Every render function calls it first, so a missing display fails at once with a clear
/// message instead of aborting inside VTK. Not real-time safe.
void requireDisplay();

}  // namespace autograv::viz
