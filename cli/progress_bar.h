// A one-line progress bar on stderr for long commands (bokeh, scene render): drawn only when stderr
// is a terminal and --quiet is not given, so logs and CI output stay clean.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>
#include <iomanip>
#include <iostream>
#include <string>

namespace lensmith::cli {

// With an estimate of the time left once a few percent are done and a second has passed: the time
// so far times the fraction left over the fraction done (the renderers report progress in even
// steps: bands of rows within each depth layer, samples per pixel). Thread-safe; the percentage only
// grows.
class ProgressBar {
 public:
  ProgressBar(std::string label, bool enabled)
      : label_(std::move(label)), enabled_(enabled && isatty(STDERR_FILENO)), start_(std::chrono::steady_clock::now()) {}
  void update(double fraction) {
    if (!enabled_) return;
    const std::lock_guard<std::mutex> lock(mutex_);
    const int percent = static_cast<int>(std::lround(100.0 * std::clamp(fraction, 0.0, 1.0)));
    if (percent <= last_) return;
    last_ = percent;
    const int filled = percent * kWidth / 100;
    std::cerr << "\r" << label_ << " [" << std::string(static_cast<std::size_t>(filled), '#')
              << std::string(static_cast<std::size_t>(kWidth - filled), ' ') << "] " << std::setw(3) << percent << "%";
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    if (fraction >= kMinFractionForEstimate && elapsed >= kMinSecondsForEstimate && fraction < 1.0) {
      const auto left = static_cast<long>(std::lround(elapsed * (1.0 - fraction) / fraction));
      std::cerr << "  about " << left / 60 << ":" << std::setw(2) << std::setfill('0') << left % 60 << std::setfill(' ') << " left";
    } else {
      std::cerr << std::string(18, ' ');
    }
    std::cerr << std::flush;
  }
  void finish() {
    if (enabled_ && last_ >= 0) std::cerr << "\n";
  }

 private:
  static constexpr int kWidth = 40;
  static constexpr double kMinFractionForEstimate = 0.03;
  static constexpr double kMinSecondsForEstimate = 1.0;
  std::string label_;
  bool enabled_;
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
  int last_ = -1;
};

}  // namespace lensmith::cli
