// Doubles printed for programs (io/number_text.h: writeCsvNumber, writeJsonNumber) and the
// cache of the streamed reports (src/io/text_sink.h). References share no code with them:
// strtod reads the text back, and the shortest length is found by brute force over
// printf's %.{1..17}g; the JSON layout is nlohmann::json's own dump.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "collision_lab/io/number_text.h"
#include "text_sink.h"

namespace {

namespace io = collision_lab::io;

std::uint64_t bitsOf(double value) {
  std::uint64_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  return bits;
}

double fromBits(std::uint64_t bits) {
  double value;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

std::string csvText(double value) {
  char buffer[io::kNumberTextMax];
  return std::string(buffer, io::writeCsvNumber(buffer, value));
}

std::string jsonText(double value) {
  char buffer[io::kNumberTextMax];
  return std::string(buffer, io::writeJsonNumber(buffer, value));
}

/// The shortest decimal that reads back to `value`, by brute force: the fewest significant
/// digits p (printf's %.{p-1}e read back by strtod), and the fewest characters that p
/// digits take in fixed or exponent form (as printf writes them: exponents of 2+ digits).
struct Shortest {
  int digits = 0;
  std::size_t characters = 0;
};

Shortest shortestDecimal(double value) {
  for (int digits = 1; digits <= 17; ++digits) {
    char text[64];
    std::snprintf(text, sizeof text, "%.*e", digits - 1, value);
    if (bitsOf(std::strtod(text, nullptr)) != bitsOf(value)) continue;
    const int exponent = std::atoi(std::strchr(text, 'e') + 1);
    const std::size_t sign = value < 0 ? 1 : 0;
    const int fraction = std::max(0, digits - 1 - exponent);
    const std::size_t fixed = sign + static_cast<std::size_t>(std::max(exponent + 1, 1)) +
                              (fraction > 0 ? 1 + static_cast<std::size_t>(fraction) : 0);
    const int magnitude = std::abs(exponent);
    const std::size_t scientific = sign + static_cast<std::size_t>(digits) + (digits > 1 ? 1 : 0) + 2 +
                                   (magnitude >= 100 ? 3 : 2);
    return {digits, std::min(fixed, scientific)};
  }
  return {99, 99};  // never: 17 digits always read back
}

bool isPlainInteger(const std::string& text) {
  return text.find_first_of(".eE") == std::string::npos;
}

/// Significant digits of a decimal text: its mantissa without sign, point, leading and
/// trailing zeros ("1000000000000.0" has 1, "0.00012" has 2, "1.5e-05" has 2).
int significantDigits(const std::string& text) {
  std::string digits;
  for (char c : text.substr(0, text.find_first_of("eE"))) {
    if (c >= '0' && c <= '9') digits += c;
  }
  const std::size_t first = digits.find_first_not_of('0');
  if (first == std::string::npos) return 0;
  const std::size_t last = digits.find_last_not_of('0');
  return static_cast<int>(last - first + 1);
}

/// Seeded doubles of every kind: random bit patterns (all exponents, subnormals), ordinary
/// magnitudes, integers, powers of ten and their neighbours, the extremes.
std::vector<double> sampleDoubles() {
  std::mt19937_64 random(20261123);
  std::vector<double> values = {std::numeric_limits<double>::min(),        std::numeric_limits<double>::max(),
                                std::numeric_limits<double>::denorm_min(), std::numeric_limits<double>::epsilon(),
                                5e-324, 1e-323, 2.2250738585072009e-308,   1e23, 9007199254740993.0,
                                0.1, 0.3, 1.0 / 3.0, M_PI, 1e15, 1e16, 1e-4, 1e-5, 123456789012345680.0};
  for (int i = 0; i < 20000; ++i) {
    const double value = fromBits(random());
    if (std::isfinite(value)) values.push_back(value);
  }
  std::uniform_real_distribution<double> unit(-2.0, 2.0);
  std::uniform_int_distribution<std::int64_t> integer(-(std::int64_t{1} << 53), std::int64_t{1} << 53);
  std::uniform_int_distribution<std::uint64_t> subnormal(1, (std::uint64_t{1} << 52) - 1);
  std::uniform_int_distribution<int> exponent(-300, 300);
  for (int i = 0; i < 5000; ++i) {
    values.push_back(unit(random));
    values.push_back(static_cast<double>(integer(random)));
    values.push_back(fromBits(subnormal(random)));
    values.push_back(unit(random) * std::pow(10.0, exponent(random)));
  }
  for (int e = -320; e <= 308; ++e) {
    const double power = std::pow(10.0, e);
    if (power == 0 || !std::isfinite(power)) continue;
    for (double value : {power, std::nextafter(power, 0.0), std::nextafter(power, INFINITY)}) values.push_back(value);
  }
  for (std::size_t i = 0, n = values.size(); i < n; ++i) values.push_back(-values[i]);
  return values;
}

void expectReadsBack(const std::string& text, double value) {
  char* end = nullptr;
  const double back = std::strtod(text.c_str(), &end);
  ASSERT_EQ(*end, '\0') << text;
  ASSERT_EQ(bitsOf(back), bitsOf(value)) << text << " for %.17g " << value;
}

TEST(NumberFormat, EveryDoubleReadsBackExactlyFromTheShortestText) {
  for (double value : sampleDoubles()) {
    if (value == 0) continue;
    const Shortest shortest = shortestDecimal(value);
    // CSV, std::to_chars' form: the fewest characters; its digits are the fewest too,
    // except that an integer written out in full (|x| >= 1e17 in fixed form) shows its
    // exact digits where trailing zeros would do, in as many characters.
    const std::string csv = csvText(value);
    expectReadsBack(csv, value);
    ASSERT_EQ(csv.size(), shortest.characters) << csv;
    if (!isPlainInteger(csv)) {
      ASSERT_EQ(significantDigits(csv), shortest.digits) << csv;
    }
    // JSON, nlohmann's layout: always the fewest significant digits.
    const std::string json = jsonText(value);
    expectReadsBack(json, value);
    ASSERT_EQ(significantDigits(json), shortest.digits) << json;
  }
}

TEST(NumberFormat, JsonNumbersAreFloatsThatNlohmannReadsBack) {
  for (double value : sampleDoubles()) {
    const std::string text = jsonText(value);
    const nlohmann::json parsed = nlohmann::json::parse(text);
    ASSERT_TRUE(parsed.is_number_float()) << text;  // counts are integers, doubles never
    ASSERT_EQ(bitsOf(parsed.get<double>()), bitsOf(value)) << text;
  }
}

TEST(NumberFormat, JsonLayoutIsNlohmanns) {
  // k * 10^e with k of 1 to 3 digits. Where nlohmann's Grisu2 finds the shortest digits
  // (those of k; it misses a few, e.g. 9.989999999999999e-24 for 999e-26), its dump and
  // ours agree character for character: fixed from 1e-4 to below 1e15, x.0 for integers,
  // exponents of two digits at least.
  int compared = 0;
  for (int e = -40; e <= 40; ++e) {
    for (int k : {1, 2, 5, 12, 25, 125, 999}) {
      for (double sign : {1.0, -1.0}) {
        const double value = sign * std::stod(std::to_string(k) + "e" + std::to_string(e));
        const std::string theirs = nlohmann::json(value).dump();
        if (significantDigits(theirs) != significantDigits(std::to_string(k))) continue;
        ASSERT_EQ(jsonText(value), theirs) << k << "e" << e;
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 1000);  // of 1134
  EXPECT_EQ(jsonText(2.0), "2.0");
  EXPECT_EQ(jsonText(1e12), "1000000000000.0");
  EXPECT_EQ(jsonText(1e15), "1e+15");
  EXPECT_EQ(jsonText(1.5e-5), "1.5e-05");
  EXPECT_EQ(jsonText(0.00012), "0.00012");
  EXPECT_EQ(jsonText(-2.5e-300), "-2.5e-300");
}

TEST(NumberFormat, ZerosAndNonFiniteValuesFollowTheReportConventions) {
  // report.h: a zero always as 0, never -0; CSV spells out nan, inf and -inf; JSON null.
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(csvText(0.0), "0");
  EXPECT_EQ(csvText(-0.0), "0");
  EXPECT_EQ(csvText(nan), "nan");
  EXPECT_EQ(csvText(-nan), "nan");
  EXPECT_EQ(csvText(inf), "inf");
  EXPECT_EQ(csvText(-inf), "-inf");
  EXPECT_EQ(jsonText(0.0), "0.0");
  EXPECT_EQ(jsonText(-0.0), "0.0");
  for (double value : {nan, -nan, inf, -inf}) EXPECT_EQ(jsonText(value), "null");
  EXPECT_EQ(csvText(1e12), "1e+12");  // std::to_chars' shorter form, as the CSV had
  EXPECT_EQ(csvText(-0.5), "-0.5");
}

TEST(NumberFormat, CacheGivesExactlyTheTextOfItsFormat) {
  // Repeats, sign flips and table collisions: a long seeded sequence drawn from a small pool.
  std::vector<double> pool = sampleDoubles();
  pool.resize(3000);
  for (double special : {0.0, -0.0, std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                         std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::quiet_NaN()}) {
    pool.push_back(special);
  }
  std::mt19937_64 random(7);
  std::uniform_int_distribution<std::size_t> pick(0, pool.size() - 1);
  io::NumberTextCache csv(io::writeCsvNumber);
  io::NumberTextCache json(io::writeJsonNumber);
  char buffer[io::kNumberTextMax + 1];
  for (int i = 0; i < 200000; ++i) {
    const double value = pool[pick(random)];
    ASSERT_EQ(std::string(buffer, csv.write(buffer, value)), csvText(value));
    ASSERT_EQ(std::string(buffer, json.write(buffer, value)), jsonText(value));
  }
}

}  // namespace
