// The DOE samplers (docs/doe.md, "Samplers") and their counter-based random
// numbers. Reference values come from independent computations, each given
// next to its test: a Python Philox written from the Random123 paper's
// constants, scipy.stats.qmc.Sobol, numpy.linspace, and closed forms.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "opt/doe/random.hpp"
#include "opt/doe/sampler.hpp"

namespace {

using opt::doe::Factor;
using opt::doe::Sampler;
using Points = std::vector<std::vector<double>>;

// d factors on [0, 1], so a point is its unit-cube coordinates.
std::vector<Factor> unit_factors(int d) {
  std::vector<Factor> f(static_cast<std::size_t>(d));
  for (int j = 0; j < d; ++j)
    f[static_cast<std::size_t>(j)] = {
        "x" + std::to_string(j), Factor::Kind::range, 0, 1, {}, {}, 0};
  return f;
}

Points points_in(const Sampler& s, std::size_t d, bool reverse = false) {
  Points p(static_cast<std::size_t>(s.size()), std::vector<double>(d));
  for (std::int64_t k = 0; k < s.size(); ++k) {
    const std::int64_t i = reverse ? s.size() - 1 - k : k;
    s.point(i, p[static_cast<std::size_t>(i)]);
  }
  return p;
}

double min_distance(const Points& p) {
  double smallest = std::numeric_limits<double>::infinity();
  for (std::size_t a = 0; a < p.size(); ++a)
    for (std::size_t b = a + 1; b < p.size(); ++b) {
      double s = 0;
      for (std::size_t j = 0; j < p[a].size(); ++j) s += (p[a][j] - p[b][j]) * (p[a][j] - p[b][j]);
      smallest = std::min(smallest, std::sqrt(s));
    }
  return smallest;
}

// True when every column has exactly one of the first `count` points in each
// of `count` equal intervals of [0, 1).
bool stratified(const Points& p, std::size_t count) {
  for (std::size_t j = 0; j < p[0].size(); ++j) {
    std::vector<int> hits(count, 0);
    for (std::size_t i = 0; i < count; ++i) {
      const double u = p[i][j];
      if (!(u >= 0 && u < 1)) return false;
      ++hits[static_cast<std::size_t>(std::floor(u * static_cast<double>(count)))];
    }
    if (std::any_of(hits.begin(), hits.end(), [](int h) { return h != 1; })) return false;
  }
  return true;
}

// ---- Philox -------------------------------------------------------------------

// Known answers of Philox4x32-10 (Random123's kat_vectors, also in Salmon et
// al., SC'11), verified with an independent Python implementation written from
// the paper's multipliers and Weyl constants:
//   M0, M1, W0, W1 = 0xD2511F53, 0xCD9E8D57, 0x9E3779B9, 0xBB67AE85
//   def philox(c, k):
//       for r in range(10):
//           if r: k = [(k[0] + W0) % 2**32, (k[1] + W1) % 2**32]
//           p0, p1 = M0 * c[0], M1 * c[2]
//           c = [(p1 >> 32) ^ c[1] ^ k[0], p1 % 2**32, (p0 >> 32) ^ c[3] ^ k[1], p0 % 2**32]
//       return c
// Our counter is {sample low, sample high, stream, domain}, key {seed low, seed high}.
TEST(DoeRandom, PhiloxKnownAnswers) {
  using W = std::array<std::uint32_t, 4>;
  EXPECT_EQ(opt::doe::philox(0, 0, 0, 0), (W{0x6627e8d5, 0xe169c58d, 0xbc57ac4c, 0x9b00dbd8}));
  EXPECT_EQ(opt::doe::philox(~0ull, ~0ull, 0xffffffff, 0xffffffff),
            (W{0x408f276d, 0x41c83b0e, 0xa20bc7c6, 0x6d5451fd}));
  // ctr {243f6a88 85a308d3 13198a2e 03707344}, key {a4093822 299f31d0} (digits of pi).
  EXPECT_EQ(opt::doe::philox(0x299f31d0a4093822ull, 0x85a308d3243f6a88ull, 0x13198a2e, 0x03707344),
            (W{0xd16cfe09, 0x94fdcceb, 0x5001e420, 0x24126ea1}));
}

// The same Python: r = philox([42, 0, 7, 0], [0x89abcdef, 0x01234567]);
// bits = r[0] | r[1] << 32 = 0x523af986db4c0f71; (bits >> 11) * 2**-53.
TEST(DoeRandom, UniformIsTheTop53BitsOfTwoPhiloxWords) {
  constexpr std::uint64_t seed = 0x0123456789abcdefull;
  EXPECT_EQ(opt::doe::random_bits(seed, 42, 7), 0x523af986db4c0f71ull);
  EXPECT_EQ(opt::doe::uniform(seed, 42, 7), 0.3212123827209298);
  EXPECT_EQ(opt::doe::uniform(seed, 42, 7), opt::doe::uniform(seed, 42, 7));
  EXPECT_NE(opt::doe::uniform(seed, 42, 8), opt::doe::uniform(seed, 42, 7));
  EXPECT_NE(opt::doe::uniform(seed + 1, 42, 7), opt::doe::uniform(seed, 42, 7));
  EXPECT_NE(opt::doe::uniform(seed, 42ull + (1ull << 32), 7), opt::doe::uniform(seed, 42, 7));
}

// ---- from_unit ----------------------------------------------------------------

TEST(DoeSamplers, FromUnitMapsRangesAndLevels) {
  const Factor range{"r", Factor::Kind::range, 2, 6, {}, {}, 0};
  EXPECT_EQ(opt::doe::from_unit(range, 0.0), 2.0);
  EXPECT_EQ(opt::doe::from_unit(range, 0.25), 3.0);
  const Factor levels{"l", Factor::Kind::levels, 0, 0, {10, 20, 30}, {}, 0};
  EXPECT_EQ(opt::doe::from_unit(levels, 0.0), 10.0);
  EXPECT_EQ(opt::doe::from_unit(levels, 0.34), 20.0);  // floor(1.02) = 1
  EXPECT_EQ(opt::doe::from_unit(levels, 0.999999999), 30.0);
  EXPECT_EQ(opt::doe::from_unit(levels, std::nextafter(1.0, 0.0)), 30.0);  // 3u rounds to 3
  const Factor choice{"c", Factor::Kind::categorical, 0, 0, {0, 1}, {"a", "b"}, 0};
  EXPECT_EQ(opt::doe::from_unit(choice, 0.49), 0.0);
  EXPECT_EQ(opt::doe::from_unit(choice, 0.5), 1.0);
}

// ---- factorial ------------------------------------------------------------------

// Order and values from Python:
//   list(itertools.product(numpy.linspace(-1.3, 2.9, 7), [10, 20], [0, 1, 2]))
// (the first factor slowest); linspace's values, as hex floats:
//   [x.hex() for x in numpy.linspace(-1.3, 2.9, 7)]
TEST(DoeFactorial, MixedRadixOrderFirstFactorSlowest) {
  const std::array<double, 7> linspace = {
      -0x1.4cccccccccccdp+0, -0x1.3333333333333p-1, 0x1.99999999999a0p-4, 0x1.999999999999ap-1,
      0x1.8000000000001p+0,  0x1.199999999999ap+1,  0x1.7333333333333p+1};
  const auto s =
      opt::doe::factorial({{"a", Factor::Kind::range, -1.3, 2.9, {}, {}, 7},
                           {"b", Factor::Kind::levels, 0, 0, {10, 20}, {}, 0},
                           {"c", Factor::Kind::categorical, 0, 0, {0, 1, 2}, {"x", "y", "z"}, 0}});
  ASSERT_EQ(s->size(), 7 * 2 * 3);
  std::int64_t i = 0;
  std::vector<double> p(3);
  for (double a : linspace)
    for (double b : {10.0, 20.0})
      for (double c : {0.0, 1.0, 2.0}) {
        s->point(i++, p);
        EXPECT_EQ(p, (std::vector<double>{a, b, c})) << "sample " << i - 1;
      }
  EXPECT_EQ(s->describe()["levels"], nlohmann::json({7, 2, 3}));
}

TEST(DoeFactorial, SizeOverflowIsRefused) {
  std::vector<Factor> f;
  for (int j = 0; j < 62; ++j)
    f.push_back({"x" + std::to_string(j), Factor::Kind::levels, 0, 0, {0, 1}, {}, 0});
  EXPECT_EQ(opt::doe::factorial(f)->size(), std::int64_t{1} << 62);
  f.push_back({"y", Factor::Kind::levels, 0, 0, {0, 1}, {}, 0});  // 2^63 > int64 max
  EXPECT_THROW(opt::doe::factorial(f), std::invalid_argument);
}

// ---- every sampler: a pure function of (seed, i) ----------------------------------

// Each sampler is built twice; points computed in order, in reverse and from the
// second (fresh) sampler, starting from the last index, must be bitwise equal.
TEST(DoeSamplers, PointsDoNotDependOnOrderOrInstance) {
  const std::vector<std::pair<std::string, std::function<std::unique_ptr<Sampler>()>>> samplers = {
      {"factorial",
       [] {
         auto f = unit_factors(4);
         for (auto& x : f) x.count = 4;
         return opt::doe::factorial(f);
       }},
      {"random", [] { return opt::doe::uniform_random(unit_factors(4), 300, 11); }},
      {"lhs", [] { return opt::doe::latin_hypercube(unit_factors(4), 300, 11, false); }},
      {"maximin", [] { return opt::doe::latin_hypercube(unit_factors(4), 300, 11, true); }},
      {"sobol", [] { return opt::doe::sobol(unit_factors(4), 300, std::nullopt); }},
      {"scrambled sobol", [] { return opt::doe::sobol(unit_factors(4), 300, 11); }},
      {"saltelli", [] { return opt::doe::saltelli(unit_factors(4), 50, 11); }},
  };
  for (const auto& [name, make] : samplers) {
    const auto first = make(), fresh = make();
    const Points forward = points_in(*first, 4);
    EXPECT_EQ(points_in(*first, 4, true), forward) << name;
    EXPECT_EQ(points_in(*fresh, 4, true), forward) << name;
    EXPECT_EQ(first->describe(), fresh->describe()) << name;
  }
}

// ---- uniform random ------------------------------------------------------------------

// Mean 1/2 and variance 1/12 of U(0, 1), within 5 standard errors for n draws:
// the mean's is sqrt(1/12 / n), the variance's sqrt((1/80 - 1/144) / n) (the
// fourth central moment of U(0, 1) is 1/80). Correlation: within 5 / sqrt(n).
TEST(DoeRandom, UniformSamplerMomentsAndRangeMapping) {
  constexpr int n = 100000, d = 3;
  auto f = unit_factors(d);
  f[2].lower = -4, f[2].upper = 6;  // u = (x + 4) / 10
  const auto s = opt::doe::uniform_random(f, n, 2024);
  std::array<double, d> sum{}, sum2{};
  double cross = 0;
  std::vector<double> p(d);
  for (int i = 0; i < n; ++i) {
    s->point(i, p);
    p[2] = (p[2] + 4) / 10;
    for (int j = 0; j < d; ++j) {
      ASSERT_TRUE(p[j] >= 0 && p[j] < 1);
      sum[j] += p[j];
      sum2[j] += (p[j] - 0.5) * (p[j] - 0.5);
    }
    cross += (p[0] - 0.5) * (p[1] - 0.5);
  }
  const double mean_tol = 5 * std::sqrt(1.0 / 12 / n);
  const double var_tol = 5 * std::sqrt((1.0 / 80 - 1.0 / 144) / n);
  for (int j = 0; j < d; ++j) {
    EXPECT_NEAR(sum[j] / n, 0.5, mean_tol) << j;
    EXPECT_NEAR(sum2[j] / n, 1.0 / 12, var_tol) << j;
  }
  EXPECT_NEAR(cross / n * 12, 0.0, 5 / std::sqrt(double{n}));
  EXPECT_EQ(s->describe()["seed"], 2024);
}

// ---- Latin hypercube --------------------------------------------------------------------

TEST(DoeLatinHypercube, OnePointPerStratumInEveryFactor) {
  for (std::int64_t n : {1, 2, 3, 17, 64, 1000, 4099}) {
    const auto s = opt::doe::latin_hypercube(unit_factors(5), n, 7, false);
    EXPECT_TRUE(stratified(points_in(*s, 5), static_cast<std::size_t>(n))) << n;
  }
}

TEST(DoeLatinHypercube, DifferentSeedsAndFactorsPermuteDifferently) {
  const Points a = points_in(*opt::doe::latin_hypercube(unit_factors(2), 100, 1, false), 2);
  const Points b = points_in(*opt::doe::latin_hypercube(unit_factors(2), 100, 2, false), 2);
  EXPECT_NE(a, b);
  int same_stratum = 0;  // factor 0 and 1 of the same sample: ~1 of 100 by chance
  for (const auto& p : a) same_stratum += std::floor(p[0] * 100) == std::floor(p[1] * 100);
  EXPECT_LT(same_stratum, 10);
}

// Candidate 0 of maximin is the plain hypercube of the same seed, so the
// chosen one's smallest distance (recomputed here) is at least the plain one's.
TEST(DoeLatinHypercube, MaximinIsNoWorseThanPlainAndStillStratified) {
  for (std::uint64_t seed : {1u, 2u, 3u, 4u, 5u}) {
    const auto plain = opt::doe::latin_hypercube(unit_factors(3), 60, seed, false);
    const auto best = opt::doe::latin_hypercube(unit_factors(3), 60, seed, true);
    const Points pb = points_in(*best, 3);
    EXPECT_GE(min_distance(pb), min_distance(points_in(*plain, 3))) << seed;
    EXPECT_TRUE(stratified(pb, 60)) << seed;
    EXPECT_DOUBLE_EQ(best->describe()["min_distance"].get<double>(), min_distance(pb)) << seed;
  }
}

TEST(DoeLatinHypercube, MaximinRefusesMoreThan5000Samples) {
  try {
    opt::doe::latin_hypercube(unit_factors(2), 5001, 1, true);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("5000"), std::string::npos) << e.what();
  }
  EXPECT_EQ(opt::doe::latin_hypercube(unit_factors(2), 5001, 1, false)->size(), 5001);
}

// ---- Sobol' ------------------------------------------------------------------------------

// scipy 1.10.1:
//   from scipy.stats import qmc
//   (qmc.Sobol(5, scramble=False).random(64) * 64).astype(int)
// (the first 64 points have 6 bits, so 64 x is exact).
constexpr int kSobolD5[64][5] = {
    {0, 0, 0, 0, 0},      {32, 32, 32, 32, 32}, {48, 16, 16, 16, 48}, {16, 48, 48, 48, 16},
    {24, 24, 40, 56, 24}, {56, 56, 8, 24, 56},  {40, 8, 56, 40, 40},  {8, 40, 24, 8, 8},
    {12, 20, 60, 28, 36}, {44, 52, 28, 60, 4},  {60, 4, 44, 12, 20},  {28, 36, 12, 44, 52},
    {20, 12, 20, 36, 60}, {52, 44, 52, 4, 28},  {36, 28, 4, 52, 12},  {4, 60, 36, 20, 44},
    {6, 30, 30, 42, 18},  {38, 62, 62, 10, 50}, {54, 14, 14, 58, 34}, {22, 46, 46, 26, 2},
    {30, 6, 54, 18, 10},  {62, 38, 22, 50, 42}, {46, 22, 38, 2, 58},  {14, 54, 6, 34, 26},
    {10, 10, 34, 54, 54}, {42, 42, 2, 22, 22},  {58, 26, 50, 38, 6},  {26, 58, 18, 6, 38},
    {18, 18, 10, 14, 46}, {50, 50, 42, 46, 14}, {34, 2, 26, 30, 30},  {2, 34, 58, 62, 62},
    {3, 17, 45, 35, 9},   {35, 49, 13, 3, 41},  {51, 1, 61, 51, 57},  {19, 33, 29, 19, 25},
    {27, 9, 5, 27, 17},   {59, 41, 37, 59, 49}, {43, 25, 21, 11, 33}, {11, 57, 53, 43, 1},
    {15, 5, 17, 63, 45},  {47, 37, 49, 31, 13}, {63, 21, 1, 47, 29},  {31, 53, 33, 15, 61},
    {23, 29, 57, 7, 53},  {55, 61, 25, 39, 21}, {39, 13, 41, 23, 5},  {7, 45, 9, 55, 37},
    {5, 15, 51, 9, 27},   {37, 47, 19, 41, 59}, {53, 31, 35, 25, 43}, {21, 63, 3, 57, 11},
    {29, 23, 27, 49, 3},  {61, 55, 59, 17, 35}, {45, 7, 11, 33, 51},  {13, 39, 43, 1, 19},
    {9, 27, 15, 21, 63},  {41, 59, 47, 53, 31}, {57, 11, 31, 5, 15},  {25, 43, 63, 37, 47},
    {17, 3, 39, 45, 39},  {49, 35, 7, 13, 7},   {33, 19, 55, 61, 23}, {1, 51, 23, 29, 55}};

TEST(DoeSobol, UnscrambledMatchesScipyInFiveDimensions) {
  const auto s = opt::doe::sobol(unit_factors(5), 64, std::nullopt);
  std::vector<double> p(5);
  for (int i = 0; i < 64; ++i) {
    s->point(i, p);
    for (int j = 0; j < 5; ++j)
      EXPECT_EQ(p[j] * 64, kSobolD5[i][j]) << "point " << i << " dim " << j;
  }
}

// scipy 1.10.1, dimensions 101, 555 and 1110 of a 1111-dimensional sequence:
//   cols = [101, 555, 1110]
//   (qmc.Sobol(1111, scramble=False).random(64)[:, cols] * 64).astype(int)    # kSobolHigh
//   s = qmc.Sobol(1111, scramble=False); s.fast_forward(100777)
//   (s.random(4)[:, cols] * 2**30).astype(np.int64)                           # kSobolDeep
// (scipy's default 30 bits make 2^30 x exact.)
constexpr int kSobolHigh[64][3] = {
    {0, 0, 0},    {32, 32, 32}, {16, 48, 48}, {48, 16, 16}, {56, 40, 56}, {24, 8, 24},
    {40, 24, 8},  {8, 56, 40},  {52, 44, 20}, {20, 12, 52}, {36, 28, 36}, {4, 60, 4},
    {12, 4, 44},  {44, 36, 12}, {28, 52, 28}, {60, 20, 60}, {54, 18, 26}, {22, 50, 58},
    {38, 34, 42}, {6, 2, 10},   {14, 58, 34}, {46, 26, 2},  {30, 10, 18}, {62, 42, 50},
    {2, 62, 14},  {34, 30, 46}, {18, 14, 62}, {50, 46, 30}, {58, 22, 54}, {26, 54, 22},
    {42, 38, 6},  {10, 6, 38},  {15, 1, 39},  {47, 33, 7},  {31, 49, 23}, {63, 17, 55},
    {55, 41, 31}, {23, 9, 63},  {39, 25, 47}, {7, 57, 15},  {59, 45, 51}, {27, 13, 19},
    {43, 29, 3},  {11, 61, 35}, {3, 5, 11},   {35, 37, 43}, {19, 53, 59}, {51, 21, 27},
    {57, 19, 61}, {25, 51, 29}, {41, 35, 13}, {9, 3, 45},   {1, 59, 5},   {33, 27, 37},
    {17, 11, 53}, {49, 43, 21}, {13, 63, 41}, {45, 31, 9},  {29, 15, 25}, {61, 47, 57},
    {53, 23, 17}, {21, 55, 49}, {37, 39, 33}, {5, 7, 1}};
constexpr std::int64_t kSobolDeep[4][3] = {{143794176, 605429760, 806690816},
                                           {949100544, 873865216, 538255360},
                                           {412229632, 336994304, 1384448},
                                           {278011904, 739647488, 672473088}};

TEST(DoeSobol, UnscrambledMatchesScipyInHighDimensions) {
  constexpr std::array<int, 3> cols = {101, 555, 1110};
  const auto s = opt::doe::sobol(unit_factors(1111), 100781, std::nullopt);
  std::vector<double> p(1111);
  for (int i = 0; i < 64; ++i) {
    s->point(i, p);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(p[cols[c]] * 64, kSobolHigh[i][c]) << "point " << i;
  }
  for (int k = 0; k < 4; ++k) {
    s->point(100777 + k, p);
    for (int c = 0; c < 3; ++c)
      EXPECT_EQ(p[cols[c]] * 0x1p30, static_cast<double>(kSobolDeep[k][c]))
          << "point " << 100777 + k;
  }
}

// A scramble keeps the net property: in every dimension, the first 2^m points
// fall one in each interval [k/2^m, (k+1)/2^m), for each m.
TEST(DoeSobol, ScrambledIsStratifiedAndSeeded) {
  const auto s = opt::doe::sobol(unit_factors(20), 1024, 99);
  const Points p = points_in(*s, 20);
  for (std::size_t m = 0; m <= 10; ++m) EXPECT_TRUE(stratified(p, std::size_t{1} << m)) << m;
  EXPECT_NE(p, points_in(*opt::doe::sobol(unit_factors(20), 1024, 100), 20));
  EXPECT_NE(p, points_in(*opt::doe::sobol(unit_factors(20), 1024, std::nullopt), 20));
  // A scrambled point has all 53 bits, not only the index's 10.
  EXPECT_NE(std::fmod(p[5][3] * 0x1p30, 1.0), 0.0);
  EXPECT_EQ(s->describe()["scrambled"], true);
}

TEST(DoeSobol, DimensionLimits) {
  EXPECT_EQ(opt::doe::sobol(unit_factors(1111), 2, std::nullopt)->size(), 2);
  EXPECT_THROW(opt::doe::sobol(unit_factors(1112), 2, std::nullopt), std::invalid_argument);
  EXPECT_EQ(opt::doe::saltelli(unit_factors(555), 1, 3)->size(), 557);
  EXPECT_THROW(opt::doe::saltelli(unit_factors(556), 1, 3), std::invalid_argument);
}

// ---- Saltelli ------------------------------------------------------------------------------

// A and B from scipy 1.10.1: (qmc.Sobol(4, scramble=False).random(16)[1:9] * 16).astype(int),
// A = columns 0, 1 and B = columns 2, 3; row r is Sobol' point r + 1 (point
// 0, all zeros, would make A = B in the first row; SALib skips it too).
TEST(DoeSaltelli, BlocksInterleavedByRow) {
  constexpr int kSobolD4[8][4] = {{8, 8, 8, 8},   {12, 4, 4, 4}, {4, 12, 12, 12}, {6, 6, 10, 14},
                                  {14, 14, 2, 6}, {10, 2, 14, 10}, {2, 10, 6, 2}, {3, 5, 15, 7}};
  const auto s = opt::doe::saltelli(unit_factors(2), 8, std::nullopt);
  ASSERT_EQ(s->size(), 8 * 4);
  std::vector<double> p(2);
  for (int row = 0; row < 8; ++row) {
    const auto* r = kSobolD4[row];
    const std::array<std::array<int, 2>, 4> blocks = {{{r[0], r[1]},    // A
                                                       {r[2], r[3]},    // B
                                                       {r[2], r[1]},    // A, column 0 from B
                                                       {r[0], r[3]}}};  // A, column 1 from B
    for (int b = 0; b < 4; ++b) {
      const std::int64_t i = 4 * row + b;
      EXPECT_EQ(opt::doe::saltelli_index(i, 2).row, row);
      EXPECT_EQ(opt::doe::saltelli_index(i, 2).block, b);
      s->point(i, p);
      EXPECT_EQ(p[0] * 16, blocks[b][0]) << "row " << row << " block " << b;
      EXPECT_EQ(p[1] * 16, blocks[b][1]) << "row " << row << " block " << b;
    }
  }
  EXPECT_EQ(s->describe()["base"], 8);
}

// With a seed, A and B are scrambled Sobol' columns: block 2 + j differs from
// A only in column j, where it equals B's.
TEST(DoeSaltelli, ScrambledBlocksShareColumns) {
  constexpr int d = 3;
  const auto s = opt::doe::saltelli(unit_factors(d), 16, 5);
  std::vector<double> a(d), b(d), ab(d);
  for (int row = 0; row < 16; ++row) {
    s->point(row * (d + 2), a);
    s->point(row * (d + 2) + 1, b);
    for (int j = 0; j < d; ++j) {
      s->point(row * (d + 2) + 2 + j, ab);
      for (int k = 0; k < d; ++k) EXPECT_EQ(ab[k], k == j ? b[k] : a[k]);
    }
  }
}

// ---- list and bad input ----------------------------------------------------------------------

TEST(DoeSamplers, PointListReturnsItsRows) {
  std::vector<Factor> f = {{"a", Factor::Kind::range, 0, 0, {}, {}, 0},
                           {"c", Factor::Kind::categorical, 0, 0, {0, 1}, {"x", "y"}, 0}};
  const Points rows = {{1.5, 1}, {-2, 0}};
  const auto s = opt::doe::point_list(f, rows);
  EXPECT_EQ(points_in(*s, 2), rows);
  EXPECT_EQ(s->describe()["sampler"], "list");
  EXPECT_THROW(opt::doe::point_list(f, {{1.5}}), std::invalid_argument);
  EXPECT_THROW(opt::doe::point_list(f, {{1.5, 2}}), std::invalid_argument);  // no option 2
  EXPECT_THROW(opt::doe::point_list(f, {{std::numeric_limits<double>::quiet_NaN(), 1}}),
               std::invalid_argument);
  EXPECT_THROW(opt::doe::point_list(f, {}), std::invalid_argument);
  std::vector<double> out(2);
  EXPECT_THROW(s->point(2, out), std::out_of_range);
}

TEST(DoeSamplers, BadInputIsRefused) {
  const auto unit = unit_factors(2);
  auto inverted = unit;
  inverted[1].lower = 1, inverted[1].upper = 1;
  auto twice = unit;
  twice[1].name = "x0";
  const std::vector<Factor> no_count = unit;  // ranges without count
  std::vector<Factor> count_one = unit;
  count_one[0].count = 1, count_one[1].count = 3;
  const std::vector<Factor> bad_labels = {{"c", Factor::Kind::categorical, 0, 0, {0, 1}, {"x"}, 0}};
  const std::vector<Factor> no_levels = {{"l", Factor::Kind::levels, 0, 0, {}, {}, 0}};

  EXPECT_THROW(opt::doe::uniform_random({}, 10, 1), std::invalid_argument);
  EXPECT_THROW(opt::doe::uniform_random(unit, 0, 1), std::invalid_argument);
  EXPECT_THROW(opt::doe::latin_hypercube(unit, -3, 1, false), std::invalid_argument);
  EXPECT_THROW(opt::doe::sobol(inverted, 10, std::nullopt), std::invalid_argument);
  EXPECT_THROW(opt::doe::saltelli(twice, 10, 1), std::invalid_argument);
  EXPECT_THROW(opt::doe::saltelli(unit, 0, 1), std::invalid_argument);
  EXPECT_THROW(opt::doe::factorial(no_count), std::invalid_argument);
  EXPECT_THROW(opt::doe::factorial(count_one), std::invalid_argument);
  EXPECT_THROW(opt::doe::factorial(bad_labels), std::invalid_argument);
  EXPECT_THROW(opt::doe::factorial(no_levels), std::invalid_argument);
  try {
    opt::doe::sobol(inverted, 10, std::nullopt);
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'x1'"), std::string::npos) << e.what();
  }
}

}  // namespace
