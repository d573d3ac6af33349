// A row's checksum (docs/doe.md, "Damage"): 64 bits over the values the row
// holds in the store, column by column as SQLite gives them back, in the
// store's last column `checksum`. SQLite's own checks cover the b-tree's
// structure, not the value bytes, and a damaged row can decode into plausible
// numbers: the writer computes it from the row it appends, and every reader
// of whole rows (export, read_rows, merge, check, recover) verifies it.
#pragma once
#include <sqlite3.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <string_view>

namespace opt::doe {

// One 64-bit word a value (8 bytes of a text), each step a bijection of the
// state for a given word and of the word for a given state: a change of one
// value always changes the result, of several with probability 1 - 2^-64.
// About 2 ns a value, against the ~1 us SQLite takes a row.
class RowHash {
 public:
  void null() { word(kNull); }
  // -0.0 is stored as the integer 0 (REAL affinity) and read back as +0.0.
  void real(double v) {
    const auto bits = std::bit_cast<std::uint64_t>(v);
    word(bits == kMinusZero ? 0 : bits);
  }
  void integer(std::int64_t v) {
    word(kInteger);
    word(static_cast<std::uint64_t>(v));
  }
  void text(std::string_view t) {
    word(kText ^ t.size());
    for (std::size_t i = 0; i < t.size(); i += 8) {
      std::uint64_t w = 0;
      std::memcpy(&w, t.data() + i, std::min<std::size_t>(8, t.size() - i));
      word(w);
    }
  }
  // The value of one column of the row `s` is on.
  void column(sqlite3_stmt* s, int c) {
    switch (sqlite3_column_type(s, c)) {
      case SQLITE_NULL: null(); break;
      case SQLITE_FLOAT: real(sqlite3_column_double(s, c)); break;
      case SQLITE_INTEGER: integer(sqlite3_column_int64(s, c)); break;
      default:  // TEXT, or a BLOB where damage put one
        text({reinterpret_cast<const char*>(sqlite3_column_blob(s, c)), std::size_t(sqlite3_column_bytes(s, c))});
    }
  }
  // MurmurHash3's finaliser: every bit of the state reaches every bit.
  std::int64_t value() const {
    std::uint64_t h = h_;
    h = (h ^ (h >> 33)) * 0xff51afd7ed558ccdULL;
    h = (h ^ (h >> 33)) * 0xc4ceb9fe1a85ec53ULL;
    return static_cast<std::int64_t>(h ^ (h >> 33));
  }

 private:
  static constexpr std::uint64_t kNull = 0x7ff8dead0000beefULL;  // a NaN: no stored REAL has these bits
  static constexpr std::uint64_t kInteger = 0x1d8e4e27c47d124fULL, kText = 0x9e3779b97f4a7c15ULL;
  static constexpr std::uint64_t kMinusZero = 0x8000000000000000ULL;
  void word(std::uint64_t w) { h_ = std::rotl(h_ ^ (w * 0x87c37b91114253d5ULL), 31) * 0x4cf5ad432745937fULL; }
  std::uint64_t h_ = 0x52dce729da3ed4e9ULL;
};

// Whether the row `s` is on (SELECT * FROM samples: its last column the
// checksum) holds what was written.
inline bool checksum_holds(sqlite3_stmt* s) {
  const int n = sqlite3_column_count(s);
  RowHash h;
  for (int c = 0; c + 1 < n; ++c) h.column(s, c);
  return sqlite3_column_type(s, n - 1) == SQLITE_INTEGER && sqlite3_column_int64(s, n - 1) == h.value();
}

}  // namespace opt::doe
