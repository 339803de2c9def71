// Bodies from CSV text (--bodies FILE, and `bodies:` in scenario files). ROS-free.
//
// Format: the header line `mass,position,velocity`, then one body per line, listed right to
// left (x_0 > x_1 > ...), numbers as on the command line (`inf` makes a wall). Blank lines
// and lines starting with '#' are skipped; a trailing '\r' is ignored. Reads 10^6 bodies in
// well under a second, in O(N) memory.
#pragma once

#include <istream>
#include <stdexcept>
#include <string>

#include "collision_lab/core/nbody/scene.h"

namespace collision_lab {
namespace io {

/// A malformed bodies file. `field` names the place ("bodies:12" = line 12, or
/// "bodies:12:mass"); `kind` says what is wrong.
struct BodiesFileError : std::runtime_error {
  enum class Kind { kUnreadable, kHeader, kWrongCount, kMalformedNumber };
  BodiesFileError(Kind kind, std::string field, const std::string& message)
      : std::runtime_error(message), kind(kind), field(std::move(field)) {}
  Kind kind;
  std::string field;
};

/// Reads masses, positions and velocities (restitution stays empty). Throws BodiesFileError.
core::Scene readBodiesCsv(std::istream& in);

/// The same from a file; "-" reads standard input. Throws BodiesFileError.
core::Scene readBodiesFile(const std::string& path);

}  // namespace io
}  // namespace collision_lab
