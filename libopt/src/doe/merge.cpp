// `mechopt merge` (store.hpp): shard stores, each with its segments, into
// one, after every row is verified and every index found once.
#include <filesystem>

#include "doe/checksum.hpp"
#include "doe/store_file.hpp"

namespace opt::doe {

namespace fs = std::filesystem;
using nlohmann::json;
using sql::Db;
using sql::Statement;
using sql::Transaction;

namespace {

// "3 indices missing: 7, 8, 9" (at most 10 named).
std::string name_indices(const std::vector<std::int64_t>& indices, std::int64_t count, const std::string& what) {
  std::string s = std::to_string(count) + (count == 1 ? " index " : " indices ") + what + ": ";
  for (std::size_t i = 0; i < indices.size(); ++i) s += (i ? ", " : "") + std::to_string(indices[i]);
  if (count > std::int64_t(indices.size())) s += ", ...";
  return s;
}

// Missing and doubled indices over all inputs, or "" when each of [0, total)
// appears exactly once.
std::string coverage_errors(const std::vector<std::string>& files, std::int64_t total) {
  constexpr std::size_t kNamed = 10;
  std::vector<std::uint8_t> seen(std::size_t(total), 0);  // 0, 1, 2 = twice or more
  std::vector<std::int64_t> outside;
  std::int64_t outside_count = 0;
  for (const auto& file : files) {
    UnionRows rows(file);  // with its segments, each index once; every checksum verified
    while (rows.step()) {
      const std::int64_t i = rows.row().int64(0);
      if (i < 0 || i >= total) {
        if (outside.size() < kNamed) outside.push_back(i);
        ++outside_count;
      } else if (seen[std::size_t(i)] < 2) {
        ++seen[std::size_t(i)];
      }
    }
  }
  std::vector<std::int64_t> missing, doubled;
  std::int64_t missing_count = 0, doubled_count = 0;
  for (std::int64_t i = 0; i < total; ++i) {
    const auto n = seen[std::size_t(i)];
    if (n == 0 && missing_count++ < std::int64_t(kNamed)) missing.push_back(i);
    if (n == 2 && doubled_count++ < std::int64_t(kNamed)) doubled.push_back(i);
  }
  std::string s;
  if (missing_count) s += name_indices(missing, missing_count, "missing") + "; ";
  if (doubled_count) s += name_indices(doubled, doubled_count, "in more than one row") + "; ";
  if (outside_count) s += name_indices(outside, outside_count, "outside [0, " + std::to_string(total) + ")") + "; ";
  return s.empty() ? s : s.substr(0, s.size() - 2);
}

}  // namespace

MergeReport merge_stores(const std::string& out_dir, const std::vector<std::string>& stores) {
  if (stores.empty()) throw std::invalid_argument("merge: no stores given");
  MergeReport report;
  std::vector<std::map<std::string, std::string>> metas;
  for (const auto& s : stores) {
    report.inputs.push_back(fs::is_directory(s) ? (fs::path(s) / "store.sqlite").string() : s);
    metas.push_back(read_meta(open_to_read(report.inputs.back())));
  }
  // All shards of one run: the same config, hence the same columns and total.
  const std::string& first = report.inputs[0];
  const auto hash = meta_value(metas[0], "config_hash");
  const StoreLayout layout = layout_from_json(first, meta_value(metas[0], "layout"));
  for (std::size_t k = 1; k < stores.size(); ++k) {
    const std::string& file = report.inputs[k];
    const auto h = meta_value(metas[k], "config_hash");
    if (h != hash)
      throw StoreMismatch(
          "merge: " + file + " has config_hash " + h.value_or("none") + ", " + first + " has " + hash.value_or("none") +
          "; " +
          config_difference(meta_value(metas[0], "config_canonical"), meta_value(metas[k], "config_canonical"), first, file));
    if (layout_json(layout_from_json(file, meta_value(metas[k], "layout"))) != layout_json(layout))
      throw StoreMismatch("merge: " + file + " has other columns than " + first);
  }
  const auto samples = meta_value(metas[0], "samples");
  std::int64_t total = -1;
  try {
    total = std::stoll(samples.value_or(""));
  } catch (const std::logic_error&) {  // invalid_argument, out_of_range
  }
  if (total < 0) throw std::runtime_error("merge: " + first + ": no meta 'samples' (the number of samples)");
  if (const std::string errors = coverage_errors(report.inputs, total); !errors.empty())
    throw std::runtime_error("merge: " + errors + "; nothing was written");

  const std::string out_file = (fs::path(out_dir) / "store.sqlite").string();
  if (fs::exists(out_file)) throw std::runtime_error("merge: " + out_file + " exists already");
  auto meta = metas[0];
  meta.erase("shard");
  meta["merged_from"] = json(report.inputs).dump();
  const Store created(out_dir, layout, meta, false);  // the schema and meta, and the writer's lock
  const Db out(out_file, SQLITE_OPEN_READWRITE);
  try {
    for (const auto& file : report.inputs) {
      std::vector<std::string> parts = segment_files(file);
      parts.insert(parts.begin(), file);
      if (stored_columns(open_to_read(file)).back() == "checksum") {
        for (const auto& part : parts)  // verified above
          if (part == file || has_table(open_to_read(part), "samples")) report.rows += copy_rows(out, part);
        continue;
      }
      // A shard from before checksums gets them here, row by row.
      const int n = int(kColumnsBefore + layout.factors.size() + layout.metrics.size());
      Statement insert(out, insert_sql(std::size_t(n) + 1));
      Transaction t(out);
      UnionRows rows(file);
      while (rows.step()) {
        sqlite3_stmt* row = rows.row().get();
        insert.reset();
        RowHash h;
        for (int c = 0; c < n; ++c) {
          insert.bind(c + 1, sqlite3_column_value(row, c));
          h.column(row, c);
        }
        insert.bind(n + 1, h.value());
        insert.step();
        ++report.rows;
      }
      t.commit();
    }
  } catch (...) {  // a merge is whole or absent
    for (const char* suffix : {"", "-wal", "-shm"}) fs::remove(out_file + suffix);
    throw;
  }
  return report;
}

}  // namespace opt::doe
