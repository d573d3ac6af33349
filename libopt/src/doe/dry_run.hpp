// --dry-run of a batch (dry_run.cpp): the samples the store already holds,
// the time a pilot predicts for the rest and the store's size.
#pragma once
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>

#include "doe/evaluator.hpp"
#include "opt/doe/batch.hpp"
#include "opt/doe/store.hpp"

namespace opt::doe {

// Samples [lo, hi) of the run whose store meta is `meta` on `threads`
// threads: printed to `out`, and as result.json's "dry_run".
nlohmann::json dry_run(const Evaluator& evaluator, const SampleMaker& maker, const StoreLayout& layout,
                       const std::map<std::string, std::string>& meta, std::int64_t lo, std::int64_t hi, int threads,
                       const BatchOptions& o, std::ostream& out);

}  // namespace opt::doe
