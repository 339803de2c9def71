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

std::string triple(const std::array<double, 3>& values) {
  return format("(%g, %g, %g)", values[0], values[1], values[2]);
}

double relativeVelocityError(const core::ThreeBodyScene& scene, const std::array<double, 3>& a,
                             const std::array<double, 3>& b) {
  double diff = 0.0, scale = 0.0;
  for (int i = 0; i < 3; ++i) {
    if (scene.isWall(i)) continue;
    diff = std::max(diff, std::fabs(a[i] - b[i]));
    scale = std::max(scale, std::fabs(b[i]));
    if (std::isnan(a[i])) return NAN;
  }
  return scale > 0.0 ? diff / scale : diff;
}

double energyRelativeDrift(const core::ThreeBodyScene& scene, const std::array<double, 3>& v) {
  long double e0 = 0, e = 0;
  for (int i = 0; i < 3; ++i) {
    if (scene.isWall(i)) continue;
    const long double m = scene.masses[i];
    e0 += m * scene.velocities[i] * scene.velocities[i] / 2;
    e += m * static_cast<long double>(v[i]) * v[i] / 2;
  }
  return static_cast<double>(std::fabs(e - e0) / e0);
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
