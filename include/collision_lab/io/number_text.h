// Numbers typed by people: command-line lists and scenario-file scalars. ROS-free.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace collision_lab {
namespace io {

/// A number read from text, or why it could not be read.
struct ParsedNumber {
  double value = 0.0;
  /// Empty on success, else a short reason for people, e.g. "is not a number".
  std::string problem;
};

/// Reads one decimal (or hexadecimal) floating-point number, as the nearest double.
/// Accepts inf / infinity / nan in any case, with an optional sign, and YAML's .inf / .nan.
/// Rejects empty text, any blank (lists are written without blanks: "1,1,1"), trailing
/// characters, magnitudes beyond a double (1e400 is an error, never silently inf) and
/// nonzero numbers below the smallest subnormal (1e-400 is an error, never silently 0).
ParsedNumber parseNumber(std::string_view text);

/// A count read from text, or why it could not be read.
struct ParsedCount {
  std::uint64_t value = 0;
  /// Empty on success, else "is not a non-negative integer" or "is too large: ...".
  std::string problem;
};

/// Reads a non-negative decimal integer ("10000000"); signs, fractions, exponents and
/// blanks are not integers, and more than 2^64 - 1 is too large (and says so).
ParsedCount parseCount(std::string_view text);

/// Splits "a,b,c" at commas. Items are not trimmed; "1,,2" gives an empty middle item.
std::vector<std::string> splitCommaList(std::string_view text);

}  // namespace io
}  // namespace collision_lab
