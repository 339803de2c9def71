#include "report.h"

#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <vector>

namespace collision_lab {
namespace bench {

std::string format(const char* fmt, ...) {
  va_list args;
  va_start(args, fmt);
  va_list copy;
  va_copy(copy, args);
  const int size = std::vsnprintf(nullptr, 0, fmt, copy);
  va_end(copy);
  std::vector<char> buffer(static_cast<std::size_t>(size) + 1);
  std::vsnprintf(buffer.data(), buffer.size(), fmt, args);
  va_end(args);
  return std::string(buffer.data(), static_cast<std::size_t>(size));
}

std::string sci(double value) {
  if (std::isnan(value)) return "nan";
  if (value == 0.0) return "0";
  return format("%.3g", value);
}

std::string tripleText(const std::vector<double>& values) {
  return format("(%g, %g, %g)", values.at(0), values.at(1), values.at(2));
}

double relativeVelocityError(const std::vector<double>& masses, const std::vector<double>& a,
                             const std::vector<double>& b) {
  double diff = 0.0, scale = 0.0;
  for (std::size_t i = 0; i < masses.size(); ++i) {
    if (std::isinf(masses[i])) continue;
    diff = std::max(diff, std::fabs(a[i] - b[i]));
    scale = std::max(scale, std::fabs(b[i]));
    if (std::isnan(a[i])) return NAN;
  }
  return scale > 0.0 ? diff / scale : diff;
}

double relativeVelocityError(const core::Scene& scene, const std::array<double, 3>& a,
                             const std::array<double, 3>& b) {
  const std::vector<double> m(scene.masses.begin(), scene.masses.end());
  return relativeVelocityError(m, {a.begin(), a.end()}, {b.begin(), b.end()});
}

long double kineticEnergy(const std::vector<double>& masses, const std::vector<double>& v) {
  long double e = 0;
  for (std::size_t i = 0; i < masses.size(); ++i) {
    if (!std::isinf(masses[i])) e += static_cast<long double>(masses[i]) * v[i] * v[i] / 2;
  }
  return e;
}

std::string sourceVersion() {
  const char* version = std::getenv("COLLISION_LAB_BENCH_SOURCE");
  return version && *version ? version : "unknown (not run through bench/run_benchmarks.sh)";
}

bool writeTextFile(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  out.close();
  if (!out) {
    std::fprintf(stderr, "error: cannot write %s\n", path.c_str());
    return false;
  }
  return true;
}

}  // namespace bench
}  // namespace collision_lab
