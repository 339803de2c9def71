// The view model's style, which the rviz markers and the page share: numbers in one
// written style, the bodies' colours and the colour of a velocity. Draws nothing (no
// marker types).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "collision_lab/ros/run_record.h"

namespace collision_lab_ros::markers {

/// A colour, 0..1 per channel.
struct Rgba {
  double r, g, b, a = 1.0;
};

namespace layout {

// ---- colours ----
/// Bodies' colours: A, B, C as always, then more for up to kMaxPlottedBodies bodies.
constexpr std::size_t kPaletteSize = 10;
/// Each keeps a contrast of at least 3:1 (WCAG, relative luminance 0.23 to 0.28) on the
/// page's white and on rviz's dark grey background alike.
constexpr Rgba kParticleRgb[kPaletteSize] = {
    {0.95, 0.25, 0.25}, {0.19, 0.63, 0.23}, {0.3, 0.55, 1.0},   {0.7, 0.52, 0.13},  {0.7, 0.42, 0.93},
    {0.13, 0.61, 0.61}, {0.82, 0.41, 0.62}, {0.47, 0.59, 0.17}, {0.82, 0.45, 0.24}, {0.52, 0.52, 0.82}};
/// The diverging colour map of velocity: its ends, and purple at rest, seen on rviz's dark
/// background and on the page's white one alike (white at rest vanished on the page).
constexpr Rgba kSlowBlue{0.2, 0.4, 1.0};
constexpr Rgba kFastRed{1.0, 0.2, 0.15};
constexpr Rgba kRestPurple{0.62, 0.42, 0.72};
constexpr Rgba kWhite{0.95, 0.95, 0.95};
constexpr Rgba kGrey{0.6, 0.6, 0.6};
/// Small grey text lighter than lines: rviz draws a minus sign one pixel thin.
constexpr Rgba kLabelGrey{0.8, 0.8, 0.8};
constexpr Rgba kAmber{1.0, 0.75, 0.2};
constexpr Rgba kPaper{1.0, 0.55, 0.9};
constexpr Rgba kPredicted{0.8, 0.5, 1.0};
constexpr Rgba kCursorWhite{1, 1, 1, 0.5};
constexpr Rgba kConeFill{1.0, 0.85, 0.2, 0.3};
constexpr Rgba kConeYellow{1.0, 0.85, 0.2};
constexpr Rgba kPathOrange{1.0, 0.55, 0.1, 0.8};
constexpr Rgba kSimulatedOrange{1.0, 0.55, 0.1};
constexpr Rgba kBannerRed{1.0, 0.35, 0.35};
/// How much lighter than its body a body's text is (0: same, 1: white).
constexpr double kTagLighten = 0.3;
/// How much lighter than its series a closed form's dot is.
constexpr double kDotLighten = 0.6;

}  // namespace layout

/// value printed by fmt (one printf conversion: %g, %e or %f, with text around it) in one
/// number style with the page: "4.68×10^11", "169,548".
std::string format(const char* fmt, double value);
/// 31415 -> "31,415".
std::string withSeparators(std::uint64_t n);
/// Largest |v| [m/s] of the finite bodies at the start (1 when all are at rest): the
/// scale of the colour by velocity (RunView::colour_scale).
double velocityScale(const RunRecord& run);
/// Velocity v [m/s] on a diverging map: blue at -v_max, purple at 0, red at +v_max
/// (clipped beyond).
Rgba velocityRgb(double v, double v_max);

}  // namespace collision_lab_ros::markers
