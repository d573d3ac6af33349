// --dry-run (docs/doe.md, "Dry run and limits"): what a run would take,
// from a pilot of a few samples, writing nothing to the output directory.
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <ostream>

#include "doe/dry_run.hpp"
#include "opt/doe/store.hpp"

namespace opt::doe {
namespace {

// "42 s", "13.5 min", "2.25 h".
std::string duration_text(double seconds) {
  char text[32];
  if (seconds < 120) std::snprintf(text, sizeof text, "%.3g s", seconds);
  else if (seconds < 7200) std::snprintf(text, sizeof text, "%.3g min", seconds / 60);
  else std::snprintf(text, sizeof text, "%.3g h", seconds / 3600);
  return text;
}

// The store's seconds a row: the pilot's rows appended to a scratch store
// in the temporary directory (removed). Each thread pays it for its own rows,
// and the fold once more for the rows of all threads but the first (a fold
// appends a row in less than an append's time: BM_Fold/0 against BM_Append),
// so a run of r samples on T threads takes at most about
// r (e + w) / T + r w (T - 1) / T.
double store_seconds_per_row(const StoreLayout& layout, const std::map<std::string, std::string>& meta,
                             std::span<const Row> rows) {
  namespace fs = std::filesystem;
  if (rows.empty()) return 0;
  const fs::path dir = fs::temp_directory_path() / ("mechopt-dry-run-" + std::to_string(getpid()));
  fs::remove_all(dir);
  double seconds = 0;
  try {
    Store scratch(dir.string(), layout, meta, false);
    const auto t0 = Clock::now();
    scratch.append(rows);
    seconds = since(t0);
  } catch (...) {
    fs::remove_all(dir);
    throw;
  }
  fs::remove_all(dir);
  return seconds / static_cast<double>(rows.size());
}

// --dry-run: the samples the store already holds (read only; a store of
// another config is refused as a real run would refuse it), the time a pilot
// of a few samples predicts for the rest (their evaluation and their rows in
// a scratch store), and the store's size from the pilot rows' record sizes.
// Nothing is written to the output directory.
}  // namespace

nlohmann::json dry_run(const Evaluator& evaluator, const SampleMaker& maker, const StoreLayout& layout,
                       const std::map<std::string, std::string>& meta, std::int64_t lo, std::int64_t hi, int threads,
                       const BatchOptions& o, std::ostream& out) {
  const std::int64_t total = std::stoll(meta.at("samples"));
  std::int64_t stored = 0;
  if (!o.fresh)
    if (const auto done = Store::peek(o.output_directory, layout, meta, total))
      for (std::int64_t i = lo; i < hi; ++i) stored += (*done)[static_cast<std::size_t>(i)];
  // The pilot: the first samples of the range for up to 0.2 s (at most
  // 4096), after one untimed sample that pays for first-use costs.
  const std::int64_t rest = hi - lo - stored;
  double bytes_per_row = 0;
  std::vector<Row> rows;
  if (hi > lo) rows.push_back(evaluator.evaluate(maker, lo));
  const auto t0 = Clock::now();
  while (lo + static_cast<std::int64_t>(rows.size()) < hi && rows.size() <= 4096 && since(t0) < 0.2)
    rows.push_back(evaluator.evaluate(maker, lo + static_cast<std::int64_t>(rows.size())));
  const auto pilot = static_cast<std::int64_t>(rows.size()) - (hi > lo);  // timed: all but the first
  const double per = pilot ? since(t0) / static_cast<double>(pilot) : 0;
  for (const Row& r : rows) bytes_per_row += row_bytes(r, layout);
  bytes_per_row /= static_cast<double>(std::max<std::size_t>(1, rows.size()));
  const double store = store_seconds_per_row(layout, meta, rows);
  const double seconds = static_cast<double>(rest) * ((per + store) / threads + store * (threads - 1) / threads),
               bytes = bytes_per_row * static_cast<double>(hi - lo);
  const bool needs_force = total > kMaxSamples && !o.force;
  const std::string shard = meta.at("shard");
  out << "dry run: " << hi - lo << " samples" << (o.shard.count > 1 ? " (shard " + shard + ")" : "") << ", "
      << stored << " already in " << o.output_directory << "/store.sqlite, " << rest << " to evaluate on " << threads
      << " threads\n  pilot: " << pilot << " samples, " << per * 1e6 << " us each, and " << store * 1e6
      << " us a row in the store\n  estimated time: "
      << duration_text(seconds) << "\n  estimated store size: " << bytes / 1e6 << " MB (" << bytes_per_row
      << " bytes a row)\n";
  if (needs_force) out << "  more than " << kMaxSamples << " samples: run with --force to go ahead\n";
  return {{"samples", hi - lo}, {"stored", stored}, {"to_evaluate", rest}, {"pilot_samples", pilot},
          {"seconds_per_sample", per}, {"store_seconds_per_row", store}, {"estimated_seconds", seconds}, {"estimated_store_bytes", bytes},
          {"bytes_per_row", bytes_per_row}, {"needs_force", needs_force}};
}

}  // namespace opt::doe
