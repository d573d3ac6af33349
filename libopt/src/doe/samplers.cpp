// The samplers of docs/doe.md: each point(i) is a pure function of (seed, i).
#include "opt/doe/sampler.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <iterator>
#include <limits>
#include <set>
#include <stdexcept>
#include <utility>

#include "opt/doe/random.hpp"

namespace opt::doe {
namespace {

[[noreturn]] void fail(const std::string& sampler, const std::string& what) {
  throw std::invalid_argument("doe sampler '" + sampler + "': " + what);
}

std::string quoted(const Factor& f) { return "factor '" + f.name + "'"; }

// What every sampler needs of its factors: at least one, unique non-empty
// names, levels that exist, categorical options 0..k-1 with a label each, and
// (unless the sampler takes its values elsewhere) a non-empty finite range.
void check_factors(const std::vector<Factor>& factors, const std::string& sampler,
                   bool ranges_used) {
  if (factors.empty()) fail(sampler, "no factors (expected at least one)");
  std::set<std::string> seen;
  for (const Factor& f : factors) {
    if (f.name.empty()) fail(sampler, "a factor has an empty name");
    if (!seen.insert(f.name).second) fail(sampler, quoted(f) + " appears twice");
    switch (f.kind) {
      case Factor::Kind::range:
        if (ranges_used && !(std::isfinite(f.lower) && std::isfinite(f.upper) && f.upper > f.lower))
          fail(sampler, quoted(f) + ": range [" + std::to_string(f.lower) + ", " +
                            std::to_string(f.upper) + "] needs finite bounds with upper > lower");
        break;
      case Factor::Kind::levels:
        if (f.levels.empty()) fail(sampler, quoted(f) + ": no levels");
        for (double v : f.levels)
          if (!std::isfinite(v)) fail(sampler, quoted(f) + ": a level is not finite");
        break;
      case Factor::Kind::categorical:
        if (f.levels.empty()) fail(sampler, quoted(f) + ": no options");
        if (f.labels.size() != f.levels.size())
          fail(sampler, quoted(f) + ": " + std::to_string(f.labels.size()) + " labels for " +
                            std::to_string(f.levels.size()) + " options");
        for (std::size_t k = 0; k < f.levels.size(); ++k)
          if (f.levels[k] != static_cast<double>(k))
            fail(sampler, quoted(f) + ": option indices must be 0.." +
                              std::to_string(f.levels.size() - 1) + " in order");
        break;
    }
  }
}

void check_samples(std::int64_t n, const std::string& sampler) {
  if (n < 1) fail(sampler, std::to_string(n) + " samples (expected at least 1)");
}

// Misuse by the caller (an index outside the design, a buffer of the wrong
// width): cheap next to an evaluation, and it would otherwise read past a list.
void check_point(std::int64_t i, std::int64_t n, std::span<double> out, std::size_t d) {
  if (i < 0 || i >= n)
    throw std::out_of_range("doe sampler: sample " + std::to_string(i) + " outside [0, " +
                            std::to_string(n) + ")");
  if (out.size() != d)
    throw std::invalid_argument("doe sampler: output of width " + std::to_string(out.size()) +
                                " for " + std::to_string(d) + " factors");
}

nlohmann::json header(const std::string& sampler, std::optional<std::uint64_t> seed, std::int64_t n,
                      const std::vector<Factor>& factors) {
  nlohmann::json names = nlohmann::json::array();
  for (const Factor& f : factors) names.push_back(f.name);
  return {{"sampler", sampler},
          {"seed", seed ? nlohmann::json(*seed) : nlohmann::json(nullptr)},
          {"samples", n},
          {"factors", names}};
}

// u in [0, 1) as a double: the largest double below 1 caps a quotient that
// rounds up to 1.
double below_one(double u) { return std::min(u, std::nextafter(1.0, 0.0)); }

// ---- factorial -------------------------------------------------------------

class Factorial final : public Sampler {
 public:
  explicit Factorial(std::vector<Factor> f) : factors_(std::move(f)) {
    const std::string name = "factorial";
    check_factors(factors_, name, true);
    n_ = 1;
    for (const Factor& f : factors_) {
      std::int64_t radix = static_cast<std::int64_t>(f.levels.size());
      if (f.kind == Factor::Kind::range) {
        if (f.count < 2)
          fail(name, quoted(f) + ": a range in a factorial needs count >= 2 (got " +
                         std::to_string(f.count) + ")");
        radix = f.count;
      }
      if (__builtin_mul_overflow(n_, radix, &n_))
        fail(name, "the number of level combinations overflows 64-bit integers");
      radix_.push_back(radix);
    }
  }
  std::int64_t size() const override { return n_; }
  void point(std::int64_t i, std::span<double> out) const override {
    check_point(i, n_, out, factors_.size());
    // Mixed-radix digits, the last factor fastest.
    for (std::size_t j = factors_.size(); j-- > 0;) {
      out[j] = level(factors_[j], i % radix_[j]);
      i /= radix_[j];
    }
  }
  nlohmann::json describe() const override {
    nlohmann::json d = header("factorial", std::nullopt, n_, factors_);
    d["levels"] = radix_;
    return d;
  }

 private:
  // numpy.linspace's levels: lower + k step, the last exactly upper.
  static double level(const Factor& f, std::int64_t k) {
    if (f.kind != Factor::Kind::range) return f.levels[static_cast<std::size_t>(k)];
    if (k == f.count - 1) return f.upper;
    return f.lower + static_cast<double>(k) * ((f.upper - f.lower) / (f.count - 1));
  }
  std::vector<Factor> factors_;
  std::vector<std::int64_t> radix_;
  std::int64_t n_ = 0;
};

// ---- uniform random ----------------------------------------------------------

class UniformRandom final : public Sampler {
 public:
  UniformRandom(std::vector<Factor> f, std::int64_t n, std::uint64_t seed)
      : factors_(std::move(f)), n_(n), seed_(seed) {
    check_factors(factors_, "random", true);
    check_samples(n_, "random");
  }
  std::int64_t size() const override { return n_; }
  void point(std::int64_t i, std::span<double> out) const override {
    check_point(i, n_, out, factors_.size());
    for (std::size_t j = 0; j < factors_.size(); ++j)
      out[j] = from_unit(factors_[j], uniform(seed_, static_cast<std::uint64_t>(i),
                                              static_cast<std::uint32_t>(j)));
  }
  nlohmann::json describe() const override { return header("random", seed_, n_, factors_); }

 private:
  std::vector<Factor> factors_;
  std::int64_t n_;
  std::uint64_t seed_;
};

// ---- Latin hypercube -----------------------------------------------------------

// A keyed bijection of [0, n) in O(1) memory: a 4-round balanced Feistel
// network on the smallest even number of bits whose range covers n, with
// cycle-walking (re-encrypt until the value is below n; since that range is
// under 4n, fewer than 4 steps on average). Round r's function is Philox of
// the right half under the key (seed, stream, feistel + r).
class Permutation {
 public:
  Permutation(std::uint64_t n, std::uint64_t seed, std::uint32_t stream)
      : n_(n), seed_(seed), stream_(stream) {
    const int bits = std::bit_width(n - 1);  // 0 for n = 1
    half_ = std::max(1, (bits + 1) / 2);
    mask_ = (half_ == 32) ? 0xFFFFFFFFull : (std::uint64_t{1} << half_) - 1;
  }
  std::uint64_t operator()(std::uint64_t x) const {
    do x = encrypt(x);
    while (x >= n_);
    return x;
  }

 private:
  static constexpr std::uint32_t kRounds = 4;
  std::uint64_t encrypt(std::uint64_t x) const {
    std::uint64_t left = x >> half_, right = x & mask_;
    for (std::uint32_t r = 0; r < kRounds; ++r) {
      const std::uint64_t f = philox_bits(seed_, right, stream_, domain::feistel + r) & mask_;
      const std::uint64_t next = left ^ f;
      left = right;
      right = next;
    }
    return (left << half_) | right;
  }
  std::uint64_t n_, seed_;
  std::uint32_t stream_;
  int half_;
  std::uint64_t mask_;
};

// One Latin hypercube in the unit cube under one key: factor j of sample i
// lies in stratum pi_j(i), jittered by uniform(key, i, j).
class Hypercube {
 public:
  Hypercube(std::int64_t n, std::size_t d, std::uint64_t key) : n_(n), key_(key) {
    for (std::size_t j = 0; j < d; ++j)
      strata_.emplace_back(static_cast<std::uint64_t>(n), key, static_cast<std::uint32_t>(j));
  }
  double unit(std::int64_t i, std::size_t j) const {
    const auto s = static_cast<std::uint64_t>(i);
    const auto stream = static_cast<std::uint32_t>(j);
    const double stratum = static_cast<double>(strata_[j](s));
    return below_one((stratum + uniform(key_, s, stream)) / static_cast<double>(n_));
  }

 private:
  std::int64_t n_;
  std::uint64_t key_;
  std::vector<Permutation> strata_;
};

// The smallest pairwise squared distance of the hypercube's points, or any
// value <= floor once it is known to be no larger than floor (pruning: such a
// candidate cannot win). Infinity for a single point.
double min_squared_distance(const Hypercube& cube, std::int64_t n, std::size_t d, double floor) {
  std::vector<double> u(static_cast<std::size_t>(n) * d);
  for (std::int64_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < d; ++j) u[static_cast<std::size_t>(i) * d + j] = cube.unit(i, j);
  double smallest = std::numeric_limits<double>::infinity();
  for (std::size_t a = 0; a < static_cast<std::size_t>(n); ++a) {
    for (std::size_t b = a + 1; b < static_cast<std::size_t>(n); ++b) {
      double s = 0;
      for (std::size_t j = 0; j < d; ++j) {
        const double diff = u[a * d + j] - u[b * d + j];
        s += diff * diff;
      }
      smallest = std::min(smallest, s);
    }
    if (smallest <= floor) return smallest;
  }
  return smallest;
}

class LatinHypercube final : public Sampler {
 public:
  static constexpr int kCandidates = 16;
  static constexpr std::int64_t kMaximinLimit = 5000;

  LatinHypercube(std::vector<Factor> f, std::int64_t n, std::uint64_t seed, bool maximin)
      : factors_(std::move(f)), n_(n), seed_(seed), maximin_(maximin), key_(seed) {
    const std::string name = "latin_hypercube";
    check_factors(factors_, name, true);
    check_samples(n_, name);
    if (maximin_) choose_candidate(name);
    cube_.emplace(n_, factors_.size(), key_);
  }
  std::int64_t size() const override { return n_; }
  void point(std::int64_t i, std::span<double> out) const override {
    check_point(i, n_, out, factors_.size());
    for (std::size_t j = 0; j < factors_.size(); ++j)
      out[j] = from_unit(factors_[j], cube_->unit(i, j));
  }
  nlohmann::json describe() const override {
    nlohmann::json d = header("latin_hypercube", seed_, n_, factors_);
    d["maximin"] = maximin_;
    if (maximin_) {
      d["candidate"] = candidate_;
      d["min_distance"] =
          std::isfinite(min_distance_) ? nlohmann::json(min_distance_) : nlohmann::json(nullptr);
    }
    return d;
  }

 private:
  // Candidate 0 is the plain hypercube of the seed (so maximin never does
  // worse than it); candidate k > 0 is keyed by Philox of (seed, k). Ties keep
  // the earlier candidate.
  void choose_candidate(const std::string& name) {
    if (n_ > kMaximinLimit)
      fail(name, "maximin with " + std::to_string(n_) + " samples; the limit is " +
                     std::to_string(kMaximinLimit) + " (the criterion costs O(16 N^2 d))");
    double best = -1;
    for (int k = 0; k < kCandidates; ++k) {
      const std::uint64_t key =
          k == 0 ? seed_
                 : philox_bits(seed_, static_cast<std::uint64_t>(k), 0, domain::derived_seed);
      const double s =
          min_squared_distance(Hypercube(n_, factors_.size(), key), n_, factors_.size(), best);
      if (s > best) best = s, key_ = key, candidate_ = k;
    }
    min_distance_ = std::sqrt(best);
  }

  std::vector<Factor> factors_;
  std::int64_t n_;
  std::uint64_t seed_;
  bool maximin_;
  std::uint64_t key_;  // the chosen hypercube's key
  int candidate_ = 0;
  double min_distance_ = 0;
  std::optional<Hypercube> cube_;
};

// ---- Sobol' -------------------------------------------------------------------

struct SobolDimension {
  std::uint32_t poly;   // primitive polynomial with leading and constant terms
  std::uint32_t m[18];  // initial direction integers, degree(poly) of them
};
constexpr SobolDimension kSobolTable[] = {
#include "sobol_directions.inc"
};
constexpr int kSobolDimensions = static_cast<int>(std::size(kSobolTable));

// Sobol' points of dimensions [0, d) as 64-bit binary fractions. Point i is
// the XOR of the direction numbers selected by the bits of i's Gray code
// i ^ (i >> 1): scipy.stats.qmc.Sobol enumerates in Gray-code order, and
// since its direction numbers (30 bits by default) are ours shifted right,
// its points are exactly ours for i < 2^30. With a seed, each dimension's
// direction numbers are multiplied by a random lower-triangular binary matrix
// with unit diagonal (the bits counted from the most significant), and the
// points XORed with a random shift, as scipy's LMS + digital shift: the
// matrix keeps every dimension's first 2^m points one per [k/2^m, (k+1)/2^m).
class SobolSequence {
 public:
  SobolSequence(int d, std::optional<std::uint64_t> seed)
      : v_(static_cast<std::size_t>(d)), shift_(d, 0) {
    for (int j = 0; j < d; ++j) {
      v_[j] = directions(j);
      if (seed) scramble(j, *seed);
    }
  }
  // Dimension j of point i, in [0, 1) with the top 53 bits.
  double unit(std::uint64_t i, int j) const {
    std::uint64_t x = shift_[j];
    for (std::uint64_t g = i ^ (i >> 1); g != 0; g &= g - 1) x ^= v_[j][std::countr_zero(g)];
    return static_cast<double>(x >> 11) * 0x1p-53;
  }

 private:
  using Directions = std::array<std::uint64_t, 64>;
  // Bratley-Fox / Joe-Kuo recurrence on the direction integers m_k (scipy's
  // _initialize_v); dimension 0 has every m_k = 1.
  static Directions directions(int j) {
    const SobolDimension& t = kSobolTable[j];
    Directions m{};
    const int degree = j == 0 ? 0 : std::bit_width(t.poly) - 1;
    for (int k = 0; k < 64; ++k) {
      if (j == 0) {
        m[k] = 1;
      } else if (k < degree) {
        m[k] = t.m[k];
      } else {
        std::uint64_t next = m[k - degree];
        for (int b = 0; b < degree; ++b)
          if ((t.poly >> (degree - 1 - b)) & 1) next ^= m[k - b - 1] << (b + 1);
        m[k] = next;
      }
    }
    Directions v{};
    for (int k = 0; k < 64; ++k) v[k] = m[k] << (63 - k);  // m_k < 2^(k+1)
    return v;
  }
  void scramble(int j, std::uint64_t seed) {
    const auto stream = static_cast<std::uint32_t>(j);
    std::array<std::uint64_t, 64> rows{};  // row p: output bit 63 - p
    for (int p = 0; p < 64; ++p) {
      const std::uint64_t diagonal = std::uint64_t{1} << (63 - p);
      const std::uint64_t at_or_above = ~(diagonal - 1);  // bits 63 .. 63 - p
      rows[p] = (philox_bits(seed, static_cast<std::uint64_t>(p), stream, domain::sobol_scramble) &
                 at_or_above) |
                diagonal;
    }
    for (std::uint64_t& v : v_[j]) {
      std::uint64_t out = 0;
      for (int p = 0; p < 64; ++p)
        out |= static_cast<std::uint64_t>(std::popcount(rows[p] & v) & 1) << (63 - p);
      v = out;
    }
    shift_[j] = philox_bits(seed, 64, stream, domain::sobol_scramble);
  }
  std::vector<Directions> v_;
  std::vector<std::uint64_t> shift_;
};

// Checks a Sobol'-based sampler's input; returns the number of Sobol'
// dimensions it uses (per_factor of them per factor).
int sobol_dimensions(const std::vector<Factor>& factors, std::int64_t n, int per_factor,
                     const std::string& sampler) {
  check_factors(factors, sampler, true);
  check_samples(n, sampler);
  const std::size_t d = factors.size();
  if (d * static_cast<std::size_t>(per_factor) > static_cast<std::size_t>(kSobolDimensions))
    fail(sampler, std::to_string(d) + " factors; the limit is " +
                      std::to_string(kSobolDimensions / per_factor) + " (" +
                      std::to_string(kSobolDimensions) + " Sobol' dimensions in the table)");
  return static_cast<int>(d) * per_factor;
}

class Sobol final : public Sampler {
 public:
  Sobol(std::vector<Factor> f, std::int64_t n, std::optional<std::uint64_t> seed)
      : factors_(std::move(f)),
        n_(n),
        seed_(seed),
        sequence_(sobol_dimensions(factors_, n_, 1, "sobol"), seed) {}
  std::int64_t size() const override { return n_; }
  void point(std::int64_t i, std::span<double> out) const override {
    check_point(i, n_, out, factors_.size());
    for (std::size_t j = 0; j < factors_.size(); ++j)
      out[j] = from_unit(factors_[j],
                         sequence_.unit(static_cast<std::uint64_t>(i), static_cast<int>(j)));
  }
  nlohmann::json describe() const override {
    nlohmann::json d = header("sobol", seed_, n_, factors_);
    d["scrambled"] = seed_.has_value();
    return d;
  }

 private:
  std::vector<Factor> factors_;
  std::int64_t n_;
  std::optional<std::uint64_t> seed_;
  SobolSequence sequence_;
};

// ---- Saltelli -------------------------------------------------------------------

class Saltelli final : public Sampler {
 public:
  Saltelli(std::vector<Factor> f, std::int64_t base, std::optional<std::uint64_t> seed)
      : factors_(std::move(f)),
        base_(base),
        seed_(seed),
        sequence_(sobol_dimensions(factors_, base_, 2, "saltelli"), seed) {
    const auto blocks = static_cast<std::int64_t>(factors_.size()) + 2;
    if (__builtin_mul_overflow(base_, blocks, &n_))
      fail("saltelli", "base " + std::to_string(base_) + " times " + std::to_string(blocks) +
                           " blocks overflows 64-bit integers");
  }
  std::int64_t size() const override { return n_; }
  void point(std::int64_t i, std::span<double> out) const override {
    check_point(i, n_, out, factors_.size());
    const int d = static_cast<int>(factors_.size());
    const SaltelliIndex at = saltelli_index(i, d);
    for (int j = 0; j < d; ++j) {
      const bool from_b = at.block == 1 || at.block == 2 + j;
      // Row r is Sobol' point r + 1: point 0 (all zeros unscrambled) would make A = B.
      const double u = sequence_.unit(static_cast<std::uint64_t>(at.row) + 1, from_b ? d + j : j);
      out[static_cast<std::size_t>(j)] = from_unit(factors_[static_cast<std::size_t>(j)], u);
    }
  }
  nlohmann::json describe() const override {
    nlohmann::json d = header("saltelli", seed_, n_, factors_);
    d["base"] = base_;
    d["scrambled"] = seed_.has_value();
    return d;
  }

 private:
  std::vector<Factor> factors_;
  std::int64_t base_;
  std::optional<std::uint64_t> seed_;
  SobolSequence sequence_;
  std::int64_t n_ = 0;
};

// ---- list -------------------------------------------------------------------------

class PointList final : public Sampler {
 public:
  PointList(std::vector<Factor> f, std::vector<std::vector<double>> rows)
      : factors_(std::move(f)), rows_(std::move(rows)) {
    const std::string name = "list";
    check_factors(factors_, name, false);
    check_samples(static_cast<std::int64_t>(rows_.size()), name);
    for (std::size_t r = 0; r < rows_.size(); ++r) {
      const std::string row = "row " + std::to_string(r) + ": ";
      if (rows_[r].size() != factors_.size())
        fail(name, row + std::to_string(rows_[r].size()) + " values for " +
                       std::to_string(factors_.size()) + " factors");
      for (std::size_t j = 0; j < factors_.size(); ++j) {
        const double v = rows_[r][j];
        const Factor& f = factors_[j];
        if (!std::isfinite(v)) fail(name, row + quoted(f) + " is not finite");
        if (f.kind == Factor::Kind::categorical &&
            std::find(f.levels.begin(), f.levels.end(), v) == f.levels.end())
          fail(name, row + quoted(f) + ": " + std::to_string(v) + " is not an option index 0.." +
                         std::to_string(f.levels.size() - 1));
      }
    }
  }
  std::int64_t size() const override { return static_cast<std::int64_t>(rows_.size()); }
  void point(std::int64_t i, std::span<double> out) const override {
    check_point(i, size(), out, factors_.size());
    const auto& row = rows_[static_cast<std::size_t>(i)];
    std::copy(row.begin(), row.end(), out.begin());
  }
  nlohmann::json describe() const override {
    return header("list", std::nullopt, size(), factors_);
  }

 private:
  std::vector<Factor> factors_;
  std::vector<std::vector<double>> rows_;
};

}  // namespace

double from_unit(const Factor& f, double u) {
  if (f.kind == Factor::Kind::range) return f.lower + u * (f.upper - f.lower);
  const std::size_t k = f.levels.size();
  return f
      .levels[std::min(k - 1, static_cast<std::size_t>(std::floor(u * static_cast<double>(k))))];
}

SaltelliIndex saltelli_index(std::int64_t i, int d) {
  return {i / (d + 2), static_cast<int>(i % (d + 2))};
}

std::unique_ptr<Sampler> factorial(std::vector<Factor> f) {
  return std::make_unique<Factorial>(std::move(f));
}
std::unique_ptr<Sampler> uniform_random(std::vector<Factor> f, std::int64_t n, std::uint64_t seed) {
  return std::make_unique<UniformRandom>(std::move(f), n, seed);
}
std::unique_ptr<Sampler> latin_hypercube(std::vector<Factor> f, std::int64_t n, std::uint64_t seed,
                                         bool maximin) {
  return std::make_unique<LatinHypercube>(std::move(f), n, seed, maximin);
}
std::unique_ptr<Sampler> sobol(std::vector<Factor> f, std::int64_t n,
                               std::optional<std::uint64_t> seed) {
  return std::make_unique<Sobol>(std::move(f), n, seed);
}
std::unique_ptr<Sampler> point_list(std::vector<Factor> f, std::vector<std::vector<double>> rows) {
  return std::make_unique<PointList>(std::move(f), std::move(rows));
}
std::unique_ptr<Sampler> saltelli(std::vector<Factor> f, std::int64_t base,
                                  std::optional<std::uint64_t> seed) {
  return std::make_unique<Saltelli>(std::move(f), base, seed);
}

}  // namespace opt::doe
