// Reader for pbrt RealisticCamera lens files (.dat): one row per surface with radius, thickness,
// index and aperture DIAMETER in millimetres, '#' comments. The files come from W. J. Smith,
// Modern Lens Design, via pbrt-v4-scenes; the two column conventions and how the header comments
// are read are in docs/lens-formats-foreign.md, section "pbrt".
#include "lensmith/core/ascii_text.h"
#include "lensmith/prescription/pbrt_reader.h"

#include <array>
#include <charconv>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"

namespace lensmith {
namespace {

constexpr std::size_t kMaxRows = 10000;  // a camera lens has tens of surfaces
constexpr std::size_t kColumns = 4;      // radius, thickness, index, aperture diameter
constexpr double kMaxPlausibleIndex = 5.0;
// A field-of-view hint in the header is believed only for a half angle in (0, 90) degrees.
constexpr double kMaxHalfFieldDeg = 90.0;

std::string shown(std::string_view s) {
  constexpr std::size_t kMax = 32;
  return s.size() <= kMax ? std::string(s) : std::string(s.substr(0, kMax)) + "...";
}


struct Row {
  int line = 0;
  std::array<double, kColumns> value{};
  std::array<int, kColumns> column{};  // 1-based byte columns of the values
};

// A header comment line as written, without '#', surrounding blanks, and the stray unbalanced '"'
// that spreadsheet exports left at the end of several pbrt-v4-scenes headers.
std::string clean_comment(std::string_view text) {
  std::string_view t = trim_blanks(text);
  std::size_t quotes = 0;
  for (char c : t) quotes += c == '"' ? 1 : 0;
  if (quotes % 2 == 1 && !t.empty() && t.back() == '"') t = trim_blanks(t.substr(0, t.size() - 1));
  return std::string(t);
}

// The "radius axpos N aperture" line that names the columns.
bool is_column_header(std::string_view comment) {
  const std::string l = to_lower_ascii(comment);
  return l.rfind("radius", 0) == 0;
}

// A number written just before position `end` in `s` ("22deg", "155.9", "22 deg"), or nullopt.
std::optional<double> number_before(std::string_view s, std::size_t end) {
  std::string_view head = trim_blanks(s.substr(0, end));
  for (std::string_view unit : {"degrees", "degree", "deg"}) {
    if (head.size() >= unit.size() && to_lower_ascii(head.substr(head.size() - unit.size())) == unit) {
      head = trim_blanks(head.substr(0, head.size() - unit.size()));
      break;
    }
  }
  std::size_t start = head.size();
  while (start > 0 && ((head[start - 1] >= '0' && head[start - 1] <= '9') || head[start - 1] == '.')) --start;
  if (start == head.size()) return std::nullopt;
  return parse_finite_number(head.substr(start));
}

// Half field angle (degrees) from a header such as "D-GAUSS F/2 22deg HFOV" (half field) or
// "Muller 16mm/f4 155.9FOV fisheye lens" (full field).
std::optional<double> half_field_from_header(std::string_view header) {
  const std::string l = to_lower_ascii(header);
  for (std::size_t pos = l.find("fov"); pos != std::string::npos; pos = l.find("fov", pos + 1)) {
    const bool half = pos > 0 && l[pos - 1] == 'h';
    const std::size_t number_end = half ? pos - 1 : pos;
    auto value = number_before(l, number_end);
    if (!value) continue;
    const double half_deg = half ? *value : *value / 2.0;
    if (half_deg > 0.0 && half_deg < kMaxHalfFieldDeg) return half_deg;
  }
  return std::nullopt;
}

class PbrtParser {
 public:
  explicit PbrtParser(const std::string& file_name) : file_(file_name) {}

  LensReadResult parse(std::string_view text, PbrtConvention convention) {
    // A UTF-8 byte-order mark (editors on Windows add one) is not part of the first line.
    if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
    int line_number = 0;
    std::size_t pos = 0;
    while (pos <= text.size()) {
      std::size_t end = text.find('\n', pos);
      if (end == std::string_view::npos) end = text.size();
      ++line_number;
      handle_line(text.substr(pos, end - pos), line_number);
      if (end == text.size()) break;
      pos = end + 1;
    }
    if (rows_.empty()) fail(line_number, 0, "no lens rows (radius thickness index aperture-diameter)");
    return build(resolve_convention(convention));
  }

 private:
  [[noreturn]] void fail(int line, int column, const std::string& message) const {
    throw FileError(SourceLocation{file_, line, column}, message);
  }

  void handle_line(std::string_view line, int number) {
    if (line.find('\0') != std::string_view::npos) {
      fail(number, static_cast<int>(line.find('\0')) + 1, "NUL byte in the text: not a pbrt lens file");
    }
    std::string_view data = line;
    const std::size_t hash = line.find('#');
    if (hash != std::string_view::npos) {
      if (rows_.empty()) {
        const std::string comment = clean_comment(line.substr(hash + 1));
        if (!comment.empty() && !is_column_header(comment)) {
          header_.push_back(comment);
          if (header_.size() == 1) name_line_ = number;
        }
      }
      data = line.substr(0, hash);
    }
    if (trim_blanks(data).empty()) return;

    Row row;
    row.line = number;
    std::size_t count = 0;
    std::size_t i = 0;
    while (i < data.size()) {
      while (i < data.size() && is_blank(data[i])) ++i;
      if (i >= data.size()) break;
      const std::size_t start = i;
      while (i < data.size() && !is_blank(data[i])) ++i;
      const std::string_view token = data.substr(start, i - start);
      const int column = static_cast<int>(start) + 1;
      if (count >= kColumns) {
        fail(number, column, "expected 4 columns (radius, thickness, index, aperture diameter), found more");
      }
      auto v = parse_finite_number(token);
      if (!v) fail(number, column, "expected a finite number, got \"" + shown(token) + "\"");
      row.value[count] = *v;
      row.column[count] = column;
      ++count;
    }
    if (count != kColumns) {
      fail(number, 0,
           "expected 4 columns (radius, thickness, index, aperture diameter), found " + std::to_string(count));
    }
    if (rows_.size() >= kMaxRows) fail(number, 0, "more than " + std::to_string(kMaxRows) + " lens rows");
    rows_.push_back(row);
  }

  PbrtConvention resolve_convention(PbrtConvention requested) const {
    if (requested != PbrtConvention::Auto) return requested;
    // Unscaled files list the separation from the previous vertex, so their first row has 0 and
    // their last row does not; scaled files end with pbrt's 0 "to be focused" thickness.
    const bool first_zero = rows_.front().value[1] == 0.0;
    const bool last_zero = rows_.back().value[1] == 0.0;
    return first_zero && !last_zero ? PbrtConvention::SeparationFromPrevious : PbrtConvention::ThicknessToNext;
  }

  LensReadResult build(PbrtConvention convention) {
    LensReadResult result;
    Prescription& p = result.prescription;
    set_metadata(p, result.diagnostics);

    if (convention == PbrtConvention::SeparationFromPrevious && rows_.front().value[1] != 0.0) {
      const Row& r = rows_.front();
      fail(r.line, r.column[1],
           "first row's separation = " + format_number(r.value[1]) +
               ": must be 0 in the separation-from-previous convention (there is no previous vertex)");
    }

    std::optional<std::size_t> stop_row;
    for (std::size_t k = 0; k < rows_.size(); ++k) {
      const Row& r = rows_[k];
      const double radius = r.value[0];
      const double index = r.value[2];
      const double diameter = r.value[3];
      Surface s;
      s.is_stop = radius == 0.0;
      if (s.is_stop) {
        if (stop_row) {
          fail(r.line, r.column[0],
               "a second aperture stop (radius 0); the first is on line " + std::to_string(rows_[*stop_row].line));
        }
        stop_row = k;
      } else {
        s.curvature_per_mm = 1.0 / radius;
      }

      // The row whose second column holds this surface's thickness. For the last surface of an
      // unscaled file there is none: its thickness stays 0, unused like pbrt's own last 0, because
      // pbrt focuses by itself and lensmith puts the image at the paraxial focus.
      const Row* holder = nullptr;
      if (convention == PbrtConvention::ThicknessToNext) {
        holder = &r;
      } else if (k + 1 < rows_.size()) {
        holder = &rows_[k + 1];
      }
      if (holder != nullptr) {
        if (holder->value[1] < 0.0) {
          fail(holder->line, holder->column[1], "thickness = " + format_number(holder->value[1]) + ": must be >= 0");
        }
        s.thickness_mm = holder->value[1];
      }

      // The index column is the medium after the surface; pbrt reads 0 (written on stop rows) as air.
      if (index == 0.0 && s.is_stop) {
        s.material = MaterialSpec::air();
      } else if (index == 1.0) {
        s.material = MaterialSpec::air();
      } else if (index > 1.0 && index <= kMaxPlausibleIndex) {
        s.material = MaterialSpec::model(index, std::nullopt);
      } else {
        fail(r.line, r.column[2],
             "index = " + format_number(index) + ": must be 1 (air), a glass index in (1, 5], or 0 on the stop row");
      }

      if (!(diameter > 0.0)) {
        fail(r.line, r.column[3], "aperture diameter = " + format_number(diameter) + ": must be > 0");
      }
      s.semi_diameter_mm = diameter / 2.0;
      p.surfaces.push_back(std::move(s));
    }
    if (!stop_row) fail(rows_.back().line, 0, "no aperture stop: pbrt marks it with a row of radius 0");

    p.object_distance_mm = kInfinity;
    p.image_at_paraxial_focus = true;
    p.aperture = ApertureSpec{ApertureSpec::Kind::FloatByStop, 0.0};

    // Only air and model glasses occur, so no catalogue is needed (or loaded).
    const GlassCatalog no_catalogue{};
    resolve_and_validate(p, no_catalogue, file_, [this](const ErrorSubject& e) { return line_for_subject(e); });
    return result;
  }

  // First header line = name; "Scaled to ..." lines = notes; the rest (patent, book page) = source.
  void set_metadata(Prescription& p, Diagnostics& diagnostics) const {
    if (header_.empty()) {
      const std::size_t slash = file_.find_last_of("/\\");
      p.name = slash == std::string::npos ? file_ : file_.substr(slash + 1);
      const std::size_t dot = p.name.find_last_of('.');
      if (dot != std::string::npos && dot > 0) p.name.resize(dot);
      return;
    }
    p.name = header_.front();
    for (std::size_t i = 1; i < header_.size(); ++i) {
      std::string& target = to_lower_ascii(header_[i]).find("scaled") != std::string::npos ? p.notes : p.source;
      if (!target.empty()) target += "; ";
      target += header_[i];
    }
    if (auto half_deg = half_field_from_header(p.name)) {
      FieldSpec field;
      field.kind = FieldSpec::Kind::AngleDeg;
      field.values = {0.0, *half_deg};
      p.field = field;
      diagnostics.push_back(
          Diagnostic{Diagnostic::Severity::Note, SourceLocation{file_, name_line_, 0},
                     "half field angle " + format_number(*half_deg) + " deg taken from the header \"" + p.name + "\""});
    }
  }

  // The row a GlassError or PrescriptionError is about: its subject's surface.
  int line_for_subject(const ErrorSubject& subject) const {
    const int n = subject.surface;
    return n >= 1 && n <= static_cast<int>(rows_.size()) ? rows_[static_cast<std::size_t>(n - 1)].line : 0;
  }

  const std::string& file_;
  std::vector<std::string> header_;
  int name_line_ = 0;
  std::vector<Row> rows_;
};

}  // namespace

LensReadResult read_pbrt(std::string_view text, const std::string& file_name, PbrtConvention convention) {
  PbrtParser parser(file_name);
  return parser.parse(text, convention);
}

}  // namespace lensmith
