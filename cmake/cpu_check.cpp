// Loaded with libmechopt_mech: a library built for AVX2 (MECHOPT_AVX2 found
// it on the building machine) stops with a message on a CPU without it,
// rather than at an illegal instruction inside a model (docs/package.md).
#include <cstdio>
#include <cstdlib>

namespace {

[[gnu::constructor]] void mechopt_cpu_check() {
#if defined(__AVX2__)
  if (!__builtin_cpu_supports("avx2")) {
    std::fputs("libmechopt_mech: built for AVX2, which this CPU lacks; build mechopt with -DMECHOPT_AVX2=OFF\n",
               stderr);
    std::abort();
  }
#endif
}

}  // namespace
