// Small formatting helpers shared by the report-writing benchmarks.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "collision_lab/core/scene.h"

namespace collision_lab {
namespace bench {

/// printf-style formatting into a std::string.
std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

/// A number for tables: "0" for exact zero, "nan" for NaN, else 3 significant digits.
std::string sci(double value);

/// "(a, b, c)" with %g, "inf" for walls.
std::string tripleText(const std::vector<double>& values);

/// max_i |a_i - b_i| / max_i |b_i| over the finite-mass bodies (walls are skipped);
/// absolute when b is all zero.
double relativeVelocityError(const core::Scene& scene, const std::array<double, 3>& a,
                             const std::array<double, 3>& b);

/// The same for N bodies: masses[i] = +inf marks a wall, which is skipped.
double relativeVelocityError(const std::vector<double>& masses, const std::vector<double>& a,
                             const std::vector<double>& b);

/// Kinetic energy of the finite masses [J], in long double.
long double kineticEnergy(const std::vector<double>& masses, const std::vector<double>& v);

/// The source version the results belong to, from $COLLISION_LAB_BENCH_SOURCE (set by
/// bench/run_benchmarks.sh to the commit, marked when src/ or include/ have local changes).
std::string sourceVersion();

/// Writes `text` to `path`, creating nothing else; false (and a message on stderr) on failure.
bool writeTextFile(const std::string& path, const std::string& text);

}  // namespace bench
}  // namespace collision_lab
