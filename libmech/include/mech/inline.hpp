// Forced inlining of the model's kernels and lane operations: GCC's size
// heuristics leave them out of line otherwise, and a recuperative DOE design
// then costs up to 1.5 times as much (docs/performance.md). Inlining changes
// no result (no contraction, the same operations in the same order), so the
// sanitizer build (MECH_NO_FORCED_INLINE, CMakeLists.txt) leaves the choice
// to the compiler: forced, each instrumented problem took up to 5 minutes
// to compile, most of a cold CI.
#pragma once

#ifdef MECH_NO_FORCED_INLINE
#define MECH_FORCE_INLINE
#else
#define MECH_FORCE_INLINE [[gnu::always_inline]]
#endif
#ifndef MECH_INLINE
#define MECH_INLINE MECH_FORCE_INLINE inline
#endif
