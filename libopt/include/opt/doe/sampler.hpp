// Factors and samplers of a design of experiments (docs/doe.md, "Samplers").
//
// A sampler maps a sample index i in [0, N) to a point, one value per factor,
// as a pure function of (seed, i): nothing is carried from one sample to the
// next, so threads, MPI ranks, shards and resumed runs all see the same
// points. Apart from point_list (which holds its rows) and maximin Latin
// hypercubes (which pick one of 16 keys at construction), a sampler's memory
// does not grow with N.
#pragma once

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace opt::doe {

struct Factor {
  std::string name;
  enum class Kind { range, levels, categorical } kind = Kind::range;
  double lower = 0, upper = 0;      // range, SI
  std::vector<double> levels;       // levels: SI values; categorical: option indices 0..k-1
  std::vector<std::string> labels;  // categorical: option names (labels.size() == levels.size())
  int count = 0;  // a range in a factorial: number of evenly spaced levels incl. both ends (>= 2)
};

class Sampler {
 public:
  virtual ~Sampler() = default;
  // Number of samples N.
  virtual std::int64_t size() const = 0;
  // Sample i's factor values (SI; a categorical factor's option index), one
  // per factor, into out (out.size() == number of factors). 0 <= i < size().
  virtual void point(std::int64_t i, std::span<double> out) const = 0;
  // {"sampler": name, "seed": seed or null, "samples": N, "factors": [names], ...}
  // for the store's meta.
  virtual nlohmann::json describe() const = 0;
};

// All factors at all levels (a range at `count` evenly spaced levels), in
// mixed-radix order, the first factor slowest.
std::unique_ptr<Sampler> factorial(std::vector<Factor> f);
// u_ij = uniform(seed, i, j).
std::unique_ptr<Sampler> uniform_random(std::vector<Factor> f, std::int64_t n, std::uint64_t seed);
// One point per stratum [k/n, (k+1)/n) in every factor. maximin: the best of 16
// candidate hypercubes by their smallest pairwise distance (n <= 5000).
std::unique_ptr<Sampler> latin_hypercube(std::vector<Factor> f, std::int64_t n, std::uint64_t seed,
                                         bool maximin);
// Sobol' points (Joe-Kuo new-joe-kuo-6.21201, at most 1111 factors) in scipy's
// order: without a seed, equal to scipy.stats.qmc.Sobol(d, scramble=False);
// with one, linearly matrix-scrambled and digitally shifted.
std::unique_ptr<Sampler> sobol(std::vector<Factor> f, std::int64_t n,
                               std::optional<std::uint64_t> seed);
// The given rows, in factor order, SI (a categorical factor's option index).
// A list only names its factors: ranges are not used and need no bounds.
std::unique_ptr<Sampler> point_list(std::vector<Factor> f, std::vector<std::vector<double>> rows);
// Saltelli's scheme on 2d Sobol' dimensions (A: the first d, B: the last d, at
// most 555 factors): N = base (d + 2), see saltelli_index.
std::unique_ptr<Sampler> saltelli(std::vector<Factor> f, std::int64_t base,
                                  std::optional<std::uint64_t> seed);

// Where Saltelli sample i sits: row i / (d+2) of the base design, block
// i % (d+2): 0 = A, 1 = B, 2 + j = A with column j taken from B. Rows are
// interleaved so that any prefix of finished rows is a usable design.
struct SaltelliIndex {
  std::int64_t row;
  int block;
};
SaltelliIndex saltelli_index(std::int64_t i, int d);

// The unit-cube value u in [0, 1) -> the factor's value, shared by the
// continuous samplers: a range -> lower + u (upper - lower); levels and
// categorical -> levels[min(k - 1, floor(u k))].
double from_unit(const Factor& f, double u);

}  // namespace opt::doe
