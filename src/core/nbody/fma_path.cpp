#include "fma_path.h"

#include <cstdlib>
#include <cstring>

namespace collision_lab {
namespace core {
namespace nbody_detail {

bool cpuHasFma() {
#if CL_HAS_FMA_PATH
  __builtin_cpu_init();
  return __builtin_cpu_supports("fma") != 0;
#else
  return false;
#endif
}

bool fmaPathEnabled() {
  static const bool enabled = [] {
    const char* off = std::getenv("COLLISION_LAB_NO_FMA");
    if (off != nullptr && *off != '\0' && std::strcmp(off, "0") != 0) return false;
    return cpuHasFma();
  }();
  return enabled;
}

}  // namespace nbody_detail
}  // namespace core
}  // namespace collision_lab
