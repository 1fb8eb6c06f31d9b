#pragma once

namespace autograv {

/// The longest gravity arrow of a picture of a map, as a fraction of the grid spacing: long
/// enough to read, short enough that the arrows of neighbouring vertices never touch.
inline constexpr double kLongestArrowFraction = 0.8;

/// The length rule of the gravity arrows in every picture of a map (the VTK scene and the
/// real-time renderer): length per newton such that `longest_force_n` is drawn
/// kLongestArrowFraction of `spacing` long. The result is in the unit of `spacing` per newton;
/// 0 when `longest_force_n` is not above 0. Real-time safe.
constexpr double arrowLengthPerNewton(double spacing, double longest_force_n) noexcept {
  return longest_force_n > 0.0 ? kLongestArrowFraction * spacing / longest_force_n : 0.0;
}

}  // namespace autograv
