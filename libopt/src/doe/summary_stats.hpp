// The statistics of a store's summary (summary_stats.cpp): main effects from
// groups of rows, Sobol' indices from the rows of a saltelli design, and the
// status map's one sample per cell. Functions of numbers only: the rows come
// from the store's reads (summary_reads.hpp).
#pragma once
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "opt/doe/batch.hpp"

namespace opt::doe {

// Rows of one group: how many, and per metric the sum and count of its
// non-NULL values (a mean skips NULLs, as SQL's avg does).
struct Group {
  std::int64_t rows = 0;
  std::vector<double> sum;
  std::vector<std::int64_t> values;
};

// The groups of one factor's main effect, filled a row at a time.
struct FactorGroups {
  std::map<double, Group> by_value;      // levels, or bin index
  std::map<std::string, Group> by_name;  // options
};

// A row's metric values `v` (NaN for NULL) into the group of its factor
// value `x`: a level, or the bin of a continuous range; none when x is NaN.
void add_value(FactorGroups& groups, const Factor& f, double x, const std::vector<double>& v);
// A row's metric values `v` into the group of its option `name`.
void add_option(FactorGroups& groups, const std::string& name, const std::vector<double>& v);

struct Effect {
  std::vector<std::string> groups;          // level, option or bin [lo, hi)
  std::vector<double> position;             // for charts: the group's place in the factor's range, 0..1
  std::vector<std::int64_t> counts;
  std::vector<std::vector<double>> means;   // [metric][group]
};

// The main effects of every factor: the mean of each of `metrics` metrics
// per level (or option, or tenth of a range) of `groups` (one per factor).
// Groups in ascending order of value, or of name for options.
std::vector<Effect> main_effects(const std::vector<FactorSpec>& factors, const std::vector<FactorGroups>& groups,
                                 std::size_t metrics);

struct Indices {
  double first = NAN, total = NAN, first_low = NAN, first_high = NAN, total_low = NAN, total_high = NAN;
};

// First-order (Saltelli 2010) and total (Jansen 1999) indices from rows of
// f_A, f_B, f_ABj, with percentile bootstrap intervals over the rows.
std::vector<Indices> sobol_indices(const std::vector<std::vector<double>>& rows, int d, std::uint64_t seed);

// The points of the status map (status_map in opt/doe/batch.hpp), one
// sample at a time: per outcome its count, every sample while there are at
// most kMaxDrawnPoints, and per cell of the kMapCells x kMapCells grid over
// the two factors' extents the sample whose index hashes lowest.
class MapCells {
 public:
  MapCells(const Factor& fx, const Factor& fy);
  // Sample `index` of `outcome` at (x, y): NaN where a value is unknown.
  void add(std::string_view outcome, std::int64_t index, double x, double y);
  // Per outcome, in the order of their names; the points are moved out.
  std::vector<MapSeries> series();

 private:
  struct Pick {
    std::uint64_t hash = ~std::uint64_t{0};
    double x = NAN, y = NAN;
  };
  struct Outcome {
    std::int64_t count = 0;
    std::vector<double> x, y;  // every sample's, while there are at most kMaxDrawnPoints
    std::vector<Pick> picks;   // by cell
  };
  std::pair<double, double> span_x_, span_y_;
  std::map<std::string, Outcome, std::less<>> outcomes_;
};

}  // namespace opt::doe
