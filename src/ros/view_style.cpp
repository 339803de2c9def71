#include "collision_lab/ros/view_style.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

namespace collision_lab_ros::markers {

using namespace layout;

namespace {

/// A printf number in the page's style: an exponent as "×10^n" ("4.68×10^11", not
/// "4.68e+11") and thousands separators in the whole part ("169,548").
std::string numberStyle(const std::string& text) {
  const std::size_t e = text.find_first_of("eE");
  if (e != std::string::npos && e > 0 && std::isdigit(static_cast<unsigned char>(text[e - 1]))) {
    return text.substr(0, e) + "×10^" + std::to_string(std::stoi(text.substr(e + 1)));
  }
  const std::size_t start = text.find_first_of("0123456789");
  if (start == std::string::npos) return text;
  std::size_t end = start;
  while (end < text.size() && std::isdigit(static_cast<unsigned char>(text[end]))) ++end;
  std::string out = text.substr(0, start);
  for (std::size_t k = start; k < end; ++k) {
    if (k > start && (end - k) % 3 == 0) out += ',';
    out += text[k];
  }
  return out + text.substr(end);
}

}  // namespace

std::string format(const char* fmt, double value) {
  // The one conversion of fmt is printed alone and styled; the text around it is kept.
  const std::string spec_and_text = fmt;
  const std::size_t percent = spec_and_text.find('%');
  const std::size_t conversion = spec_and_text.find_first_of("gGeEf", percent);
  if (percent == std::string::npos || conversion == std::string::npos) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, fmt, value);
    return buffer;
  }
  char number[64];
  std::snprintf(number, sizeof number, spec_and_text.substr(percent, conversion + 1 - percent).c_str(), value);
  return spec_and_text.substr(0, percent) + numberStyle(number) + spec_and_text.substr(conversion + 1);
}

std::string withSeparators(std::uint64_t n) {
  std::string digits = std::to_string(n), out;
  for (std::size_t k = 0; k < digits.size(); ++k) {
    if (k > 0 && (digits.size() - k) % 3 == 0) out += ',';
    out += digits[k];
  }
  return out;
}

double velocityScale(const RunRecord& run) {
  double v_max = 0.0;
  for (std::size_t i = 0; i < run.bodies(); ++i) {
    if (!run.isWall(i)) v_max = std::max(v_max, std::abs(run.input().velocities[i]));
  }
  return v_max > 0 && std::isfinite(v_max) ? v_max : 1.0;
}

Rgba velocityRgb(double v, double v_max) {
  const double f = std::isfinite(v) && v_max > 0 ? std::clamp(v / v_max, -1.0, 1.0) : 0.0;
  const Rgba& end = f < 0 ? kSlowBlue : kFastRed;
  const double a = std::abs(f);
  const Rgba& rest = kRestPurple;
  return {rest.r + (end.r - rest.r) * a, rest.g + (end.g - rest.g) * a, rest.b + (end.b - rest.b) * a};
}

}  // namespace collision_lab_ros::markers
