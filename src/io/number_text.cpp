#include "collision_lab/io/number_text.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>

namespace collision_lab {
namespace io {

namespace {

std::string_view trimBlanks(std::string_view text) {
  const auto is_blank = [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; };
  while (!text.empty() && is_blank(text.front())) text.remove_prefix(1);
  while (!text.empty() && is_blank(text.back())) text.remove_suffix(1);
  return text;
}

std::string lowerCase(std::string_view text) {
  std::string out(text);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

/// YAML 1.2 spellings of the special values, which strtod does not know.
std::optional<double> yamlSpecialValue(const std::string& lower) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  if (lower == ".inf" || lower == "+.inf") return kInf;
  if (lower == "-.inf") return -kInf;
  if (lower == ".nan") return std::numeric_limits<double>::quiet_NaN();
  return std::nullopt;
}

}  // namespace

ParsedNumber parseNumber(std::string_view text) {
  const std::string_view trimmed = trimBlanks(text);
  if (trimmed.empty()) return {0.0, "is empty"};
  const std::string lower = lowerCase(trimmed);
  if (const auto special = yamlSpecialValue(lower)) return {*special, ""};

  // strtod also reads inf, infinity, nan and hex floats; the C locale is in force.
  const char* begin = lower.c_str();
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(begin, &end);
  if (end == begin || *end != '\0') return {0.0, "is not a number"};
  if (errno == ERANGE && std::isinf(value)) return {0.0, "is too large for a double"};
  return {value, ""};
}

std::optional<std::uint64_t> parseCount(std::string_view text) {
  if (text.empty() || text.size() > 20) return std::nullopt;
  std::uint64_t value = 0;
  for (char c : text) {
    if (c < '0' || c > '9') return std::nullopt;
    const std::uint64_t digit = static_cast<std::uint64_t>(c - '0');
    if (value > (std::numeric_limits<std::uint64_t>::max() - digit) / 10) return std::nullopt;
    value = value * 10 + digit;
  }
  return value;
}

std::vector<std::string> splitCommaList(std::string_view text) {
  std::vector<std::string> items;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    if (comma == std::string_view::npos) {
      items.emplace_back(text.substr(start));
      return items;
    }
    items.emplace_back(text.substr(start, comma - start));
    start = comma + 1;
  }
}

}  // namespace io
}  // namespace collision_lab
