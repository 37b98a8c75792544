#include "openmp_team.h"

#include <omp.h>

#include <atomic>
#include <thread>

namespace lensmith::cli {

namespace {
// Set once the team is up; the helper, detached, reads it until then (a static, so that it outlives
// the call that started the helper).
std::atomic<bool> team_started{false};
}  // namespace

void start_openmp_team(int threads) {
  if (threads <= 1 || team_started.load()) return;
  std::thread([] {
    while (!team_started.load(std::memory_order_relaxed)) std::this_thread::yield();
  }).detach();
#pragma omp parallel num_threads(threads)
  {
  }
  team_started.store(true);
}

}  // namespace lensmith::cli
