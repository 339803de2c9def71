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
//
// Two instances of one arithmetic: DD (portable x86-64: Dekker's product with Veltkamp
// splitting) and DDFma (the same algorithms with the exact product from one FMA, for code
// compiled for an FMA target: nbody/fma_path.h). Only the exact two-product differs in code,
// and it is the same value either way (p and p's exact rounding error), so both compute the
// same bits. Everything else is one formula (the dd * dd cross term is Alg. 10's without
// FMA in both). The build keeps the compiler from fusing anything else (-ffp-contract=off):
// a fused a*b+c would break the error-free transforms.
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

template <bool kFma>
struct BasicDD;

/// Portable: every platform, every build.
using DD = BasicDD<false>;
/// The same values from an FMA's exact product; only in code compiled for FMA (fma_path.h).
using DDFma = BasicDD<true>;

template <bool kFma = false>
CL_DD_INLINE BasicDD<kFma> twoSum(double a, double b) {
  const double s = a + b;
  const double bb = s - a;
  return BasicDD<kFma>(s, (a - (s - bb)) + (b - bb), 0);
}

/// Precondition: |a| >= |b| or a == 0.
template <bool kFma = false>
CL_DD_INLINE BasicDD<kFma> fastTwoSum(double a, double b) {
  const double s = a + b;
  return BasicDD<kFma>(s, b - (s - a), 0);
}

/// p = fl(a b) and its exact error: the same two doubles either way.
template <bool kFma = false>
CL_DD_INLINE BasicDD<kFma> twoProd(double a, double b) {
  const double p = a * b;
  if constexpr (kFma) {
    return BasicDD<kFma>(p, __builtin_fma(a, b, -p), 0);
  } else {
    // Dekker's product with Veltkamp splitting (exact while |a|, |b| < 2^996).
    constexpr double kSplit = 134217729.0;  // 2^27 + 1
    const double ca = kSplit * a, cb = kSplit * b;
    const double ah = ca - (ca - a), al = a - ah;
    const double bh = cb - (cb - b), bl = b - bh;
    return BasicDD<kFma>(p, ((ah * bh - p) + ah * bl + al * bh) + al * bl, 0);
  }
}

template <bool kFma>
struct BasicDD {
  double hi = 0.0;
  double lo = 0.0;

  BasicDD() = default;
  BasicDD(double value) : hi(value), lo(0.0) {}  // NOLINT: exact, so implicit like a widening
  BasicDD(double h, double l, int /*normalized*/) : hi(h), lo(l) {}

  friend CL_DD_INLINE BasicDD operator+(const BasicDD& x, const BasicDD& y) {
    const BasicDD s = twoSum<kFma>(x.hi, y.hi);
    const BasicDD t = twoSum<kFma>(x.lo, y.lo);
    const BasicDD v = fastTwoSum<kFma>(s.hi, s.lo + t.hi);
    return fastTwoSum<kFma>(v.hi, t.lo + v.lo);
  }

  friend CL_DD_INLINE BasicDD operator-(const BasicDD& x) { return BasicDD(-x.hi, -x.lo, 0); }
  friend CL_DD_INLINE BasicDD operator-(const BasicDD& x, const BasicDD& y) { return x + (-y); }

  friend CL_DD_INLINE BasicDD operator*(const BasicDD& x, double y) {
    const BasicDD c = twoProd<kFma>(x.hi, y);
    const BasicDD t = fastTwoSum<kFma>(c.hi, x.lo * y);
    return fastTwoSum<kFma>(t.hi, t.lo + c.lo);
  }

  friend CL_DD_INLINE BasicDD operator*(const BasicDD& x, const BasicDD& y) {
    const BasicDD c = twoProd<kFma>(x.hi, y.hi);
    const double cross = x.hi * y.lo + x.lo * y.hi;
    return fastTwoSum<kFma>(c.hi, c.lo + cross);
  }

  friend CL_DD_INLINE BasicDD operator/(const BasicDD& x, const BasicDD& y) {
    const double th = x.hi / y.hi;
    const BasicDD r = y * th;
    const BasicDD pi = twoSum<kFma>(x.hi, -r.hi);
    const double delta = pi.hi + ((pi.lo - r.lo) + x.lo);
    return fastTwoSum<kFma>(th, delta / y.hi);
  }

  friend CL_DD_INLINE bool operator<(const BasicDD& x, const BasicDD& y) {
    return x.hi < y.hi || (x.hi == y.hi && x.lo < y.lo);
  }
  friend CL_DD_INLINE bool operator>(const BasicDD& x, const BasicDD& y) { return y < x; }
  friend CL_DD_INLINE bool operator==(const BasicDD& x, const BasicDD& y) { return x.hi == y.hi && x.lo == y.lo; }
};

}  // namespace nbody_detail
}  // namespace core
}  // namespace collision_lab
