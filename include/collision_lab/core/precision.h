// Every precision of the three-body core in one place: the working precisions a run can
// choose (and their names), and the tiers a decision escalates to when the working
// precision cannot take it (see simulation.h and analytic.h).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <boost/multiprecision/cpp_bin_float.hpp>

namespace collision_lab {
namespace core {

// ---- working precisions ----

/// The high-precision working type: 50 decimal digits, header-only.
using HighPrecision = boost::multiprecision::cpp_bin_float_50;

/// Runtime choice of the working precision: double, long double or HighPrecision.
enum class Precision { kDouble, kLongDouble, kHigh };

/// "double", "long_double" or "high": the names of the CLI, the scenario files and the
/// ROS parameters.
inline const char* precisionName(Precision p) {
  switch (p) {
    case Precision::kDouble: return "double";
    case Precision::kLongDouble: return "long_double";
    case Precision::kHigh: return "high";
  }
  return "unknown";
}

/// The precision named `name` (precisionName's spelling); empty for any other text.
inline std::optional<Precision> parsePrecision(const std::string& name) {
  for (Precision p : {Precision::kDouble, Precision::kLongDouble, Precision::kHigh}) {
    if (name == precisionName(p)) return p;
  }
  return std::nullopt;
}

// ---- escalation tiers, above every working precision ----

/// First tier: 100 digits, for the closed-form state (or a short replay) when the working
/// precision cannot tell a sign, and for resynchronizing long runs.
using ReplayPrecision = boost::multiprecision::cpp_bin_float_100;

/// Last floating tier: 500 digits, for masses that span more than ~1e100 and for long runs
/// beyond the exact replay's reach.
using DeepPrecision = boost::multiprecision::number<boost::multiprecision::cpp_bin_float<500>>;

/// Longest run (collisions) an exact rational replay is attempted for: its cost grows
/// about quadratically. Beyond it 500 digits decide, and a zero to 500 digits counts as
/// zero.
constexpr std::uint64_t kExactReplayLimit = 20000;

/// Longest run (collisions) the predicted count is found by exact simulation for, when
/// not even 500 digits can place the start in the wedge (analytic.h).
constexpr std::uint64_t kExactCountLimit = 2000;

}  // namespace core
}  // namespace collision_lab
