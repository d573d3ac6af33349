// A damaged store (docs/doe.md, "Damage"): `mechopt check` says what is
// wrong with a store file, `mechopt recover` copies every row that is
// readable and intact into a new store, whose run then re-evaluates only the
// samples that were lost. Both read the file tolerantly: a part SQLite
// cannot read is stepped over, every row's checksum is verified.
#pragma once
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace opt::doe {

struct StoreCheck {
  std::string file;                          // the store file read
  std::optional<std::string> config_hash;    // none when the meta is unreadable or has none
  std::int64_t lo = 0, hi = -1;              // the run's samples [lo, hi) (its shard); hi < 0: unknown
  bool finished = false;                     // meta 'finished': [lo, hi) should be whole
  bool checksums = true;                     // rows carry checksums (not a store from before them)
  std::int64_t intact = 0;                   // rows read whose checksum holds (inside [lo, hi) when known)
  std::int64_t missing = 0;                  // indices of [lo, hi) without an intact row (hi known)
  std::map<std::string, std::int64_t> statuses;  // intact rows by status
  std::vector<std::string> problems;         // what is wrong, a line each; none: sound
  std::int64_t saved = -1;                   // recover: rows written to the new store (-1: none written)
  bool sound() const { return problems.empty(); }
};

// `mechopt check STORE` (a file, or a directory holding store.sqlite):
// SQLite's integrity check, the meta (config hash, samples, shard), and
// every row read: its checksum, its index inside the run's range, present
// once, and in a finished store every index present.
StoreCheck check_store(const std::string& store);

// `mechopt recover STORE OUT`: the check above, every intact row of the
// run's range copied into OUT/store.sqlite (which must not exist) with what
// can be read of the meta (without 'finished'); a store from before row
// checksums gets them. When the schema is unreadable, nothing is written
// (saved stays -1); when the meta is, the new store has none, and the next
// run of the config on OUT supplies it.
StoreCheck recover_store(const std::string& store, const std::string& out_dir);

}  // namespace opt::doe
