#include "engines.h"

namespace collision_lab {
namespace bench {

std::vector<SteppedMethod> steppedMethods() {
  std::vector<SteppedMethod> methods{fixedStepMethod()};
#ifdef COLLISION_LAB_BENCH_HAVE_BULLET
  methods.push_back(bulletMethod());
#endif
#ifdef COLLISION_LAB_BENCH_HAVE_ODE
  methods.push_back(odeMethod());
#endif
#ifdef COLLISION_LAB_BENCH_HAVE_BOX2D
  methods.push_back(box2dMethod());
#endif
  return methods;
}

}  // namespace bench
}  // namespace collision_lab
