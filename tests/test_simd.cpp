// mech::Lanes and its sincos (libmech/include/mech/simd.hpp): the reference
// is the x87 long-double libm (sinl, cosl: 64-bit significands, an
// independent implementation), errors in units in the last place of the
// double result; and the twin drive's lane loops against its scalar loops
// (the same model summed in another order, the design-derivative path);
// and that an evaluation hands back the AVX registers' upper halves clean.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <limits>
#include <random>
#include <tuple>
#include <vector>

#if defined(__AVX__)
#include <cpuid.h>
#endif

#include "mech/conveyor_swing.hpp"
#include "mech/simd.hpp"
#include "mech/twin_slider_crank.hpp"
#include "opt/config.hpp"
#include "problems/conveyor_swing.hpp"

namespace {

using mech::kLanes;
using mech::Lanes;

double ulps(double got, long double exact) {
  const double rounded = static_cast<double>(exact);
  const double ulp = std::nextafter(std::abs(rounded), HUGE_VAL) - std::abs(rounded);
  return static_cast<double>(std::abs(static_cast<long double>(got) - exact) / ulp);
}

TEST(Lanes, SinCosWithinOneUlpOfTheLongDoubleLibm) {
  std::mt19937_64 gen(7);
  for (const double range : {1.0, 10.0, 1e3, 8e5}) {
    std::uniform_real_distribution<double> u(-range, range);
    double worst_sin = 0, worst_cos = 0;
    for (int i = 0; i < 200000; i += kLanes) {
      Lanes x, s, c;
      for (int j = 0; j < kLanes; ++j) x[j] = u(gen);
      mech::sincos(x, s, c);
      for (int j = 0; j < kLanes; ++j) {
        worst_sin = std::max(worst_sin, ulps(s[j], sinl(static_cast<long double>(x[j]))));
        worst_cos = std::max(worst_cos, ulps(c[j], cosl(static_cast<long double>(x[j]))));
      }
    }
    // Measured: at most 0.80 ulp (fdlibm's kernels with the reduction's tail).
    EXPECT_LT(worst_sin, 1.0) << "|x| < " << range;
    EXPECT_LT(worst_cos, 1.0) << "|x| < " << range;
  }
}

TEST(Lanes, SinCosAtSpecialAngles) {
  double s, c;
  mech::sincos(0.0, s, c);
  EXPECT_EQ(s, 0.0);
  EXPECT_EQ(c, 1.0);
  // Every quadrant, both signs: sin is odd and cos even, bit for bit.
  for (double x = 0.1; x < 20; x += 0.37) {
    double s1, c1, s2, c2;
    mech::sincos(x, s1, c1);
    mech::sincos(-x, s2, c2);
    EXPECT_EQ(s1, -s2) << x;
    EXPECT_EQ(c1, c2) << x;
    EXPECT_NEAR(s1 * s1 + c1 * c1, 1.0, 4e-16) << x;
  }
  // Beyond the reduction's range and not finite: the library's values.
  for (const double x : {1e6, -3e7, 1e300}) {
    mech::sincos(x, s, c);
    EXPECT_EQ(s, std::sin(x)) << x;
    EXPECT_EQ(c, std::cos(x)) << x;
  }
  for (const double x : {HUGE_VAL, -HUGE_VAL, std::numeric_limits<double>::quiet_NaN()}) {
    mech::sincos(x, s, c);
    EXPECT_TRUE(std::isnan(s) && std::isnan(c)) << x;
  }
}

TEST(Lanes, SinCosWithoutTheReductionIsTheSameBits) {
  // sincos_small (|x| < 0.78, the Gauss panels' half-angles) skips the
  // reduction by pi/2: the same bits as sincos at random angles, at +-0, at
  // tiny and subnormal ones and next to the bound.
  std::mt19937_64 gen(3);
  std::uniform_real_distribution<double> u(-0.78, 0.78);
  std::vector<double> xs = {0.0, -0.0, 1e-300, -4.9e-324, 1e-160, 1e-8, 0.7799999999999999, -0.7799999999999999};
  for (int i = 0; i < 20000; ++i) xs.push_back(u(gen));
  for (std::size_t i = 0; i + kLanes <= xs.size(); i += kLanes) {
    Lanes x, s, c, s_small, c_small;
    for (int j = 0; j < kLanes; ++j) x[j] = xs[i + static_cast<std::size_t>(j)];
    mech::sincos(x, s, c);
    mech::sincos_small(x, s_small, c_small);
    for (int j = 0; j < kLanes; ++j) {
      EXPECT_EQ(std::bit_cast<std::uint64_t>(s_small[j]), std::bit_cast<std::uint64_t>(s[j])) << x[j];
      EXPECT_EQ(std::bit_cast<std::uint64_t>(c_small[j]), std::bit_cast<std::uint64_t>(c[j])) << x[j];
    }
  }
}

TEST(Lanes, ALaneDoesNotDependOnItsNeighbours) {
  // The same angle in every lane, beside others: the same bits.
  const double x = 2.3456789;
  double s0, c0;
  mech::sincos(x, s0, c0);
  for (int j = 0; j < kLanes; ++j) {
    Lanes v = mech::iota(100.0), s, c;
    v[j] = x;
    mech::sincos(v, s, c);
    EXPECT_EQ(s[j], s0);
    EXPECT_EQ(c[j], c0);
  }
}

TEST(Lanes, TwinDriveLaneLoopsAgreeWithTheScalarLoops) {
  // The grid and the Gauss nodes run kLanes angles at a time for double,
  // Dual and DualN<N>; DualX (a run-time derivative count) keeps the scalar
  // loops with glibc's sin and cos. Same model, other rounding: the values
  // agree to a few ulps of their size. n = 30 is not a multiple of kLanes
  // (a partial last block).
  mech::TwinDrive<double> d{0.2, 0.8, 1.1, 0.03, 100 * M_PI / 30, 1000, 80, 0.9, 3562};
  d.resistance = mech::Resistance::opposes_motion;
  for (const int n : {16, 30, 64}) {
    const auto a = mech::cycle_metrics(d, n);
    const auto b = mech::cycle_metrics(d.cast<mech::DualX>(), n);
    EXPECT_NEAR(a.mean_kinetic_energy / b.mean_kinetic_energy.value(), 1, 1e-14) << n;
    EXPECT_NEAR(a.peak_kinetic_energy / b.peak_kinetic_energy.value(), 1, 1e-14) << n;
    EXPECT_NEAR(a.mean_total_moment, b.mean_total_moment.value(), 1e-14 * a.rms_total_moment) << n;
    EXPECT_NEAR(a.rms_total_moment / b.rms_total_moment.value(), 1, 1e-14) << n;
    EXPECT_NEAR(a.peak_total_moment / b.peak_total_moment.value(), 1, 1e-14) << n;
    EXPECT_NEAR(mech::mean_kinetic_energy(d, n) / mech::mean_kinetic_energy(d.cast<mech::DualX>(), n).value(), 1,
                1e-14);
  }
}

TEST(Lanes, ConveyorLaneLoopsAgreeWithTheScalarLoops) {
  // The conveyor's grid and Gauss nodes run kLanes angles at a time for
  // double and Dual; DualX keeps the scalar loops (glibc's sin and cos).
  // Seed 002's variant 1 and a longer crank; n = 30 leaves a partial block.
  for (const double l_co1 : {1.2, 1.6}) {
    const auto k = mech::synthesize_crank_rocker<double>(1.0, 2.2, l_co1, 1.0, 0.0, 16 * M_PI / 180).linkage;
    const mech::SwingMechanism<double> m{k, 12.0, 200.0, 3200.0, 3200 * 1.44, std::hypot(1.2, 1.0), 48.0};
    ASSERT_EQ(mech::check(m), mech::Status::ok);
    for (const int n : {30, 48}) {
      const auto a = mech::swing_metrics(m, n);
      const auto b = mech::swing_metrics(m.cast<mech::DualX>(), n);
      EXPECT_NEAR(a.mean_abs_moment / b.mean_abs_moment.value(), 1, 1e-14) << l_co1 << " " << n;
      EXPECT_NEAR(a.rms_moment / b.rms_moment.value(), 1, 1e-14) << l_co1 << " " << n;
      EXPECT_NEAR(a.peak_moment / b.peak_moment.value(), 1, 1e-14) << l_co1 << " " << n;
      EXPECT_NEAR(a.max_pressure_angle, b.max_pressure_angle.value(), 1e-15) << l_co1 << " " << n;
      // The design derivative through the lanes (LaneDual<1>) and the scalar loops.
      mech::SwingMechanism<mech::Dual> d = m.cast<mech::Dual>();
      mech::SwingMechanism<mech::DualX> dx = m.map([](double x) { return mech::DualX(x, Eigen::VectorXd::Zero(1)); });
      d.friction_moment.d = 1;  // d/dM_c: every moment's friction part
      dx.friction_moment.derivatives()[0] = 1;
      const auto g = mech::swing_metrics(d, n);
      const auto gx = mech::swing_metrics(dx, n);
      EXPECT_NEAR(g.rms_moment.d, gx.rms_moment.derivatives()[0], 1e-12 * std::abs(g.rms_moment.d)) << n;
      EXPECT_NEAR(g.mean_abs_moment.d, gx.mean_abs_moment.derivatives()[0], 1e-12 * std::abs(g.mean_abs_moment.d))
          << n;
    }
  }
}

TEST(Lanes, AValueIsTheSameBitsWithOrWithoutItsGradient) {
  // A driver asks for the value alone in its line searches and with the
  // gradient elsewhere: both must be one function, or it sees roundoff
  // noise as slope (LD_SLSQP took 34 evaluations for the rod length, not
  // 24, while the two paths summed in different orders).
  mech::TwinDrive<double> d{0.2, 0.8, 1.1, 0.03, 100 * M_PI / 30, 1000, 80, 0.9, 3562};
  d.resistance = mech::Resistance::opposes_motion;
  auto with_two = d.cast<mech::DualN<2>>();
  with_two.rod_length = mech::seed<2>(d.rod_length, 0);
  with_two.phase_shift = mech::seed<2>(d.phase_shift, 1);
  auto with_one = d.cast<mech::Dual>();
  with_one.rod_length = mech::Dual(d.rod_length, 1.0);
  for (const int n : {16, 30}) {
    const double mean = mech::mean_kinetic_energy(d, n);
    EXPECT_EQ(mean, mech::mean_kinetic_energy(with_one, n).v);
    EXPECT_EQ(mean, mech::mean_kinetic_energy(with_two, n).value());
    const auto a = mech::cycle_metrics(d, n);
    const auto b = mech::cycle_metrics(with_one, n);
    const auto c = mech::cycle_metrics(with_two, n);
    for (const auto& [x, y, z] : {std::tuple{a.mean_kinetic_energy, b.mean_kinetic_energy.v, c.mean_kinetic_energy.value()},
                                  std::tuple{a.mean_total_moment, b.mean_total_moment.v, c.mean_total_moment.value()},
                                  std::tuple{a.rms_total_moment, b.rms_total_moment.v, c.rms_total_moment.value()},
                                  std::tuple{a.peak_total_moment, b.peak_total_moment.v, c.peak_total_moment.value()},
                                  std::tuple{a.k1, b.k1.v, c.k1.value()}}) {
      EXPECT_EQ(x, y) << n;
      EXPECT_EQ(x, z) << n;
    }
    // The derivative in the rod length: central differences (step 1e-6 m).
    const double h = 1e-6;
    auto at = [&](double l) {
      auto e = d;
      e.rod_length = l;
      return mech::mean_kinetic_energy(e, n);
    };
    const double fd = (at(d.rod_length + h) - at(d.rod_length - h)) / (2 * h);
    EXPECT_NEAR(mech::mean_kinetic_energy(with_one, n).d, fd, 1e-6 * std::abs(fd));
    EXPECT_EQ(mech::mean_kinetic_energy(with_one, n).d, mech::mean_kinetic_energy(with_two, n).derivatives()[0]);
  }
}

#ifdef MECHOPT_LANES_HASH_DIR
// tests/isa/lanes_hash.cpp built four ways (tests/CMakeLists.txt): the
// cycle metrics and gradients of 20 000 designs hash to the same bits with
// SSE2 (two instructions a lane operation), AVX2 (one), this machine's own
// instruction set (on AVX-512 machines: FMA available, not used) and at -O3
// (the problems' level; the others are built at the project's -O2).
std::string first_line_of(const std::string& command) {
  std::string line;
  if (FILE* pipe = popen(command.c_str(), "r")) {
    char buffer[128];
    if (std::fgets(buffer, sizeof buffer, pipe)) line = buffer;
    EXPECT_EQ(pclose(pipe), 0) << command;
  }
  return line;
}

TEST(Lanes, EveryInstructionSetGivesTheSameBits) {
  const std::string dir = MECHOPT_LANES_HASH_DIR;
  const std::string sse2 = first_line_of(dir + "/lanes_hash_sse2");
  ASSERT_EQ(sse2.size(), 17u) << sse2;  // 16 hex digits and a newline
  EXPECT_EQ(first_line_of(dir + "/lanes_hash_native"), sse2);
  EXPECT_EQ(first_line_of(dir + "/lanes_hash_o3"), sse2);
  if (__builtin_cpu_supports("avx2")) {
    EXPECT_EQ(first_line_of(dir + "/lanes_hash_avx2"), sse2);
  }
}
#endif

#if defined(__AVX__)
// Whether the upper halves of the AVX registers are marked in use (XINUSE
// bit 2, read by XGETBV with ECX = 1), or -1 where the processor cannot say.
int avx_upper_in_use() {
  unsigned a, b, c, d;
  if (!__get_cpuid_count(0xd, 1, &a, &b, &c, &d) || !(a & 4)) return -1;
  unsigned lo, hi;
  asm volatile("xgetbv" : "=a"(lo), "=d"(hi) : "c"(1));
  return (lo >> 2) & 1;
}

TEST(Avx, AnEvaluationHandsBackTheUpperHalvesClean) {
  // Code built without AVX (SQLite, NLopt, the C++ runtime) runs slowly
  // after a model that leaves them in use (problem.cpp, leave_avx): GCC 12
  // leaves them so in the conveyor's Grashof check, whose failed designs
  // return right after it.
  // XGETBV 1 exists on x86 since Skylake and Zen; on an older processor
  // the test fails and says why rather than pass unchecked.
  ASSERT_GE(avx_upper_in_use(), 0) << "XGETBV 1 (XINUSE) is not available: this check cannot read the state";
  const auto p = problems::make_conveyor_swing(opt::ConfigNode::parse(R"(
problem: conveyor_swing
model: {design: free_links, frame_x: 1.0 m, frame_y: 2.2 m, crank_speed: 12 rad/s}
variables:
  crank_length: {min: 0.3 m, max: 1.6 m}
  coupler_length: {min: 0.3 m, max: 1.6 m}
  rocker_length: {min: 0.3 m, max: 3.0 m}
)", "<avx>"));
  // Not Grashof (0.3 + 2.42 > 1.6 + 1.0 m), cannot be assembled, and one that runs.
  for (const Eigen::Vector3d& x : {Eigen::Vector3d(0.3, 1.6, 1.0), Eigen::Vector3d(1.6, 0.3, 0.3),
                                  Eigen::Vector3d(0.4, 2.2, 1.0)}) {
    const auto e = p->evaluate(x, opt::MetricSet::all(), false);
    EXPECT_EQ(avx_upper_in_use(), 0) << x.transpose() << ": " << mech::to_string(e.status);
  }
}
#endif

}  // namespace
