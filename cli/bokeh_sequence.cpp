// `lensmith bokeh --frames`: a shot, frame by frame (docs/sequences.md). Each frame is one ordinary
// `lensmith bokeh` run on the frame's files with the frame's camera values, so a frame comes out the
// same whether the shot is rendered whole, in chunks or on a farm.
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "commands.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/frame_curves.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/imageio/frame_sequence.h"

namespace lensmith::cli {

namespace {

// The curves a shot can key, and what each sets.
const std::vector<std::string> kCurveNames{"focus_m", "fstop", "focal_length_mm", "pinhole_focal_length_mm"};

// "I/N" -> (I, N).
std::pair<int, int> parse_chunk(const std::string& text) {
  const std::size_t slash = text.find('/');
  const std::optional<double> index = slash == std::string::npos ? std::nullopt : parse_finite_number(text.substr(0, slash));
  const std::optional<double> count = slash == std::string::npos ? std::nullopt : parse_finite_number(text.substr(slash + 1));
  if (!index || !count || *index != std::floor(*index) || *count != std::floor(*count) || *count < 1 || *index < 0 || *index >= *count ||
      *count > 1e6) {
    throw UsageError("--chunk " + text + ": expected I/N, chunk I (0-based) of N, e.g. 0/8 ... 7/8");
  }
  return {static_cast<int>(*index), static_cast<int>(*count)};
}

std::string clock_text(double seconds) {
  const auto s = static_cast<long>(std::lround(seconds));
  std::ostringstream os;
  os << s / 60 << ":" << std::setw(2) << std::setfill('0') << s % 60;
  return os.str();
}

// Frames done, frames per second and the time left, on one line of a terminal.
class ShotProgress {
 public:
  ShotProgress(std::size_t frames, bool enabled) : frames_(frames), enabled_(enabled && isatty(STDERR_FILENO)) {}
  void update(std::size_t done, std::size_t rendered) {
    if (!enabled_) return;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    std::cerr << "\rshot: " << done << " of " << frames_ << " frames";
    if (rendered > 0 && elapsed > 0.0) {
      const double rate = static_cast<double>(rendered) / elapsed;
      std::cerr << ", " << std::fixed << std::setprecision(rate < 1.0 ? 2 : 1) << rate << " frames/s, about "
                << clock_text(static_cast<double>(frames_ - done) / rate) << " left";
    }
    std::cerr << "      " << std::flush;
  }
  void finish() {
    if (enabled_) std::cerr << "\n";
  }

 private:
  std::size_t frames_;
  bool enabled_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace

int run_bokeh_sequence(const BokehCommandOptions& o, const GlobalOptions& global) {
  const std::optional<FramePattern> image = FramePattern::find(o.image);
  const std::optional<FramePattern> output = FramePattern::find(o.output);
  const std::optional<FramePattern> depth = o.depth.empty() ? std::nullopt : FramePattern::find(o.depth);
  if (!image) throw UsageError("--frames: --image " + o.image + " names one file; a sequence's name has a frame field (shot.####.exr, shot.%04d.exr)");
  if (!output) throw UsageError("--frames: -o " + o.output + " names one file; write the frames to a pattern (out.####.exr)");
  std::vector<long> frames;
  try {
    frames = parse_frame_list(o.frames);
  } catch (const OptionsError& e) {
    throw UsageError(std::string("--") + e.what());  // the command line's fault: exit 2
  }
  if (!o.chunk.empty()) {
    const auto [index, count] = parse_chunk(o.chunk);
    frames = frame_chunk(frames, index, count);
  }
  std::optional<FrameCurves> curves;
  if (!o.curves.empty()) {
    curves = FrameCurves::read(o.curves, kCurveNames);
    const auto conflict = [&](const char* curve, bool flag_given, const char* flag) {
      if (curves->has(curve) && flag_given) throw UsageError(std::string(flag) + " and the curve " + curve + " in " + o.curves + " both set it");
    };
    conflict("focus_m", o.focus_m || !o.focus_pixel.empty(), "--focus (or --focus-pixel)");
    conflict("fstop", o.f_number.has_value(), "--fstop");
    conflict("focal_length_mm", o.focal_length_mm.has_value(), "--focal-length");
    conflict("pinhole_focal_length_mm", o.pinhole_focal_length_mm || o.hfov_deg, "--pinhole-focal-length (or --hfov)");
    if (curves->has("focal_length_mm") && !o.thin_lens) {
      throw UsageError(o.curves + ": focal_length_mm keys the focal length of --thin-lens; a prescription's focal length is its own");
    }
  }
  if (o.list_frames) {
    for (const long frame : frames) std::cout << frame << "\n";
    return kExitOk;
  }

  std::size_t written = 0, skipped = 0, done = 0;
  std::vector<std::pair<long, std::string>> failed;
  ShotProgress progress(frames.size(), !global.quiet);
  progress.update(0, 0);
  for (const long frame : frames) {
    BokehCommandOptions f = o;
    f.frames.clear();
    f.image = image->path(frame);
    f.output = output->path(frame);
    if (depth) f.depth = depth->path(frame);
    if (curves) {
      if (auto v = curves->value("focus_m", frame)) f.focus_m = *v;
      if (auto v = curves->value("fstop", frame)) f.f_number = *v;
      if (auto v = curves->value("focal_length_mm", frame)) f.focal_length_mm = *v;
      if (auto v = curves->value("pinhole_focal_length_mm", frame)) f.pinhole_focal_length_mm = *v;
    }
    ++done;
    if (o.skip_existing && std::filesystem::exists(f.output)) {
      ++skipped;
      progress.update(done, written);
      continue;
    }
    // The first frame says what it notices (notes and warnings are the same for every frame); the
    // others only their result.
    GlobalOptions frame_global = global;
    frame_global.quiet = global.quiet || written + failed.size() > 0;
    try {
      const auto started = std::chrono::steady_clock::now();
      run_bokeh(f, frame_global);
      ++written;
      if (!global.quiet && !isatty(STDERR_FILENO)) {
        std::cerr << "frame " << frame << ": wrote " << f.output << " in " << std::fixed << std::setprecision(2)
                  << std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count() << " s\n";
      }
    } catch (const UsageError&) {
      // The command line is wrong for every frame alike: say it once.
      progress.finish();
      throw;
    } catch (const std::exception& e) {
      failed.emplace_back(frame, e.what());
      if (!global.quiet) {
        if (isatty(STDERR_FILENO)) std::cerr << "\n";
        std::cerr << "frame " << frame << ": error: " << e.what() << "\n";
      }
    }
    progress.update(done, written);
  }
  progress.finish();
  if (!global.quiet || !failed.empty()) {
    std::cerr << "shot: " << frames.size() << " frames: " << written << " written, " << skipped << " skipped (output exists), "
              << failed.size() << " failed";
    if (!failed.empty()) {
      std::cerr << " (frames";
      for (std::size_t i = 0; i < failed.size() && i < 20; ++i) std::cerr << " " << failed[i].first;
      if (failed.size() > 20) std::cerr << " ...";
      std::cerr << ")";
    }
    std::cerr << "\n";
  }
  return failed.empty() ? kExitOk : kExitFrames;
}

}  // namespace lensmith::cli
