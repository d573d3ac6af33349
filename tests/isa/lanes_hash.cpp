// One hash of the twin drive's cycle metrics (values and gradients) over
// 20 000 random designs: built for SSE2, AVX2 and the build machine's own
// instruction set (tests/CMakeLists.txt), test_simd checks that all three
// print the same (docs/performance.md: the same numbers from every build).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>

#include "mech/twin_slider_crank.hpp"

int main() {
  std::mt19937_64 gen(11);
  std::uniform_real_distribution<double> u(0, 1);
  std::uint64_t hash = 1469598103934665603ull;
  auto mix = [&](double v) {
    std::uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    hash = (hash ^ bits) * 1099511628211ull;
  };
  for (int i = 0; i < 20000; ++i) {
    mech::TwinDrive<double> d{0.1 + 0.2 * u(gen), 0.3 + 1.3 * u(gen), M_PI * u(gen), -0.1 + 0.2 * u(gen),
                              100 * M_PI / 30, 1000, 80, 0.9, 3562};
    d.resistance = mech::Resistance::opposes_motion;
    if (mech::check(d) != mech::Status::ok) continue;
    const int n = mech::auto_cycle_points(d);
    const auto m = mech::cycle_metrics(d, n);
    for (double v : {m.mean_kinetic_energy, m.peak_kinetic_energy, m.mean_total_moment, m.rms_total_moment,
                     m.peak_total_moment})
      mix(v);
    auto g = d.cast<mech::DualN<2>>();
    g.rod_length = mech::seed<2>(d.rod_length, 0);
    g.phase_shift = mech::seed<2>(d.phase_shift, 1);
    const auto mean = mech::mean_kinetic_energy(g, n);
    mix(mean.value());
    mix(mean.derivatives()[0]);
    mix(mean.derivatives()[1]);
  }
  std::printf("%016llx\n", static_cast<unsigned long long>(hash));
}
