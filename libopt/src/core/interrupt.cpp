#include "opt/interrupt.hpp"

#include <atomic>
#include <csignal>

namespace opt {
namespace {
std::atomic<int> g_stop{0};  // 0: none; else the signal (or -1 without one)
static_assert(std::atomic<int>::is_always_lock_free, "used from a signal handler");
void on_signal(int s) { request_stop(s); }
}  // namespace

bool stop_requested() { return g_stop.load(std::memory_order_relaxed) != 0; }
void request_stop(int signal) { g_stop.store(signal ? signal : -1, std::memory_order_relaxed); }
int stop_signal() { const int s = g_stop.load(std::memory_order_relaxed); return s > 0 ? s : 0; }
void clear_stop() { g_stop.store(0, std::memory_order_relaxed); }

void install_stop_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

}  // namespace opt
