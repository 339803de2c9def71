#pragma once
// Counts in texts people read (stop messages, truncation reasons): thousands separators,
// as every view shows them ("31,415 impacts").
#include <cstdint>
#include <string>

namespace collision_lab {
namespace core {

/// 31415 -> "31,415".
inline std::string countText(std::uint64_t count) {
  std::string digits = std::to_string(count);
  for (std::size_t at = digits.size(); at > 3; at -= 3) digits.insert(at - 3, ",");
  return digits;
}

}  // namespace core
}  // namespace collision_lab
