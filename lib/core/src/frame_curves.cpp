// Keyframed per-frame curves (frame_curves.h).
#include "lensmith/core/ascii_text.h"
#include "lensmith/core/frame_curves.h"

#include <algorithm>
#include <cmath>

#include "lensmith/core/errors.h"
#include "lensmith/core/located_json.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/text_file.h"

namespace lensmith {

namespace {

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

void check_name(const std::string& name, const std::vector<std::string>& allowed, const SourceLocation& where) {
  if (std::find(allowed.begin(), allowed.end(), name) == allowed.end()) {
    throw FileError(where, "unknown curve \"" + name + "\"; the curves a shot can key are " + join(allowed));
  }
}

// Sorts the keys and refuses a frame keyed twice.
void finish_curve(std::vector<std::pair<long, double>>& keys, const std::string& name, const SourceLocation& where) {
  if (keys.empty()) throw FileError(where, "curve \"" + name + "\" has no keys");
  std::sort(keys.begin(), keys.end());
  for (std::size_t i = 1; i < keys.size(); ++i) {
    if (keys[i].first == keys[i - 1].first) {
      throw FileError(where, "curve \"" + name + "\" keys frame " + std::to_string(keys[i].first) + " twice");
    }
  }
}

}  // namespace

FrameCurves FrameCurves::read(const std::string& path, const std::vector<std::string>& allowed) {
  const std::string text = decode_text(read_file_bytes(path), path);
  const std::string name = to_lower_ascii(path);
  if (name.size() >= 4 && name.compare(name.size() - 4, 4, ".csv") == 0) return parse_csv(text, path, allowed);
  if (name.size() >= 5 && name.compare(name.size() - 5, 5, ".json") == 0) return parse_json(text, path, allowed);
  throw FileError({path, 0, 0}, "a curve file is .json or .csv");
}

FrameCurves FrameCurves::parse_json(std::string_view text, const std::string& file_name, const std::vector<std::string>& allowed) {
  const LocatedJson doc = LocatedJson::parse(text, file_name);
  if (!doc.root().is_object()) throw FileError(doc.where(""), "expected an object of curves, e.g. {\"focus_m\": [[1001, 2.0], [1048, 3.5]]}");
  FrameCurves out;
  for (const auto& [name, keys] : doc.root().items()) {
    const std::string pointer = "/" + name;
    check_name(name, allowed, doc.where(pointer));
    if (!keys.is_array()) throw FileError(doc.where(pointer), name + ": expected an array of [frame, value] keys");
    auto& curve = out.curves_[name];
    for (std::size_t i = 0; i < keys.size(); ++i) {
      const std::string key_pointer = pointer + "/" + std::to_string(i);
      const nlohmann::json& key = keys[i];
      const std::string path = name + "[" + std::to_string(i) + "]";
      if (!key.is_array() || key.size() != 2 || !key[0].is_number() || !key[1].is_number()) {
        throw FileError(doc.where(key_pointer), path + ": expected [frame, value], two numbers");
      }
      const double frame = key[0].get<double>(), value = key[1].get<double>();
      if (frame != std::floor(frame) || std::abs(frame) > 1e15) {
        throw FileError(doc.where(key_pointer + "/0"), path + ": frame " + format_number(frame) + " is not a whole number");
      }
      if (!std::isfinite(value)) throw FileError(doc.where(key_pointer + "/1"), path + ": the value must be finite");
      curve.emplace_back(static_cast<long>(frame), value);
    }
    finish_curve(curve, name, doc.where(pointer));
  }
  return out;
}

FrameCurves FrameCurves::parse_csv(std::string_view text, const std::string& file_name, const std::vector<std::string>& allowed) {
  std::vector<std::string> columns;
  FrameCurves out;
  int line_number = 0;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    std::string line(text.substr(start, end - start));
    start = end + 1;
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos || line[line.find_first_not_of(" \t")] == '#') continue;
    std::vector<std::string> cells;
    std::size_t from = 0;
    while (true) {
      const std::size_t comma = line.find(',', from);
      std::string cell = line.substr(from, comma == std::string::npos ? std::string::npos : comma - from);
      cell.erase(0, cell.find_first_not_of(" \t"));
      cell.erase(cell.find_last_not_of(" \t") + 1);
      cells.push_back(cell);
      if (comma == std::string::npos) break;
      from = comma + 1;
    }
    const SourceLocation where{file_name, line_number, 0};
    if (columns.empty()) {
      if (cells[0] != "frame") throw FileError(where, "expected a header \"frame,NAME,...\", e.g. frame,focus_m,fstop");
      if (cells.size() < 2) throw FileError(where, "the header names no curve after \"frame\"");
      for (std::size_t c = 1; c < cells.size(); ++c) {
        check_name(cells[c], allowed, where);
        if (std::find(cells.begin() + 1, cells.begin() + static_cast<std::ptrdiff_t>(c), cells[c]) != cells.begin() + static_cast<std::ptrdiff_t>(c)) {
          throw FileError(where, "column \"" + cells[c] + "\" twice");
        }
      }
      columns = cells;
      continue;
    }
    if (cells.size() != columns.size()) {
      throw FileError(where, std::to_string(cells.size()) + " cells; the header has " + std::to_string(columns.size()));
    }
    const std::optional<double> frame = parse_finite_number(cells[0]);
    if (!frame || *frame != std::floor(*frame) || std::abs(*frame) > 1e15) {
      throw FileError(where, "frame \"" + cells[0] + "\" is not a whole number");
    }
    for (std::size_t c = 1; c < cells.size(); ++c) {
      if (cells[c].empty()) continue;
      const std::optional<double> value = parse_finite_number(cells[c]);
      if (!value) throw FileError(where, columns[c] + ": \"" + cells[c] + "\" is not a finite number");
      out.curves_[columns[c]].emplace_back(static_cast<long>(*frame), *value);
    }
  }
  if (columns.empty()) throw FileError({file_name, line_number, 0}, "no header \"frame,NAME,...\"");
  for (std::size_t c = 1; c < columns.size(); ++c) finish_curve(out.curves_[columns[c]], columns[c], {file_name, 0, 0});
  return out;
}

std::optional<double> FrameCurves::value(const std::string& name, long frame) const {
  const auto it = curves_.find(name);
  if (it == curves_.end()) return std::nullopt;
  const auto& keys = it->second;
  if (frame <= keys.front().first) return keys.front().second;
  if (frame >= keys.back().first) return keys.back().second;
  const auto after = std::upper_bound(keys.begin(), keys.end(), frame, [](long f, const auto& key) { return f < key.first; });
  const auto before = after - 1;
  const double t = static_cast<double>(frame - before->first) / static_cast<double>(after->first - before->first);
  return before->second + t * (after->second - before->second);
}

std::vector<std::string> FrameCurves::names() const {
  std::vector<std::string> out;
  for (const auto& [name, keys] : curves_) out.push_back(name);
  return out;
}

}  // namespace lensmith
