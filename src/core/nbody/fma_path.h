// The FMA path: where the CPU has fused multiply-add, the engine's hot loops (its working
// tier's step, and the known-count pass) run an instance compiled for it (target "fma"),
// chosen at run time; the portable instance stays for every other CPU and build. Both
// compute the same bits (double_double.h: only the exact two-product differs in code).
// COLLISION_LAB_NO_FMA=1 in the environment keeps a process on the portable path
// (benchmarks and the tests that compare the two). Internal to the engine; not installed.
#pragma once

#include "collision_lab/core/nbody/engine.h"

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#define CL_HAS_FMA_PATH 1
#define CL_FMA_TARGET __attribute__((target("fma")))
#else
#define CL_HAS_FMA_PATH 0
#define CL_FMA_TARGET
#endif

#if defined(__GNUC__)
#define CL_FLATTEN __attribute__((flatten))  // every call inlined: the loop in one function
#else
#define CL_FLATTEN
#endif

namespace collision_lab {
namespace core {
namespace nbody_detail {

/// Does the CPU have FMA (and this build an FMA path)?
bool cpuHasFma();

/// Does this process take the FMA path? The CPU has FMA and COLLISION_LAB_NO_FMA is unset,
/// empty or "0". Decided once per process.
bool fmaPathEnabled();

/// runEngine on the portable path (fma false) or the FMA path (fma true; the CPU must have
/// FMA), whatever fmaPathEnabled() says: for the test that compares the two.
SceneSimulation runEngineOnPath(bool fma, const Scene& scene, const EngineOptions& options,
                                const ImpactVisitor& visitor);

}  // namespace nbody_detail
}  // namespace core
}  // namespace collision_lab
