// The filter of the published angles (src/core/correct_rounding.h, detail::Filtered): long
// double values with a running error bound, used before any exact rational is built. Each
// operation's bound is checked against the exact result to 500 bits (exact for + and * of
// 64-bit operands but for far apart exponents) on seeded operands, exact and inexact, across the double range; a
// bound four times tighter must fail somewhere, or these checks could not tell a bound too
// tight. The same for the filtered walk of the final velocities (rotation_run.h), against
// the exact rational run (rational_reference.h). The published values the filters decide are
// checked against exact references in test_published_rounding.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <random>
#include <string>

#include "collision_lab/core/precision.h"
#include "correct_rounding.h"
#include "rational_reference.h"
#include "rotation_run.h"
#include "scenes.h"

namespace collision_lab {
namespace core {
namespace {

using detail::Filtered;
using testing_support::kInf;
using D = DeepPrecision;

/// An operand: its exact value (a long double) and the filter's view of it.
struct Operand {
  long double exact;
  Filtered filtered;
};

/// Exact (error 0) one time in four; a computed value off the exact one by up to its stated
/// error, 2^-20 to 2^-64 of it, two times in four; and one time in four a wide error, 1/2 to
/// 4 times the value (its sign uncertain), or a computed 0.
Operand operand(std::mt19937_64& rng, int min_exponent, int max_exponent, bool positive) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_int_distribution<int> exponent(min_exponent, max_exponent), bits(20, 64), kind(0, 3);
  long double exact = std::ldexp(static_cast<long double>(0.5 + unit(rng)), exponent(rng));
  if (!positive && unit(rng) < 0.5) exact = -exact;
  const int drawn = kind(rng);
  if (drawn == 0) return {exact, Filtered(exact)};
  long double error = std::ldexp(std::fabs(exact), -bits(rng));
  long double value = exact + (2 * unit(rng) - 1) * error;
  if (drawn == 3) {
    error = std::fabs(exact) * (0.5L + 3.5L * unit(rng));
    value = unit(rng) < 0.25 ? 0.0L : exact + (2 * unit(rng) - 1) * error;
  }
  // The stated error holds: |value - exact| rounded up (not exact where value may cross 0).
  const long double distance = std::fabs(value - exact);
  return {exact, Filtered(value, std::max(error, distance) * (1 + 0x1p-55L) + std::fabs(value) * 0x1p-60L)};
}

D toDeep(long double x) { return D(x); }  // exact

/// |exact - value| / error, from an exact value to 500 bits (relative slack 2^-480).
double ratio(const D& exact, const Filtered& result) {
  EXPECT_TRUE(std::isfinite(result.error));
  const D distance = abs(exact - toDeep(result.value));
  const D slack = abs(exact) * ldexp(D(1), -480);
  EXPECT_LE(distance, toDeep(result.error) + slack) << "value " << static_cast<double>(result.value) << ", error "
                                                    << static_cast<double>(result.error) << ", exact " << exact.str(25);
  // The ratio only where the reference is far more exact than the bound (not a sum of
  // operands whose exponents differ by more than the 500 digits hold).
  if (!(result.error > 0) || slack * 1000 > toDeep(result.error)) return 0.0;
  return static_cast<double>(distance / toDeep(result.error));
}

TEST(FilteredArithmetic, EveryOperationsBoundHoldsAndAFourTimesTighterOneFails) {
  ASSERT_TRUE(detail::kFilterable) << "long double has no 64-bit significand here: the filter is off";
  std::mt19937_64 rng(4801);
  // The largest |exact - value| / error of each operation: at most 1, and above 1/4.
  std::map<std::string, double> worst;
  const auto note = [&worst](const std::string& op, double r) { worst[op] = std::max(worst[op], r); };
  for (int trial = 0; trial < 20000; ++trial) {
    const int low = trial % 2 == 0 ? -40 : -1000, high = trial % 2 == 0 ? 40 : 1000;
    const Operand a = operand(rng, low, high, false), b = operand(rng, low, high, false);
    const D da = toDeep(a.exact), db = toDeep(b.exact);
    // The worst ratio of inexact operands only: an exact operation's bound is its rounding.
    const bool inexact = a.filtered.error > 0 && b.filtered.error > 0;
    const auto check = [&](const std::string& op, const D& exact, const Filtered& result) {
      const double r = ratio(exact, result);
      if (inexact) note(op, r);
    };
    check("+", da + db, a.filtered + b.filtered);
    check("-", da - db, a.filtered - b.filtered);
    check("*", da * db, a.filtered * b.filtered);
    const Filtered quotient = a.filtered / b.filtered;
    if (std::isfinite(quotient.error)) check("/", da / db, quotient);
    const Operand p = operand(rng, low, high, true);
    const Filtered root = sqrt(p.filtered);
    note("sqrt", ratio(sqrt(toDeep(p.exact)), root));
    // Angles: the branch cut and the origin are left undecided (infinite error), never wrong.
    const Filtered angle = detail::atan2(a.filtered, b.filtered);
    if (std::isfinite(angle.error)) check("atan2", atan2(da, db), angle);
    const Operand s = operand(rng, -60, 60, true);
    const Filtered scaled = detail::atan2Sqrt(a.filtered, b.filtered, s.filtered);
    if (std::isfinite(scaled.error)) check("atan2Sqrt", atan2(da, db * sqrt(toDeep(s.exact))), scaled);
  }
  for (const auto& [op, r] : worst) {
    RecordProperty("worst_ratio_" + op, std::to_string(r));
    EXPECT_GT(r * 4, 1.0) << op << ": a bound four times tighter would pass too (worst ratio " << r << ")";
  }
  EXPECT_EQ(worst.size(), 7u);
}

TEST(FilteredArithmetic, TheBranchCutAndTheOriginAreLeftUndecided) {
  // y straddles 0 left of the origin: the angle may be near +pi or near -pi.
  EXPECT_TRUE(std::isinf(detail::atan2(Filtered(1e-30L, 1e-29L), Filtered(-1)).error));
  // An exact 0 left of the origin is +pi, as the exact path says.
  const Filtered pi = detail::atan2(Filtered(0), Filtered(-1, 1e-20L));
  EXPECT_GT(pi.value, 3.14L);
  EXPECT_EQ(detail::filteredNearest(pi), M_PI);
  // The origin within the bounds.
  EXPECT_TRUE(std::isinf(detail::atan2(Filtered(1e-10L, 1e-9L), Filtered(1e-10L, 1e-9L)).error));
  // A quotient whose divisor's bound reaches 0.
  EXPECT_TRUE(std::isinf((Filtered(1) / Filtered(1e-5L, 2e-5L)).error));
  // Rounding: a value within its bound of a rounding boundary between two doubles is not rounded.
  const long double boundary = 1.0L + 0x1p-53L;  // halfway between 1 and its successor
  EXPECT_FALSE(detail::filteredNearest(Filtered(boundary + 0x1p-62L, 0x1p-61L)));
  EXPECT_EQ(detail::filteredNearest(Filtered(boundary + 0x1p-60L, 0x1p-62L)), 1.0 + 0x1p-52);
}

TEST(FilteredArithmetic, PsiIsTheExactPathsBitsWhereverTheFilterDecides) {
  // psi's arguments (physics.md: Y = v_B - v_C, X = (m_B + m_C) v_A - m_B v_B - m_C v_C,
  // s = m_A / (m_B m_C M)) filtered and exact, on seeded scenes across the double range with
  // exact ties and zeros: where the filter decides, the same double as the exact path; and
  // it decides nearly everywhere (else it would be a filter in name only).
  std::mt19937_64 rng(4812);
  std::uniform_real_distribution<double> unit(0.0, 1.0), mass_decade(-15.0, 15.0), speed_decade(-30.0, 30.0);
  const auto speed = [&] { return (unit(rng) < 0.5 ? -1 : 1) * std::pow(10.0, speed_decade(rng)); };
  int decided = 0, scenes = 0;
  for (int k = 0; k < 2000; ++k) {
    const double m[3] = {std::pow(10.0, mass_decade(rng)), std::pow(10.0, mass_decade(rng)),
                         std::pow(10.0, mass_decade(rng))};
    double v[3] = {speed(), speed(), speed()};
    if (k % 5 == 0) v[2] = v[1];
    if (k % 5 == 1) v[0] = v[1];
    if (k % 5 == 2) v[k % 3] = 0.0;
    const auto arguments = [&](auto zero) {
      using T = decltype(zero);
      const T m_a(m[0]), m_b(m[1]), m_c(m[2]), v_a(v[0]), v_b(v[1]), v_c(v[2]);
      return std::array<T, 3>{v_b - v_c, (m_b + m_c) * v_a - m_b * v_b - m_c * v_c, m_a / (m_b * m_c * (m_a + m_b + m_c))};
    };
    const auto f = arguments(Filtered());
    const auto e = arguments(detail::ExactRational());
    const std::optional<double> exact = detail::roundedAtan2Sqrt(e[0], e[1], e[2], true);
    ASSERT_TRUE(exact) << k;
    ++scenes;
    if (const std::optional<double> filtered = detail::filteredAtan2Sqrt(f[0], f[1], f[2], true)) {
      ++decided;
      EXPECT_EQ(*filtered, *exact) << "scene " << k;
    }
  }
  RecordProperty("decided", decided);
  EXPECT_GT(decided, scenes * 9 / 10);
}

TEST(FilteredWalk, DecidesMostShortRunsWithTheExactRunsBits) {
  // Seeded three-body runs of up to 64 impacts (the walk's limit; a wall in some): where
  // every walked velocity is decided, each is the exact rational run's rounded; and most
  // runs of up to 16 impacts are decided.
  std::mt19937_64 rng(4813);
  std::uniform_real_distribution<double> unit(0.0, 1.0), decade(-4.0, 4.0);
  int decided = 0, short_runs = 0, short_decided = 0;
  for (int k = 0; k < 600; ++k) {
    Scene scene{{std::pow(10.0, decade(rng)), std::pow(10.0, decade(rng)), std::pow(10.0, decade(rng))},
                {2, 1, 0},
                {-unit(rng), 2 * unit(rng) - 1, unit(rng)}};
    if (k % 4 == 1) scene.masses[0] = kInf;
    if (k % 4 == 3) scene.masses[2] = kInf;
    const std::optional<Pair> first = firstPair(scene);
    if (!first) continue;
    const reference::Run run = reference::simulateVelocities(scene, 64);
    if (run.truncated || run.impacts.empty()) continue;
    const std::array<Filtered, 3> walked = filteredVelocitiesAfter(scene, *first, run.impacts.size());
    std::array<std::optional<double>, 3> nearest;
    for (int b = 0; b < 3; ++b) nearest[b] = detail::filteredNearest(walked[b]);
    const bool all = nearest[0] && nearest[1] && nearest[2];
    short_runs += run.impacts.size() <= 16;
    short_decided += all && run.impacts.size() <= 16;
    if (!all) continue;
    ++decided;
    for (int b = 0; b < 3; ++b) {
      EXPECT_TRUE(reference::correctlyRounded(*nearest[b], run.final_velocities[b]))
          << testing_support::describe(scene) << " body " << b << ": " << *nearest[b];
    }
  }
  RecordProperty("decided", decided);
  EXPECT_GT(short_runs, 400);
  EXPECT_GT(short_decided, short_runs * 9 / 10);
}

TEST(FilteredWalk, BoundsHoldAgainstTheExactRunAndATighterBoundFails) {
  // Seeded three-body scenes, a wall at either end in some, masses over 12 decades: after
  // every impact n of the exact run, the walked velocities are within their bounds.
  std::mt19937_64 rng(4811);
  std::uniform_real_distribution<double> unit(0.0, 1.0), decade(-6.0, 6.0);
  constexpr double kTighter = 4.0;
  double worst = 0.0;
  int checked = 0;
  for (int k = 0; k < 300; ++k) {
    Scene scene{{std::pow(10.0, decade(rng)), std::pow(10.0, decade(rng)), std::pow(10.0, decade(rng))},
                {2, 1, 0},
                {-unit(rng), 2 * unit(rng) - 1, unit(rng)}};
    if (k % 5 == 1) scene.masses[0] = kInf;
    if (k % 5 == 3) scene.masses[2] = kInf;
    const std::optional<Pair> first = firstPair(scene);
    if (!first) continue;
    const reference::Run run = reference::simulate(scene, 64);
    SCOPED_TRACE(testing_support::describe(scene));
    for (std::size_t n = 1; n <= run.impacts.size(); ++n) {
      const std::array<Filtered, 3> walked = filteredVelocitiesAfter(scene, *first, n);
      for (int b = 0; b < 3; ++b) {
        const D exact = D(numerator(run.impacts[n - 1].velocities[b])) / D(denominator(run.impacts[n - 1].velocities[b]));
        worst = std::max(worst, ratio(exact, walked[b]));
        ++checked;
      }
    }
  }
  RecordProperty("worst_ratio", std::to_string(worst));
  EXPECT_GT(checked, 1000);
  EXPECT_GT(worst * kTighter, 1.0) << "a bound " << kTighter << " times tighter would pass too (worst ratio " << worst
                                   << ")";
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
