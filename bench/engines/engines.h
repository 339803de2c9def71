// Factories of the stepped methods. Each real engine's translation unit is compiled only
// when CMake found that engine; stepped_methods.cpp lists the ones present.
#pragma once

#include "stepped.h"

namespace collision_lab {
namespace bench {

SteppedMethod fixedStepMethod();
#ifdef COLLISION_LAB_BENCH_HAVE_BULLET
SteppedMethod bulletMethod();
#endif
#ifdef COLLISION_LAB_BENCH_HAVE_ODE
SteppedMethod odeMethod();
#endif
#ifdef COLLISION_LAB_BENCH_HAVE_BOX2D
SteppedMethod box2dMethod();
#endif

}  // namespace bench
}  // namespace collision_lab
