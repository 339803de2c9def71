#include "collision_lab/io/number_text.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>

namespace collision_lab {
namespace io {

namespace {

bool isBlank(char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }

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

/// nlohmann::json's layout (dtoa_impl::format_buffer with min_exp -4, max_exp 15) of
/// digits[0..k) * 10^(n - k), written at `out`, where `out` already holds the k digits.
char* jsonLayout(char* out, int k, int n) {
  constexpr int kMinExp = -4;
  constexpr int kMaxExp = 15;
  if (k <= n && n <= kMaxExp) {  // digits[000].0
    std::memset(out + k, '0', static_cast<std::size_t>(n - k));
    out[n] = '.';
    out[n + 1] = '0';
    return out + n + 2;
  }
  if (0 < n && n <= kMaxExp) {  // dig.its
    std::memmove(out + n + 1, out + n, static_cast<std::size_t>(k - n));
    out[n] = '.';
    return out + k + 1;
  }
  if (kMinExp < n && n <= 0) {  // 0.[000]digits
    std::memmove(out + 2 - n, out, static_cast<std::size_t>(k));
    out[0] = '0';
    out[1] = '.';
    std::memset(out + 2, '0', static_cast<std::size_t>(-n));
    return out + 2 - n + k;
  }
  if (k > 1) {  // d.igits
    std::memmove(out + 2, out + 1, static_cast<std::size_t>(k - 1));
    out[1] = '.';
  }
  out += k == 1 ? 1 : k + 1;
  *out++ = 'e';
  int e = n - 1;
  *out++ = e < 0 ? '-' : '+';
  e = e < 0 ? -e : e;
  if (e >= 100) *out++ = static_cast<char>('0' + e / 100);
  *out++ = static_cast<char>('0' + e / 10 % 10);
  *out++ = static_cast<char>('0' + e % 10);
  return out;
}

}  // namespace

char* writeCsvNumber(char* out, double value) {
  if (std::isnan(value)) return std::copy_n("nan", 3, out);
  if (value == 0) {
    *out = '0';
    return out + 1;
  }
  return std::to_chars(out, out + kNumberTextMax, value).ptr;  // inf and -inf as such
}

char* writeJsonNumber(char* out, double value) {
  if (!std::isfinite(value)) return std::copy_n("null", 4, out);
  if (value == 0) return std::copy_n("0.0", 3, out);
  if (value < 0) {
    *out++ = '-';
    value = -value;
  }
  // Shortest round-trip digits in exponent form, "d.ddde+XX" or "de-XX", then laid out.
  char scientific[kNumberTextMax];
  char* const end = std::to_chars(scientific, scientific + sizeof scientific, value, std::chars_format::scientific).ptr;
  char* const e = std::find(scientific, end, 'e');
  int k = 0;
  for (const char* c = scientific; c != e; ++c) {
    if (*c != '.') out[k++] = *c;
  }
  int exponent = 0;
  std::from_chars(e + (e[1] == '+' ? 2 : 1), end, exponent);
  return jsonLayout(out, k, exponent + 1);
}

ParsedNumber parseNumber(std::string_view text) {
  if (text.empty()) return {0.0, "is empty"};
  if (std::any_of(text.begin(), text.end(), isBlank)) return {0.0, "contains a blank; numbers are written without blanks"};
  const std::string lower = lowerCase(text);
  if (const auto special = yamlSpecialValue(lower)) return {*special, ""};

  // strtod also reads inf, infinity, nan and hex floats; the C locale is in force.
  const char* begin = lower.c_str();
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(begin, &end);
  if (end == begin || *end != '\0') return {0.0, "is not a number"};
  if (errno == ERANGE && std::isinf(value)) return {0.0, "is too large for a double"};
  // A subnormal result is the nearest double and is kept; only a nonzero number that
  // would be read as 0 is refused.
  if (errno == ERANGE && value == 0) {
    return {0.0, "is too small for a double (it would be read as 0; the smallest is 4.9e-324); write 0 for zero"};
  }
  return {value, ""};
}

ParsedCount parseCount(std::string_view text) {
  if (text.empty() || !std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return {0, "is not a non-negative integer"};
  }
  std::uint64_t value = 0;
  for (char c : text) {
    const std::uint64_t digit = static_cast<std::uint64_t>(c - '0');
    if (value > (std::numeric_limits<std::uint64_t>::max() - digit) / 10) {
      return {0, "is too large: the largest is 2^64 - 1 = 18446744073709551615"};
    }
    value = value * 10 + digit;
  }
  return {value, ""};
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
