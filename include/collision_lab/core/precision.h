// Arithmetic types of the core.
#pragma once

#include <boost/multiprecision/cpp_bin_float.hpp>

namespace collision_lab {
namespace core {

/// The high-precision working type: 50 decimal digits, header-only.
using HighPrecision = boost::multiprecision::cpp_bin_float_50;

}  // namespace core
}  // namespace collision_lab
