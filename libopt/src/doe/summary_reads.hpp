// What a store's summary reads from the store (summary_reads.cpp): every SQL
// query summarize and status_map make of its samples table, and the one
// write, the summary's JSON into its summary table. The statistics over
// what they read are in summary_stats.hpp.
#pragma once
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "doe/sqlite.hpp"
#include "doe/summary_stats.hpp"
#include "opt/doe/batch.hpp"

namespace opt::doe {

// The samples of one failure status: how many, and one of their messages ("" for none).
struct Failures {
  std::string status;
  std::int64_t count = 0;
  std::string example;
};
// Failures by status, the most frequent first.
std::vector<Failures> failures_by_status(const sql::Db& db);

// How many samples `where` selects.
std::int64_t count_samples(const sql::Db& db, const std::string& where);

// The sample `where` selects with the lowest (highest when `maximize`)
// non-NULL value of `metric`: its index, its factors' values in the order
// of spec.factors (a number, or an option's name) and the metric's value.
struct BestSample {
  std::int64_t index = 0;
  std::vector<std::variant<double, std::string>> factors;
  double value = 0;
};
std::optional<BestSample> best_sample(const sql::Db& db, const DoeSpec& spec, const std::string& metric,
                                      bool maximize, const std::string& where);

// Every factor's main-effect groups of the metric columns `metrics` over
// the rows `where` selects, in one scan of the store (a GROUP BY per factor
// was a scan and a sort each: ~35 s on 10^7 rows).
std::vector<FactorGroups> effect_groups(const sql::Db& db, const std::vector<FactorSpec>& factors,
                                        const std::vector<std::string>& metrics, const std::string& where);

// Rows of (f_A, f_B, f_AB1..f_ABd) of `metric` for the saltelli rows whose
// d + 2 samples are all feasible.
std::vector<std::vector<double>> saltelli_rows(const sql::Db& db, const std::string& metric, int d,
                                               const std::string& where);

// `j` as the store's summary: one JSON document, for scripts.
void save_summary(const sql::Db& db, const nlohmann::json& j);

}  // namespace opt::doe
