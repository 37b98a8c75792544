// Image sequences: file-name patterns with a frame number, and the frames of a shot.
//
// Patterns as the tools that write sequences spell them (docs/sequences.md):
//   "shot.####.exr"  one digit per '#' (Nuke, Houdini): frame 1001 -> shot.1001.exr, 7 -> shot.0007.exr;
//                    a single '#' is four digits, as OpenImageIO reads it ("shot.#.exr" -> shot.0007.exr);
//   "shot.@@@.exr"   one digit per '@' (OpenImageIO, Nuke): 7 -> shot.007.exr;
//   "shot.%04d.exr"  printf's zero-padded decimal (Nuke, ffmpeg, OpenImageIO); "%d" is unpadded.
// Frames wider than the padding keep all their digits (12345 in "####" -> 12345); negative frames
// get a '-' before the padded digits (-5 in "####" -> -005, as Nuke writes them).
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace lensmith {

class FramePattern {
 public:
  // The pattern in `path`, or nothing when `path` names one file. Throws OptionsError for a path with
  // two frame-number fields ("a.##.b.##.exr"), which no tool writes and which is surely a mistake.
  static std::optional<FramePattern> find(const std::string& path);

  // The file of `frame`.
  std::string path(long frame) const;
  const std::string& text() const { return text_; }  // the pattern as given
  int padding() const { return padding_; }            // digits (0: unpadded %d)

 private:
  std::string text_;
  std::string prefix_;
  std::string suffix_;
  int padding_ = 0;
};

// The frames of a shot, in the order given: "1001-1100", "1001-1100x2" (every second frame),
// "1,5,10-20", "-3--1" (negative frames). Throws OptionsError naming the part that is not a frame,
// a range, or a range with a step (a step must be >= 1; a range must not run backwards), and for a
// list of more than 10 million frames.
std::vector<long> parse_frame_list(const std::string& text);

// The frames of `frames` in chunk `index` (0-based) of `count` contiguous chunks of as equal a size
// as can be (a farm's array task). Throws OptionsError when index is not in [0, count).
std::vector<long> frame_chunk(const std::vector<long>& frames, int index, int count);

}  // namespace lensmith
