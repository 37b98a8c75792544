// Per-frame values of a shot's camera (a focus pull, an iris or zoom move) as keyframed curves:
// linear between keys, held before the first key and after the last (docs/sequences.md).
//
// JSON: an object of curves, each an array of [frame, value] keys:
//   {"focus_m": [[1001, 2.0], [1048, 3.5]], "fstop": [[1001, 2.8]]}
// CSV: a header "frame,NAME,..." and one row per key frame; an empty cell is no key for that curve;
// lines starting with '#' are comments:
//   frame,focus_m,fstop
//   1001,2.0,2.8
//   1048,3.5,
#pragma once

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace lensmith {

class FrameCurves {
 public:
  // Reads a .json or .csv curve file (by extension; any case). Curve names must be among `allowed`.
  // Throws IoError when the file cannot be read, FileError(file:line[:col]) for a malformed file:
  // an unknown curve (listing the allowed names), a value that is not a finite number, a frame that
  // is not a whole number, a frame keyed twice in one curve, a curve without keys.
  static FrameCurves read(const std::string& path, const std::vector<std::string>& allowed);
  static FrameCurves parse_json(std::string_view text, const std::string& file_name, const std::vector<std::string>& allowed);
  static FrameCurves parse_csv(std::string_view text, const std::string& file_name, const std::vector<std::string>& allowed);

  bool has(const std::string& name) const { return curves_.count(name) > 0; }
  // The curve's value at `frame`; nothing when the file has no such curve.
  std::optional<double> value(const std::string& name, long frame) const;
  std::vector<std::string> names() const;

 private:
  std::map<std::string, std::vector<std::pair<long, double>>> curves_;  // keys sorted by frame
};

}  // namespace lensmith
