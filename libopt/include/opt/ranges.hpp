// Indices shared among threads (or MPI ranks) with work stealing: the DOE's
// runner (docs/doe.md, "Threads") and opt::evaluate_rows.
#pragma once
#include <algorithm>
#include <cstdint>
#include <mutex>
#include <utility>
#include <vector>

namespace opt {

// The indices [lo, hi) as one contiguous range per taker (a thread of this
// process, or under MPI another rank): each takes chunks from the front of
// its own, and one whose range is spent steals the back half of the largest
// range left. Each writer's rows are then few long runs of indices, so that
// the fold appends them to the store's B-tree instead of inserting them
// between another writer's: 1.15-1.6x faster (bench_doe_store, BM_Fold/0
// against BM_Fold/1, which interleaves two writers in chunks of 4096 as one
// shared counter did).
class Ranges {
 public:
  Ranges(std::int64_t lo, std::int64_t hi, int takers) : ranges_(static_cast<std::size_t>(takers)) {
    for (int k = 0; k < takers; ++k) {
      ranges_[std::size_t(k)].begin = lo + (hi - lo) * k / takers;
      ranges_[std::size_t(k)].end = lo + (hi - lo) * (k + 1) / takers;
    }
  }
  // The next chunk, of up to `want` indices, for taker k: [begin, end), empty when every range is spent.
  std::pair<std::int64_t, std::int64_t> take(int k, std::int64_t want) {
    Range& own = ranges_[std::size_t(k)];
    for (;;) {
      {
        std::lock_guard lock(own.m);
        if (own.begin < own.end) {
          const std::int64_t begin = own.begin;
          own.begin = std::min(own.end, begin + std::max<std::int64_t>(want, 1));
          return {begin, own.begin};
        }
      }
      Range* victim = nullptr;
      std::int64_t most = 0;
      for (Range& r : ranges_) {
        std::lock_guard lock(r.m);
        if (r.end - r.begin > most) most = r.end - r.begin, victim = &r;
      }
      if (!victim) return {0, 0};
      std::int64_t begin, end;
      {
        std::lock_guard lock(victim->m);
        const std::int64_t left = victim->end - victim->begin;
        if (left <= 0) continue;  // spent meanwhile: look again
        end = victim->end;
        begin = victim->end -= (left + 1) / 2;
      }
      std::lock_guard lock(own.m);
      own.begin = begin, own.end = end;
    }
  }

 private:
  struct Range {
    std::mutex m;
    std::int64_t begin = 0, end = 0;
  };
  std::vector<Range> ranges_;
};

// The next chunk's size after `count` samples took `seconds` on `threads`
// threads: ~50 ms of work, few enough requests to keep the counter (or rank
// 0) cold, small enough that slow samples do not idle the others.
inline std::int64_t next_chunk(double seconds, std::int64_t count, int threads) {
  const double per = seconds / static_cast<double>(std::max<std::int64_t>(1, count));
  return std::clamp<std::int64_t>(static_cast<std::int64_t>(0.05 * threads / std::max(per, 1e-9)), 1, 4096);
}

}  // namespace opt
