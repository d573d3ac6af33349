// What the store (store.cpp) and its check and recovery (recover.cpp) share
// about a store file: opening it, its meta, and the writer's lock.
#pragma once
#include <map>
#include <string>

#include "doe/sqlite.hpp"

namespace opt::doe {

// A store to read: a missing file is an error, never a new empty store.
sql::Db open_to_read(const std::string& file);
// A store to write: 64 KiB pages (for a new file), WAL journal, synchronous=NORMAL.
sql::Db open_to_write(const std::string& file);

std::map<std::string, std::string> read_meta(const sql::Db& db);
// Adds the keys the store lacks; stored values are kept.
void add_meta(const sql::Db& db, const std::map<std::string, std::string>& meta);

// DIR/store.lock, held (flock, exclusive) from construction to destruction:
// StoreBusy naming the holder when another process holds it (store.hpp, Store).
class WriterLock {
 public:
  explicit WriterLock(const std::string& dir);
  ~WriterLock();
  WriterLock(WriterLock&& o) noexcept;
  WriterLock& operator=(WriterLock&&) = delete;

 private:
  std::string file_;
  int fd_ = -1;
};

}  // namespace opt::doe
