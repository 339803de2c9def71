// The viscoelastic law's e(v) (impact_rule.h, viscoelasticRestitution) as the correctly
// rounded value of its formula at the exact approach speed, in Ziv's steps: long double over
// a tier's interval of speeds, 100 digits near a speed known to within a bound, and the
// exact speed at 100 digits, then 500 bits. e(v) = min(1, 1 - C1 s + C2 s^2) with
// s = (v / v*)^(1/5) and the decimals C1 = 1.15344, C2 = 0.79826; it is never below 0.583.
// Internal to the engine.
#pragma once

#include <optional>

#include "arithmetic.h"
#include "double_double.h"

namespace collision_lab {
namespace core {
namespace nbody_detail {

/// e of every speed within `error` of v (0 <= error < v) [m/s] when they all round to the
/// same double (long double with a 64-bit significand; else empty).
std::optional<double> viscoelasticOver(long double v, long double error, double v_star);
/// The same in double-double, s refined by a Newton step (error below 2^-20 v).
std::optional<double> viscoelasticDD(const DD& v, double error, double v_star);
/// e at a speed within `error` of v (0 <= error < v) [m/s], at 128 bits, else 100 digits,
/// when that decides.
std::optional<double> viscoelasticNear(const Float100& v, const Float100& error, double v_star);
/// e at the exact speed v > 0 [m/s], correctly rounded.
double viscoelasticAt(const Rational& v, double v_star);

}  // namespace nbody_detail
}  // namespace core
}  // namespace collision_lab
