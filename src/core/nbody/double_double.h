// Double-double arithmetic (an unevaluated sum hi + lo, |lo| <= ulp(hi)/2): about 106 bits
// at a few times the cost of double. The algorithms and their relative error bounds, with
// u = 2^-53, are those of Joldes, Muller and Popescu, "Tight and rigorous error bounds for
// basic building blocks of double-word arithmetic", ACM TOMS 44 (2017):
//   add/sub (AccurateDWPlusDW, Alg. 6)  3u^2 + 13u^3
//   dd * double (DWTimesFP3, Alg. 9)     2u^2
//   dd * dd (DWTimesDW3, Alg. 12)        4u^2   (Alg. 10 without FMA: 7u^2)
//   dd / dd (DWDivDW2, Alg. 17)          15u^2 + 56u^3
// so every operation has a relative error below kDoubleDoubleOpError = 16u^2, away from
// underflow. Internal to the engine; not installed.
#pragma once

#include <cmath>

// The operations are small and sit on the engine's hot path: always inline them.
#if defined(__GNUC__)
#define CL_DD_INLINE inline __attribute__((always_inline))
#else
#define CL_DD_INLINE inline
#endif

namespace collision_lab {
namespace core {
namespace nbody_detail {

/// Relative error bound of one double-double operation (see above).
constexpr double kDoubleDoubleOpError = 16.0 * 0x1p-106;

struct DD {
  double hi = 0.0;
  double lo = 0.0;

  DD() = default;
  DD(double value) : hi(value), lo(0.0) {}  // NOLINT: exact, so implicit like a widening
  DD(double h, double l, int /*normalized*/) : hi(h), lo(l) {}
};

CL_DD_INLINE DD twoSum(double a, double b) {
  const double s = a + b;
  const double bb = s - a;
  return DD(s, (a - (s - bb)) + (b - bb), 0);
}

/// Precondition: |a| >= |b| or a == 0.
CL_DD_INLINE DD fastTwoSum(double a, double b) {
  const double s = a + b;
  return DD(s, b - (s - a), 0);
}

CL_DD_INLINE DD twoProd(double a, double b) {
  const double p = a * b;
#if defined(__FMA__) || defined(FP_FAST_FMA)
  return DD(p, std::fma(a, b, -p), 0);
#else
  // Dekker's product with Veltkamp splitting (exact while |a|, |b| < 2^996).
  constexpr double kSplit = 134217729.0;  // 2^27 + 1
  const double ca = kSplit * a, cb = kSplit * b;
  const double ah = ca - (ca - a), al = a - ah;
  const double bh = cb - (cb - b), bl = b - bh;
  return DD(p, ((ah * bh - p) + ah * bl + al * bh) + al * bl, 0);
#endif
}

CL_DD_INLINE DD operator+(const DD& x, const DD& y) {
  const DD s = twoSum(x.hi, y.hi);
  const DD t = twoSum(x.lo, y.lo);
  const DD v = fastTwoSum(s.hi, s.lo + t.hi);
  return fastTwoSum(v.hi, t.lo + v.lo);
}

CL_DD_INLINE DD operator-(const DD& x) { return DD(-x.hi, -x.lo, 0); }
CL_DD_INLINE DD operator-(const DD& x, const DD& y) { return x + (-y); }

CL_DD_INLINE DD operator*(const DD& x, double y) {
  const DD c = twoProd(x.hi, y);
  const DD t = fastTwoSum(c.hi, x.lo * y);
  return fastTwoSum(t.hi, t.lo + c.lo);
}

CL_DD_INLINE DD operator*(const DD& x, const DD& y) {
  const DD c = twoProd(x.hi, y.hi);
#if defined(__FMA__) || defined(FP_FAST_FMA)
  const double cross = std::fma(x.lo, y.hi, std::fma(x.hi, y.lo, x.lo * y.lo));
#else
  const double cross = x.hi * y.lo + x.lo * y.hi;
#endif
  return fastTwoSum(c.hi, c.lo + cross);
}

CL_DD_INLINE DD operator/(const DD& x, const DD& y) {
  const double th = x.hi / y.hi;
  const DD r = y * th;
  const DD pi = twoSum(x.hi, -r.hi);
  const double delta = pi.hi + ((pi.lo - r.lo) + x.lo);
  return fastTwoSum(th, delta / y.hi);
}

CL_DD_INLINE bool operator<(const DD& x, const DD& y) { return x.hi < y.hi || (x.hi == y.hi && x.lo < y.lo); }
CL_DD_INLINE bool operator>(const DD& x, const DD& y) { return y < x; }
CL_DD_INLINE bool operator==(const DD& x, const DD& y) { return x.hi == y.hi && x.lo == y.lo; }

}  // namespace nbody_detail
}  // namespace core
}  // namespace collision_lab
