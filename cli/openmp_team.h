// The command line's OpenMP team, started before the first parallel region needs it.
#pragma once

namespace lensmith::cli {

// Starts OpenMP's team of `threads` threads (a parallel region with nothing in it) while a helper
// thread keeps the other processors awake, yielding to any thread that can run, until the team is
// up. libgomp's first region waits for its new threads to start, and on the KVM guests of
// docs/performance.md a thread woken on an idle virtual processor starts when the host next wakes
// that processor: a first region of nothing took 0.8 to 17 ms there, and 0.10 to 0.17 ms so. Call
// it once, before a command's first parallel work; 1 thread or fewer: nothing.
void start_openmp_team(int threads);

}  // namespace lensmith::cli
