// Readers of a store file and its segments (store.hpp): CSV (and the
// canonical dump), JSON, and rows as Row values.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>

#include "doe/store_file.hpp"
#include "mech/status.hpp"

namespace opt::doe {

using nlohmann::json;
using sql::Statement;

namespace {

void csv_text(std::ostream& out, std::string_view text) {
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) {
    out << text;
    return;
  }
  out << '"';
  for (char c : text) {
    if (c == '"') out << '"';
    out << c;
  }
  out << '"';
}

void check_written(const std::ostream& out, const std::string& file) {
  if (!out) throw std::runtime_error(file + ": export: cannot write the output");
}


}  // namespace

void export_csv(const std::string& store_file, std::ostream& out, bool wall_time) {
  UnionRows rows(store_file);
  const int n = rows.columns();
  constexpr int kWallTime = 2;  // idx, status, wall_time, ...
  auto skip = [&](int c) { return !wall_time && c == kWallTime; };
  for (int c = 0; c < n; ++c) {
    if (skip(c)) continue;
    if (c) out << ',';
    csv_text(out, sqlite3_column_name(rows.row().get(), c));
  }
  out << '\n';
  char number[32];
  while (rows.step()) {
    const Statement& s = rows.row();
    for (int c = 0; c < n; ++c) {
      if (skip(c)) continue;
      if (c) out << ',';
      switch (sqlite3_column_type(s.get(), c)) {
        case SQLITE_NULL: break;
        case SQLITE_INTEGER: out << s.int64(c); break;
        case SQLITE_FLOAT:
          std::snprintf(number, sizeof number, "%.17g", sqlite3_column_double(s.get(), c));
          out << number;
          break;
        default: csv_text(out, *s.text(c));
      }
    }
    out << '\n';
  }
  check_written(out, store_file);
}

void read_rows(const std::string& store_file, const std::function<void(const Row&)>& f) {
  UnionRows rows(store_file);
  const StoreLayout l = layout_from_json(store_file, meta_value(read_meta(rows.store()), "layout"));
  Row r;
  r.factors.resize(l.factors.size());
  r.metrics.resize(l.metrics.size());
  while (rows.step()) {
    const Statement& s = rows.row();
    r.index = s.int64(0);
    // The status as its static name (Row holds a view).
    r.status = mech::to_string(mech::status_from_string(s.text(1).value_or("")).value_or(mech::Status::evaluation_error));
    r.wall_time = s.real(2);
    r.message = s.text(3).value_or("");
    for (std::size_t j = 0; j < l.factors.size(); ++j) {
      const int c = 4 + static_cast<int>(j);
      const auto& labels = l.labels.empty() ? std::vector<std::string>() : l.labels[j];
      if (labels.empty()) {
        r.factors[j] = s.real(c);
      } else {
        const auto at = std::find(labels.begin(), labels.end(), s.text(c).value_or(""));
        r.factors[j] = at == labels.end() ? std::nan("") : static_cast<double>(at - labels.begin());
      }
    }
    for (std::size_t m = 0; m < l.metrics.size(); ++m) r.metrics[m] = s.real(4 + static_cast<int>(l.factors.size() + m));
    f(r);
  }
}

void export_json(const std::string& store_file, std::ostream& out) {
  UnionRows rows(store_file);
  json meta = json::object();
  for (const auto& [key, value] : read_meta(rows.store())) meta[key] = value;
  out << "{\"meta\": " << meta.dump() << ",\n\"samples\": [";
  const int n = rows.columns();
  std::vector<std::string> keys;  // quoted once
  for (int c = 0; c < n; ++c) keys.push_back(json(sqlite3_column_name(rows.row().get(), c)).dump() + ": ");
  // One small object a row: memory stays constant for 10^7 rows.
  for (bool first = true; rows.step(); first = false) {
    out << (first ? "\n{" : ",\n{");
    const Statement& s = rows.row();
    for (int c = 0; c < n; ++c) {
      out << (c ? ", " : "") << keys[std::size_t(c)];
      switch (sqlite3_column_type(s.get(), c)) {
        case SQLITE_NULL: out << "null"; break;
        case SQLITE_INTEGER: out << s.int64(c); break;
        case SQLITE_FLOAT: out << json(sqlite3_column_double(s.get(), c)).dump(); break;
        default: out << json(*s.text(c)).dump();
      }
    }
    out << '}';
  }
  out << "\n]}\n";
  check_written(out, store_file);
}

}  // namespace opt::doe
