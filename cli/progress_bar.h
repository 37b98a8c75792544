// A one-line progress bar on stderr for long commands (bokeh, scene render): drawn only when stderr
// is a terminal and --quiet is not given, so logs and CI output stay clean.
#pragma once

#include <unistd.h>

#include <cmath>
#include <iomanip>
#include <iostream>
#include <string>

namespace lensmith::cli {

class ProgressBar {
 public:
  ProgressBar(std::string label, bool enabled) : label_(std::move(label)), enabled_(enabled && isatty(STDERR_FILENO)) {}
  void update(double fraction) {
    if (!enabled_) return;
    const int percent = static_cast<int>(std::lround(100.0 * fraction));
    if (percent == last_) return;
    last_ = percent;
    const int filled = percent * kWidth / 100;
    std::cerr << "\r" << label_ << " [" << std::string(static_cast<std::size_t>(filled), '#')
              << std::string(static_cast<std::size_t>(kWidth - filled), ' ') << "] " << std::setw(3) << percent << "%"
              << std::flush;
  }
  void finish() {
    if (enabled_ && last_ >= 0) std::cerr << "\n";
  }

 private:
  static constexpr int kWidth = 40;
  std::string label_;
  bool enabled_;
  int last_ = -1;
};

}  // namespace lensmith::cli
