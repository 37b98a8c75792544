// Image-sequence patterns and frame lists (frame_sequence.h).
#include "lensmith/imageio/frame_sequence.h"

#include <charconv>
#include <cstdlib>

#include "lensmith/core/errors.h"

namespace lensmith {

namespace {

// One frame-number field of a file name: where it starts, how long it is, its padding.
struct Field {
  std::size_t begin = 0;
  std::size_t length = 0;
  int padding = 0;
};

// The frame-number fields of the file-name part of `path` (a folder may well contain '#' or '@').
std::vector<Field> fields_of(const std::string& path) {
  std::vector<Field> fields;
  const std::size_t slash = path.find_last_of('/');
  std::size_t i = slash == std::string::npos ? 0 : slash + 1;
  while (i < path.size()) {
    const char c = path[i];
    if (c == '#' || c == '@') {
      std::size_t j = i;
      while (j < path.size() && path[j] == c) ++j;
      const int run = static_cast<int>(j - i);
      fields.push_back({i, j - i, c == '#' && run == 1 ? 4 : run});
      i = j;
    } else if (c == '%') {
      // %d or %0Nd
      std::size_t j = i + 1;
      int padding = 0;
      if (j < path.size() && path[j] == '0') {
        ++j;
        const std::size_t digits = j;
        while (j < path.size() && path[j] >= '0' && path[j] <= '9') ++j;
        if (j == digits) {
          ++i;
          continue;
        }
        padding = std::atoi(path.substr(digits, j - digits).c_str());
      }
      if (j < path.size() && path[j] == 'd') {
        fields.push_back({i, j + 1 - i, padding});
        i = j + 1;
      } else {
        ++i;
      }
    } else {
      ++i;
    }
  }
  return fields;
}

}  // namespace

std::optional<FramePattern> FramePattern::find(const std::string& path) {
  const std::vector<Field> fields = fields_of(path);
  if (fields.empty()) return std::nullopt;
  if (fields.size() > 1) {
    throw OptionsError(path + ": two frame-number fields (" + path.substr(fields[0].begin, fields[0].length) + " and " +
                       path.substr(fields[1].begin, fields[1].length) + "); a sequence's file name has one (####, @@@@ or %04d)");
  }
  if (fields[0].padding > 18) throw OptionsError(path + ": a frame number of " + std::to_string(fields[0].padding) + " digits");
  FramePattern p;
  p.text_ = path;
  p.prefix_ = path.substr(0, fields[0].begin);
  p.suffix_ = path.substr(fields[0].begin + fields[0].length);
  p.padding_ = fields[0].padding;
  return p;
}

std::string FramePattern::path(long frame) const {
  std::string digits = std::to_string(frame < 0 ? -frame : frame);
  if (static_cast<int>(digits.size()) < padding_ - (frame < 0 ? 1 : 0)) {
    digits.insert(0, static_cast<std::size_t>(padding_ - (frame < 0 ? 1 : 0)) - digits.size(), '0');
  }
  return prefix_ + (frame < 0 ? "-" : "") + digits + suffix_;
}

namespace {

long parse_frame(const std::string& text, const std::string& whole) {
  long value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, error] = std::from_chars(text.data(), end, value);
  if (text.empty() || error != std::errc() || ptr != end) {
    throw OptionsError("frames '" + whole + "': '" + text + "' is not a frame number");
  }
  return value;
}

}  // namespace

std::vector<long> parse_frame_list(const std::string& text) {
  constexpr std::size_t kMaxFrames = 10'000'000;
  std::vector<long> frames;
  if (text.empty()) throw OptionsError("frames: empty; expected e.g. 1001-1100, 1001-1100x2 or 1,5,10-20");
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = text.find(',', start);
    const std::string part = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (part.empty()) throw OptionsError("frames '" + text + "': an empty entry between commas");
    // A range is FIRST-LAST[xSTEP]; FIRST may be negative, so the '-' looked for starts after it.
    const std::size_t dash = part.find('-', 1);
    if (dash == std::string::npos) {
      frames.push_back(parse_frame(part, text));
    } else {
      const long first = parse_frame(part.substr(0, dash), text);
      std::string rest = part.substr(dash + 1);
      long step = 1;
      if (const std::size_t x = rest.find('x'); x != std::string::npos) {
        step = parse_frame(rest.substr(x + 1), text);
        rest = rest.substr(0, x);
        if (step < 1) throw OptionsError("frames '" + text + "': in '" + part + "' the step must be >= 1");
      }
      const long last = parse_frame(rest, text);
      if (last < first) throw OptionsError("frames '" + text + "': '" + part + "' runs backwards (write FIRST-LAST with FIRST <= LAST)");
      if (static_cast<unsigned long>(last - first) / static_cast<unsigned long>(step) + frames.size() >= kMaxFrames) {
        throw OptionsError("frames '" + text + "': more than 10 million frames");
      }
      for (long f = first; f <= last; f += step) frames.push_back(f);
    }
    if (frames.size() > kMaxFrames) throw OptionsError("frames '" + text + "': more than 10 million frames");
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return frames;
}

std::vector<long> frame_chunk(const std::vector<long>& frames, int index, int count) {
  if (count < 1 || index < 0 || index >= count) {
    throw OptionsError("chunk " + std::to_string(index) + " of " + std::to_string(count) + ": the index must be in [0, " +
                       std::to_string(count) + ")");
  }
  const std::size_t n = frames.size(), k = static_cast<std::size_t>(count), i = static_cast<std::size_t>(index);
  const std::size_t begin = n * i / k, end = n * (i + 1) / k;
  return {frames.begin() + static_cast<std::ptrdiff_t>(begin), frames.begin() + static_cast<std::ptrdiff_t>(end)};
}

}  // namespace lensmith
