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

/// Reads one decimal (or hexadecimal) floating-point number. Surrounding blanks are
/// ignored. Accepts inf / infinity / nan in any case, with an optional sign, and YAML's
/// .inf / .nan. Rejects empty text, trailing characters, and magnitudes beyond a double
/// (1e400 is an error, never silently inf). Underflow rounds towards zero, as C does.
ParsedNumber parseNumber(std::string_view text);

/// Reads a non-negative decimal integer that fits in 64 bits ("10000000"). Returns empty
/// for anything else (signs, fractions, exponents, blanks inside, overflow).
std::optional<std::uint64_t> parseCount(std::string_view text);

/// Splits "a,b,c" at commas. Items are not trimmed; "1,,2" gives an empty middle item.
std::vector<std::string> splitCommaList(std::string_view text);

}  // namespace io
}  // namespace collision_lab
