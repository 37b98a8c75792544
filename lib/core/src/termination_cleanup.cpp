#include "lensmith/core/termination_cleanup.h"

#include <unistd.h>

#include <array>
#include <atomic>
#include <csignal>
#include <cstring>
#include <mutex>

namespace lensmith {

namespace {

constexpr int kSlots = 64;
constexpr std::size_t kPathBytes = 4096;

// A slot is free (0), being filled or emptied (1), or holds a path the handler may remove (2).
// The handler reads only slots in state 2; a path is written before the slot becomes 2 and the slot
// leaves 2 before the path is changed, so the handler never reads a path being written.
struct Slot {
  std::atomic<int> state{0};
  char path[kPathBytes]{};
};
std::array<Slot, kSlots> g_slots;

extern "C" void remove_temporaries_and_die(int signal_number) {
  for (Slot& slot : g_slots) {
    if (slot.state.load(std::memory_order_acquire) == 2) ::unlink(slot.path);  // async-signal-safe
  }
  // End the process as the signal would have, so the parent (a shell, Slurm) sees which signal.
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
}

}  // namespace

void remove_temporaries_on_termination() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (const int s : {SIGTERM, SIGINT, SIGHUP}) {
      struct sigaction action {};
      action.sa_handler = remove_temporaries_and_die;
      sigemptyset(&action.sa_mask);
      // Keep an ignored signal ignored (nohup, a shell's background job ignoring SIGINT).
      struct sigaction previous {};
      if (sigaction(s, nullptr, &previous) == 0 && previous.sa_handler == SIG_IGN) continue;
      sigaction(s, &action, nullptr);
    }
  });
}

TemporaryFileGuard::TemporaryFileGuard(const std::string& path) {
  if (path.size() >= kPathBytes) return;
  for (int i = 0; i < kSlots; ++i) {
    int expected = 0;
    if (g_slots[i].state.compare_exchange_strong(expected, 1, std::memory_order_acq_rel)) {
      std::memcpy(g_slots[i].path, path.c_str(), path.size() + 1);
      g_slots[i].state.store(2, std::memory_order_release);
      slot_ = i;
      return;
    }
  }
}

TemporaryFileGuard::~TemporaryFileGuard() {
  if (slot_ >= 0) g_slots[slot_].state.store(0, std::memory_order_release);
}

}  // namespace lensmith
