// The store file's layout, meta and schema, and the checks that an existing
// store holds this run's samples (store_file.hpp).
#include <ctime>
#include <filesystem>
#include <map>
#include <stdexcept>

#include "doe/store_file.hpp"

namespace opt::doe {

namespace fs = std::filesystem;
using nlohmann::json;
using sql::Db;
using sql::identifier;
using sql::Statement;

namespace {

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

// What differs between two layouts, in column names.
std::string columns_difference(const StoreLayout& a, const StoreLayout& b, const std::string& a_name,
                               const std::string& b_name) {
  auto columns = [](const StoreLayout& l) {
    std::map<std::string, std::vector<std::string>> c;  // name -> labels (metrics: none)
    for (std::size_t i = 0; i < l.factors.size(); ++i) c[l.factors[i]] = l.labels[i];
    for (const auto& m : l.metrics) c[m];
    return c;
  };
  const auto ca = columns(a), cb = columns(b);
  std::vector<std::string> only_a, only_b, labels;
  for (const auto& [name, l] : ca) {
    const auto it = cb.find(name);
    if (it == cb.end())
      only_a.push_back(name);
    else if (it->second != l)
      labels.push_back(name);
  }
  for (const auto& [name, l] : cb)
    if (!ca.contains(name)) only_b.push_back(name);
  std::string s;
  if (!only_a.empty()) s += "columns only in " + a_name + ": " + joined(only_a) + "; ";
  if (!only_b.empty()) s += "columns only in " + b_name + ": " + joined(only_b) + "; ";
  if (!labels.empty()) s += "categorical options differ: " + joined(labels) + "; ";
  return s.empty() ? "the columns' order or kinds differ" : s.substr(0, s.size() - 2);
}

std::string timestamp() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  localtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y%m%d-%H%M%S", &tm);
  return buf;
}

std::vector<std::string> column_names(const StoreLayout& l) {
  std::vector<std::string> names = {"idx", "status", "wall_time", "message"};
  names.insert(names.end(), l.factors.begin(), l.factors.end());
  names.insert(names.end(), l.metrics.begin(), l.metrics.end());
  names.push_back("checksum");
  return names;
}

}  // namespace

// labels may be left empty when no factor is categorical.
StoreLayout normalized(StoreLayout l) {
  if (l.labels.empty()) l.labels.resize(l.factors.size());
  if (l.labels.size() != l.factors.size())
    throw std::invalid_argument("store layout: " + std::to_string(l.labels.size()) + " label lists for " +
                                std::to_string(l.factors.size()) + " factors");
  return l;
}

json layout_json(const StoreLayout& l) {
  json factors = json::array();
  for (std::size_t i = 0; i < l.factors.size(); ++i)
    factors.push_back({{"name", l.factors[i]}, {"labels", l.labels[i]}});
  return {{"factors", factors}, {"metrics", l.metrics}};
}

StoreLayout layout_from_json(const std::string& file, const std::optional<std::string>& text) {
  const json j = json::parse(text.value_or(""), nullptr, false);
  try {
    StoreLayout l;
    for (const auto& f : j.at("factors")) {
      l.factors.push_back(f.at("name").get<std::string>());
      l.labels.push_back(f.at("labels").get<std::vector<std::string>>());
    }
    l.metrics = j.at("metrics").get<std::vector<std::string>>();
    return l;
  } catch (const json::exception&) {
    throw std::runtime_error(file + ": meta 'layout' is missing or not a store layout");
  }
}

// The top-level keys whose canonical config values differ: a refusal says
// what changed, not just that two hashes differ.
std::string config_difference(const std::optional<std::string>& a_text, const std::optional<std::string>& b_text,
                              const std::string& a_name, const std::string& b_name) {
  const json a = json::parse(a_text.value_or(""), nullptr, false);
  const json b = json::parse(b_text.value_or(""), nullptr, false);
  if (!a.is_object() || !b.is_object()) return "no canonical config (meta 'config_canonical') to compare";
  std::vector<std::string> changed, only_a, only_b;
  for (const auto& [key, value] : a.items()) {
    if (!b.contains(key))
      only_a.push_back(key);
    else if (b.at(key) != value)
      changed.push_back(key);
  }
  for (const auto& [key, value] : b.items())
    if (!a.contains(key)) only_b.push_back(key);
  std::string s;
  if (!changed.empty()) s += "keys that differ: " + joined(changed) + "; ";
  if (!only_a.empty()) s += "keys only in " + a_name + ": " + joined(only_a) + "; ";
  if (!only_b.empty()) s += "keys only in " + b_name + ": " + joined(only_b) + "; ";
  return s.empty() ? "no top-level key differs" : s.substr(0, s.size() - 2);
}

bool has_table(const Db& db, const char* name) {
  Statement s(db, "SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = ?");
  s.bind(1, std::string_view(name));
  return s.step();
}

void create_schema(const Db& db, const StoreLayout& l, const std::map<std::string, std::string>& meta) {
  db.exec("CREATE TABLE meta(key TEXT PRIMARY KEY, value TEXT)");
  std::string sql = "CREATE TABLE samples(idx INTEGER PRIMARY KEY, status TEXT NOT NULL, wall_time REAL, message TEXT";
  for (std::size_t i = 0; i < l.factors.size(); ++i)
    sql += ", " + identifier(l.factors[i]) + (l.labels[i].empty() ? " REAL" : " TEXT");
  for (const auto& m : l.metrics) sql += ", " + identifier(m) + " REAL";
  db.exec(sql + ", checksum INTEGER)");
  add_meta(db, meta);
}

// "INSERT INTO samples VALUES(?, ?, ...)" for n columns.
std::string insert_sql(std::size_t columns) {
  std::string sql = "INSERT INTO samples VALUES(?";
  for (std::size_t i = 1; i < columns; ++i) sql += ", ?";
  return sql + ")";
}

// FILE (and its -wal, -shm) -> FILE.old-<time> (-wal, -shm): SQLite finds the
// old store's WAL by that name, so nothing committed to it is lost.
void move_aside(const std::string& file) {
  const std::string base = file + ".old-" + timestamp();
  std::string old = base;
  for (int n = 2; fs::exists(old); ++n) old = base + "-" + std::to_string(n);  // two --new in one second
  for (const char* suffix : {"", "-wal", "-shm"})
    if (fs::exists(file + suffix)) fs::rename(file + suffix, old + suffix);
}

// The names of the columns of `samples` (SELECT * FROM samples), in order.
std::vector<std::string> stored_columns(const Db& db) {
  Statement s(db, "SELECT * FROM samples LIMIT 0");
  std::vector<std::string> names;
  for (int c = 0; c < sqlite3_column_count(s.get()); ++c) names.push_back(sqlite3_column_name(s.get(), c));
  return names;
}

// An existing store must hold this run's samples: the same config_hash and
// columns; else StoreMismatch names what differs. A store that `mechopt
// recover` saved without its meta has neither hash nor layout: its columns
// must be this run's, whose meta it then takes.
void check_same_run(const Db& db, const std::map<std::string, std::string>& meta, const StoreLayout& l) {
  const std::string& file = db.file();
  const auto stored = read_meta(db);
  const auto stored_hash = meta_value(stored, "config_hash"), hash = meta_value(meta, "config_hash");
  if (stored_hash && stored_hash != hash)
    throw StoreMismatch(
        file + ": written by another configuration (config_hash " + *stored_hash + ", this run " +
        hash.value_or("none") + "); " +
        config_difference(meta_value(stored, "config_canonical"), meta_value(meta, "config_canonical"), "the store", "this run") +
        ". Start afresh (--new) to move it aside.");
  const std::vector<std::string> columns = stored_columns(db);
  if (columns.empty() || columns.back() != "checksum")
    throw StoreMismatch(file + ": written by a mechopt before row checksums; `mechopt recover " + file +
                        " OUT` copies it into a store of this version, or start afresh (--new) to move it aside.");
  if (!stored.contains("layout")) {
    if (columns != column_names(l))
      throw StoreMismatch(file + ": has no meta and other columns than this run (" + joined(columns) + "; this run " +
                          joined(column_names(l)) + "). Start afresh (--new) to move it aside.");
    return;
  }
  const StoreLayout old = layout_from_json(file, meta_value(stored, "layout"));
  if (layout_json(old) != layout_json(l))
    throw StoreMismatch(file + ": written with other columns; " + columns_difference(old, l, "the store", "this run") +
                        ". Start afresh (--new) to move it aside.");
}

}  // namespace opt::doe
