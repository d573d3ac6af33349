// MPI ranks of one batch (docs/doe.md, "MPI"). Rank 0 owns the store: its
// main thread serves chunks of sample indices to the other ranks, which ask
// for a chunk size, commit each chunk's rows to a segment of their own and
// report the rows committed, by status, with the next request. Only the main
// thread of a process calls MPI (MPI_THREAD_FUNNELED).
//
// Messages, all MPI_BYTE on one tag:
//   rank k -> 0: int64 wanted chunk size (0: stopping), int64 segment files
//                closed in all, then per status int32 status and int64 rows
//                committed since the last request
//   0 -> rank k: int64 begin, int64 end (begin == end: stop)
#include <chrono>
#include <cstdlib>
#include <thread>
#include <tuple>
#include <cstring>

#include "opt/doe/batch.hpp"
#include "opt/doe/store.hpp"
#include "opt/interrupt.hpp"

#ifdef MECHOPT_MPI
#include <mpi.h>
#endif

namespace opt::doe {

#ifdef MECHOPT_MPI
namespace {

constexpr int kTag = 7;

template <class T>
void put(std::vector<char>& b, const T& v) {
  const char* p = reinterpret_cast<const char*>(&v);
  b.insert(b.end(), p, p + sizeof v);
}

template <class T>
T take(const char*& p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  p += sizeof v;
  return v;
}

std::vector<char> pack(std::int64_t want, const Report& report) {
  std::vector<char> b;
  put(b, want);
  put(b, report.closed);
  for (const auto& [status, n] : report.committed) {
    put(b, static_cast<std::int32_t>(mech::status_from_string(status).value_or(Status::evaluation_error)));
    put(b, n);
  }
  return b;
}

Report unpack(const std::vector<char>& b, std::int64_t& want) {
  const char* p = b.data();
  const char* end = b.data() + b.size();
  want = take<std::int64_t>(p);
  Report report;
  report.closed = take<std::int64_t>(p);
  while (p < end) {
    const auto status = mech::to_string(static_cast<Status>(take<std::int32_t>(p)));
    report.committed[std::string(status)] += take<std::int64_t>(p);
  }
  return report;
}

class MpiPeers final : public Peers {
 public:
  MpiPeers() {
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    std::atexit([] {
      int done = 0;
      MPI_Finalized(&done);
      if (!done) MPI_Finalize();
    });
  }
  int rank() const override { return rank_; }
  int size() const override { return size_; }

  void share(std::vector<bool>& finished) override {
    std::vector<unsigned char> bytes((finished.size() + 7) / 8);
    if (rank_ == 0)
      for (size_t i = 0; i < finished.size(); ++i)
        if (finished[i]) bytes[i / 8] |= static_cast<unsigned char>(1u << (i % 8));
    // In pieces: MPI counts are ints.
    for (size_t at = 0; at < bytes.size(); at += 1 << 30)
      MPI_Bcast(bytes.data() + at, static_cast<int>(std::min<size_t>(bytes.size() - at, 1 << 30)), MPI_BYTE, 0,
                MPI_COMM_WORLD);
    for (size_t i = 0; i < finished.size(); ++i) finished[i] = bytes[i / 8] >> (i % 8) & 1u;
  }

  void serve(const std::function<std::pair<std::int64_t, std::int64_t>(int, std::int64_t)>& chunk_of,
             const std::function<void(int, const Report&)>& reported,
             const std::function<bool()>& stopping) override {
    for (int active = size_ - 1; active > 0;) {
      // Polled with a pause, not MPI_Probe: Open MPI's blocking calls spin,
      // and this thread would take a core from the evaluating ones.
      MPI_Status st;
      int arrived = 0;
      for (;;) {
        MPI_Iprobe(MPI_ANY_SOURCE, kTag, MPI_COMM_WORLD, &arrived, &st);
        if (arrived) break;
        std::this_thread::sleep_for(std::chrono::microseconds(200));
      }
      int count = 0;
      MPI_Get_count(&st, MPI_BYTE, &count);
      std::vector<char> b(static_cast<size_t>(count));
      MPI_Recv(b.data(), count, MPI_BYTE, st.MPI_SOURCE, kTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      std::int64_t want = 0;
      reported(st.MPI_SOURCE, unpack(b, want));
      std::int64_t chunk[2] = {0, 0};
      if (want > 0 && !stopping()) std::tie(chunk[0], chunk[1]) = chunk_of(st.MPI_SOURCE, want);
      if (chunk[0] == chunk[1]) --active;
      MPI_Send(chunk, sizeof chunk, MPI_BYTE, st.MPI_SOURCE, kTag, MPI_COMM_WORLD);
    }
  }

  void work(const std::function<Report(std::int64_t, std::int64_t, std::int64_t&)>& evaluate) override {
    Report report;
    std::int64_t want = 1;
    for (;;) {
      const auto b = pack(stop_requested() ? 0 : want, report);
      MPI_Send(b.data(), static_cast<int>(b.size()), MPI_BYTE, 0, kTag, MPI_COMM_WORLD);
      std::int64_t chunk[2];
      MPI_Recv(chunk, sizeof chunk, MPI_BYTE, 0, kTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      if (chunk[0] == chunk[1]) return;
      report = evaluate(chunk[0], chunk[1], want);
    }
  }

  // Polled, as serve() is: Open MPI's blocking barrier spins.
  void barrier() override {
    MPI_Request request;
    MPI_Ibarrier(MPI_COMM_WORLD, &request);
    for (int done = 0; MPI_Test(&request, &done, MPI_STATUS_IGNORE), !done;)
      std::this_thread::sleep_for(std::chrono::microseconds(200));
  }

 private:
  int rank_ = 0, size_ = 1;
};

// Started by mpirun (Open MPI, or a PMI launcher) with more than one rank.
bool launched_with_ranks() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"})
    if (const char* s = std::getenv(v)) return std::atoi(s) > 1;
  return false;
}

}  // namespace

Peers* mpi_peers() {
  static MpiPeers* peers = launched_with_ranks() ? new MpiPeers() : nullptr;  // lives to the end
  return peers;
}

void abort_peers(int code) {
  int initialized = 0, finalized = 0;
  MPI_Initialized(&initialized);
  MPI_Finalized(&finalized);
  if (initialized && !finalized && mpi_peers() && mpi_peers()->size() > 1) MPI_Abort(MPI_COMM_WORLD, code);
}

#else

Peers* mpi_peers() { return nullptr; }
void abort_peers(int) {}

#endif

}  // namespace opt::doe
