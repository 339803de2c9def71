// Numbers typed by people (command-line lists, scenario-file scalars) and numbers printed
// for programs (CSV and JSON reports). ROS-free.
#pragma once

#include <cstddef>
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

/// Room that writeCsvNumber and writeJsonNumber need at `out` (the longest text is 24
/// characters, e.g. -2.2250738585072014e-308 or -0.00012345678901234567).
constexpr std::size_t kNumberTextMax = 32;

/// A double for a CSV cell: the shortest decimal text that reads back (strtod) to the same
/// double, laid out as std::to_chars does (fixed or exponent form, whichever is shorter:
/// 0.5, 1e+12); 0 for either zero; nan for any NaN; inf and -inf. Returns the end.
char* writeCsvNumber(char* out, double value);

/// A double for JSON, laid out as nlohmann::json dumps doubles (fixed form from 1e-4 up to
/// 1e15 with a fraction always shown, as in 2.0 or 1000000000000.0; else 1.5e-05, 1e+15)
/// but with the shortest digits that read back to the same double; 0.0 for either zero;
/// null for NaN and infinities. Returns the end.
char* writeJsonNumber(char* out, double value);

/// Splits "a,b,c" at commas. Items are not trimmed; "1,,2" gives an empty middle item.
std::vector<std::string> splitCommaList(std::string_view text);

}  // namespace io
}  // namespace collision_lab
