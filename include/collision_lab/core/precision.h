// The floating types of the three-body closed form in one place: 50 digits where double's
// range does not reach, and the tiers a decision escalates to when a narrower type cannot
// take it (analytic.h). Every run is simulated by the exact event engine (nbody/engine.h),
// which has its own tiers (nbody/tier.h).
#pragma once

#include <cstdint>

#include <boost/multiprecision/cpp_bin_float.hpp>

namespace collision_lab {
namespace core {

/// 50 decimal digits, header-only: the closed form's type where double's exponent range
/// does not reach (analytic.h).
using HighPrecision = boost::multiprecision::cpp_bin_float_50;

// ---- escalation tiers, above 50 digits ----

/// First tier: 100 digits, for the closed-form state (or a short replay) when the working
/// precision cannot tell a sign, and for resynchronizing long runs.
using ReplayPrecision = boost::multiprecision::cpp_bin_float_100;

/// Last floating tier: 500 digits, for masses that span more than ~1e100 and for long runs
/// beyond the exact replay's reach.
using DeepPrecision = boost::multiprecision::number<boost::multiprecision::cpp_bin_float<500>>;

/// Longest run (impacts) an exact rational replay is attempted for: its cost grows
/// about quadratically. Beyond it 500 digits decide, and a zero to 500 digits counts as
/// zero.
constexpr std::uint64_t kExactReplayLimit = 20000;

/// Longest run (impacts) the predicted count is found by exact simulation for, when
/// not even 500 digits can place the start in the wedge (analytic.h).
constexpr std::uint64_t kExactCountLimit = 2000;

}  // namespace core
}  // namespace collision_lab
