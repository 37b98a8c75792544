// Wall-clock time spent in each stage of a computation (ms), in the order the stages first ran: what
// `lensmith bokeh --timings` prints, so that a user (and docs/performance.md) can see where a
// process's time goes without a profiler. Stages are named by string literals; a stage lapped
// again (once per depth layer) adds up. A lap costs one clock read (about 20 ns) and no allocation
// after the first few stages, so the renderer keeps it on always.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstring>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

namespace lensmith {

class StageTimes {
 public:
  struct Stage {
    const char* name;  // a string literal
    double ms = 0.0;   // wall-clock milliseconds, summed over its laps
  };

  // Starts (or restarts) the clock of the next lap without charging the time since to any stage.
  void restart() { last_ = Clock::now(); }

  // Charges the wall time since the last lap (or restart) to `name`, a string literal.
  void lap(const char* name) {
    const Clock::time_point now = Clock::now();
    add(name, std::chrono::duration<double, std::milli>(now - last_).count());
    last_ = now;
  }

  // Adds `ms` to `name`'s time (a stage timed elsewhere, e.g. a file's reading by the command).
  void add(const char* name, double ms) {
    for (Stage& s : stages_) {
      if (s.name == name || std::strcmp(s.name, name) == 0) {
        s.ms += ms;
        return;
      }
    }
    stages_.push_back({name, ms});
  }

  const std::vector<Stage>& stages() const { return stages_; }
  double total_ms() const {
    double t = 0.0;
    for (const Stage& s : stages_) t += s.ms;
    return t;
  }

  // "reading 6.12 ms, sources 1.10 ms, ..., total 41.3 ms"
  std::string to_string() const {
    std::ostringstream os;
    os.setf(std::ios::fixed);
    os.precision(2);
    for (const Stage& s : stages_) os << s.name << ' ' << s.ms << " ms, ";
    os << "total " << total_ms() << " ms";
    return os.str();
  }
  friend std::ostream& operator<<(std::ostream& os, const StageTimes& t) { return os << t.to_string(); }

 private:
  using Clock = std::chrono::steady_clock;
  std::vector<Stage> stages_;
  Clock::time_point last_ = Clock::now();
};

}  // namespace lensmith
