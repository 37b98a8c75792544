// Reader for Zemax OpticStudio sequential lens files (.zmx). OpticStudio writes one keyword per
// line: system data first, then one block per surface ("SURF n" followed by indented surface
// keywords). Lengths are in the lens unit of the UNIT line, wavelengths in micrometres.
// The keyword table (read, ignored, refused) is in docs/lens-formats-foreign.md, section "Zemax".
#include "lensmith/core/ascii_text.h"
#include "lensmith/prescription/zemax_reader.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/text_file.h"
#include "lensmith/core/units.h"

namespace lensmith {
namespace {

// Limits that keep hostile input from asking for unbounded work or memory. OpticStudio itself
// stays far below them (24 wavelength slots, a few hundred surfaces and fields).
constexpr int kMaxSurfaceNumber = 10000;
constexpr int kMaxWavelengthSlot = 1000;
constexpr int kMaxFieldCount = 1000;

// OpticStudio writes nd 1.5 and Vd 40 on the GLAS line of every catalogue glass: they are its
// model-glass defaults, not data about that glass, so they never stand in for a missing glass.
constexpr double kPlaceholderNd = 1.5;
constexpr double kPlaceholderVd = 40.0;

// Indices and Vd on a GLAS line outside these bounds are not optical glass.
constexpr double kMaxPlausibleIndex = 5.0;

// Keywords that change nothing lensmith models: drawing, coating, tolerancing, optimisation,
// ray-aiming and bookkeeping data (MIRR only sets how a mirror substrate is drawn; GLAS MIRROR is
// what makes a mirror). Sorted for binary search.
// clang-format off
constexpr auto kIgnoredKeywords = std::to_array<std::string_view>({
    "BLNK", "COAT", "COFN", "CONF", "DMFS", "EDGE", "EFFL", "FIMP", "FWGN", "FWGT", "GFAC", "GLRS",
    "GSTD", "HIDE", "HYPR", "ISNA", "LANG", "MAZH", "MEMA", "MIRR", "MNCA", "MNCG", "MNEA", "MNEG", "MOFF",
    "MXCA", "MXCG", "NSCD", "OEMA", "OMMA", "OPDX", "PFIL", "PICB", "PKUP", "PMAG", "POLS", "POPS", "PPAR",
    "PUPD", "PUSH", "PZUP", "RGLA", "ROPD", "SDMA", "SLAB", "TCED", "TCMM", "TOL", "TOLE", "TOTR",
    "TRAC", "VCON", "VDSZ", "VERS", "VPAR", "WAVN", "WWGN", "WWGT",
    "ZVAN", "ZVCX", "ZVCY", "ZVDX", "ZVDY",
});
// Surface apertures lensmith cannot represent (spiders, user-defined aperture files): always an error.
constexpr auto kRefusedApertureKeywords = std::to_array<std::string_view>({
    "SPID", "UDAD", "USAP", "USOB",
});
// Decentres, tilts and extra surface data: an error unless every value is zero.
constexpr auto kZeroOnlyKeywords = std::to_array<std::string_view>({
    "DECX", "DECY", "TILT", "TILX", "TILY", "TILZ", "XDAT", "YDAT",
});
// clang-format on
static_assert(std::ranges::is_sorted(kIgnoredKeywords) && std::ranges::is_sorted(kRefusedApertureKeywords) &&
              std::ranges::is_sorted(kZeroOnlyKeywords));

template <std::size_t N>
bool contains(const std::array<std::string_view, N>& sorted, std::string_view key) {
  return std::binary_search(sorted.begin(), sorted.end(), key);
}

// Trims blanks and line breaks (a note often ends with "NOTE 4" line breaks).
std::string_view trim_lines(std::string_view s) {
  while (!s.empty() && (is_blank(s.front()) || s.front() == '\n')) s.remove_prefix(1);
  while (!s.empty() && (is_blank(s.back()) || s.back() == '\n')) s.remove_suffix(1);
  return s;
}

std::optional<long long> parse_integer(std::string_view s) {
  if (s.size() >= 2 && s.front() == '+' && s[1] != '-') s.remove_prefix(1);
  long long v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return v;
}

struct Token {
  std::string_view text;
  int column = 0;  // 1-based byte column in the line
};

// One line split into its keyword and arguments (views into the decoded text).
struct ZmxLine {
  int number = 0;
  Token keyword;
  std::vector<Token> args;
  std::string_view rest;  // everything after the keyword and the blanks that follow it
  int end_column = 1;     // column just past the last character, for "missing argument" errors
};

ZmxLine split_line(std::string_view line, int number) {
  ZmxLine out;
  out.number = number;
  out.end_column = static_cast<int>(line.size()) + 1;
  std::size_t i = 0;
  bool first = true;
  while (i < line.size()) {
    while (i < line.size() && is_blank(line[i])) ++i;
    if (i >= line.size()) break;
    const std::size_t start = i;
    while (i < line.size() && !is_blank(line[i])) ++i;
    Token t{line.substr(start, i - start), static_cast<int>(start) + 1};
    if (first) {
      out.keyword = t;
      std::size_t r = i;
      while (r < line.size() && is_blank(line[r])) ++r;
      out.rest = line.substr(r);
      first = false;
    } else {
      out.args.push_back(t);
    }
  }
  return out;
}

struct GlassRef {
  std::string name;
  int line = 0;
  int column = 0;
  std::optional<double> nd;
  std::optional<double> vd;
  double dpgf = 0.0;
};

struct ParmRecord {
  long long index = 0;
  double value = 0.0;
  int line = 0;
  int column = 0;
};

struct Located {
  double value = 0.0;
  int line = 0;
  int column = 0;
};

// One SURF block as written, in lens units; converted to millimetres when the prescription is built.
struct ZmxSurface {
  int number = 0;
  int line = 0;
  std::string type = "STANDARD";
  double curvature = 0.0;  // 1 / lens unit
  int curv_line = 0;
  std::optional<double> disz;  // lens units; empty with disz_infinite for INFINITY
  bool disz_infinite = false;
  int disz_line = 0;
  int disz_column = 0;
  std::optional<GlassRef> glass;
  std::optional<double> diam;      // semi-diameter, lens units
  bool floating_aperture = false;  // FLAP: the semi-diameter is a clear aperture
  // An explicit aperture (CLAP, SQAP, ELAP, OBSC, OBSQ, ELOB), lens units; decentred by OBDC.
  std::optional<SurfaceAperture> aperture;
  int aperture_line = 0;
  std::string aperture_keyword;
  std::optional<std::array<double, 2>> aperture_decenter;  // OBDC x y, lens units
  int decenter_line = 0;
  bool stop = false;
  int stop_line = 0;
  double conic = 0.0;
  std::vector<ParmRecord> parms;
  std::vector<ParmRecord> xdat;  // TOROIDAL's extra data (XDAT index value)
  bool mirror = false;           // GLAS MIRROR
  // SCBD 1 (a tilt and decentre before the surface, as a coordinate break): order, dx, dy, tx, ty, tz.
  std::optional<CoordinateBreak> break_before;  // in lens units until make_surface
  int break_line = 0;
  std::string comment;
};

struct ApertureLine {
  ApertureSpec::Kind kind = ApertureSpec::Kind::FloatByStop;
  double value = 0.0;  // EPD in lens units, or F/#
  int line = 0;
};

struct FieldTypeLine {
  long long type = 0;
  long long field_count = 0;
  long long wavelength_count = 0;
  bool telecentric = false;  // object space
  int line = 0;
};


class ZemaxParser {
 public:
  ZemaxParser(const std::string& file_name, const GlassCatalog& catalogue) : file_(file_name), catalogue_(catalogue) {}

  LensReadResult parse(std::string_view bytes) {
    const std::string text = decode_text(bytes, file_);
    int line_number = 0;
    std::size_t pos = 0;
    while (pos <= text.size()) {
      std::size_t end = text.find('\n', pos);
      if (end == std::string::npos) end = text.size();
      std::string_view line(text.data() + pos, end - pos);
      ++line_number;
      if (line.find('\0') != std::string_view::npos) {
        fail(line_number, static_cast<int>(line.find('\0')) + 1,
             "NUL byte in the text: not a .zmx text file (UTF-16 without a byte-order mark?)");
      }
      handle(split_line(line, line_number));
      if (end == text.size()) break;
      pos = end + 1;
    }
    last_line_ = line_number;
    return build();
  }

 private:
  // ---- errors and argument access --------------------------------------------------------------

  [[noreturn]] void fail(int line, int column, const std::string& message) const {
    throw FileError(SourceLocation{file_, line, column}, message);
  }
  [[noreturn]] void fail_at(const ZmxLine& l, const Token& t, const std::string& message) const {
    fail(l.number, t.column, std::string(l.keyword.text) + ": " + message);
  }
  void warn(int line, const std::string& message) {
    diagnostics_.push_back(Diagnostic{Diagnostic::Severity::Warning, SourceLocation{file_, line, 0}, message});
  }
  void note(int line, const std::string& message) {
    diagnostics_.push_back(Diagnostic{Diagnostic::Severity::Note, SourceLocation{file_, line, 0}, message});
  }

  const Token& required_arg(const ZmxLine& l, std::size_t i, const std::string& what) const {
    if (i >= l.args.size()) {
      fail(l.number, l.end_column, std::string(l.keyword.text) + ": missing " + what);
    }
    return l.args[i];
  }
  double number(const ZmxLine& l, std::size_t i, const std::string& what) const {
    const Token& t = required_arg(l, i, what);
    auto v = parse_finite_number(t.text);
    if (!v) fail_at(l, t, "expected a finite number for " + what + ", got \"" + shown_text(t.text) + "\"");
    return *v;
  }
  long long integer(const ZmxLine& l, std::size_t i, const std::string& what, long long min, long long max) const {
    const Token& t = required_arg(l, i, what);
    auto v = parse_integer(t.text);
    if (!v) fail_at(l, t, "expected an integer for " + what + ", got \"" + shown_text(t.text) + "\"");
    if (*v < min || *v > max) {
      fail_at(l, t,
              what + " = " + std::to_string(*v) + ": must be in [" + std::to_string(min) + ", " + std::to_string(max) +
                  "]");
    }
    return *v;
  }
  std::vector<Located> all_numbers(const ZmxLine& l, const std::string& what) const {
    std::vector<Located> out;
    out.reserve(l.args.size());
    for (std::size_t i = 0; i < l.args.size(); ++i) out.push_back({number(l, i, what), l.number, l.args[i].column});
    return out;
  }
  ZmxSurface& current_surface(const ZmxLine& l) {
    if (surfaces_.empty()) {
      fail(l.number, l.keyword.column, std::string(l.keyword.text) + ": surface data before the first SURF line");
    }
    return surfaces_.back();
  }

  // ---- one line --------------------------------------------------------------------------------

  void handle(const ZmxLine& l) {
    const std::string_view k = l.keyword.text;
    if (k.empty()) return;
    if (k == "SURF") return handle_surf(l);
    if (k == "TYPE") return handle_type(l);
    if (k == "CURV") {
      ZmxSurface& s = current_surface(l);
      s.curvature = number(l, 0, "the curvature (1/lens unit)");
      s.curv_line = l.number;
      return;
    }
    if (k == "DISZ") return handle_disz(l);
    if (k == "GLAS") return handle_glas(l);
    if (k == "DIAM") {
      ZmxSurface& s = current_surface(l);
      const double sd = number(l, 0, "the semi-diameter");
      if (sd < 0.0) fail_at(l, l.args[0], "semi-diameter = " + format_number(sd) + ": must be >= 0");
      s.diam = sd;
      return;
    }
    if (k == "CLAP" || k == "SQAP" || k == "ELAP" || k == "OBSC" || k == "OBSQ" || k == "ELOB" || k == "SQOB") {
      return handle_aperture(l);
    }
    if (k == "FLAP") {
      current_surface(l).floating_aperture = true;
      return;
    }
    if (k == "OBDC") {
      ZmxSurface& s = current_surface(l);
      s.aperture_decenter = std::array<double, 2>{number(l, 0, "the aperture x decentre"), number(l, 1, "the aperture y decentre")};
      s.decenter_line = l.number;
      return;
    }
    if (k == "RAIM") return handle_raim(l);
    if (k == "STOP") {
      ZmxSurface& s = current_surface(l);
      if (stop_line_ != 0) {
        fail(l.number, l.keyword.column,
             "STOP: a second aperture stop (the first is on line " + std::to_string(stop_line_) + ")");
      }
      s.stop = true;
      s.stop_line = l.number;
      stop_line_ = l.number;
      return;
    }
    if (k == "CONI") {
      current_surface(l).conic = number(l, 0, "the conic constant");
      return;
    }
    if (k == "PARM") {
      ZmxSurface& s = current_surface(l);
      ParmRecord p;
      p.index = integer(l, 0, "the parameter number", 0, 1000);
      p.value = number(l, 1, "the parameter value");
      p.line = l.number;
      p.column = l.args[1].column;
      s.parms.push_back(p);
      return;
    }
    if (k == "COMM") {
      current_surface(l).comment = std::string(trim_blanks(l.rest));
      return;
    }
    if (k == "UNIT") return handle_unit(l);
    if (k == "NAME") {
      std::string_view name = trim_blanks(l.rest);
      if (name.size() >= 2 && name.front() == '"' && name.back() == '"') name = name.substr(1, name.size() - 2);
      name_ = std::string(name);
      return;
    }
    if (k == "NOTE") return handle_note(l);
    if (k == "MODE") {
      const Token& t = required_arg(l, 0, "the mode");
      if (t.text != "SEQ") {
        fail_at(l, t, "mode \"" + shown_text(t.text) + "\" is not supported: only sequential (SEQ) files are read");
      }
      return;
    }
    if (k == "GCAT") return handle_gcat(l);
    if (k == "ENPD") {
      aperture_ = ApertureLine{ApertureSpec::Kind::EntrancePupilDiameter, number(l, 0, "the entrance-pupil diameter"),
                               l.number};
      return;
    }
    if (k == "FNUM") {
      // FNUM value type: type 0 image-space F/#, 1 paraxial working F/#.
      const double f = number(l, 0, "the F-number");
      const long long type = l.args.size() > 1 ? integer(l, 1, "the F-number type (0 image space, 1 paraxial working)", 0, 1) : 0;
      aperture_ = ApertureLine{type == 0 ? ApertureSpec::Kind::ImageSpaceFNumber : ApertureSpec::Kind::ParaxialWorkingFNumber, f,
                               l.number};
      return;
    }
    if (k == "FLOA") {
      aperture_ = ApertureLine{ApertureSpec::Kind::FloatByStop, 0.0, l.number};
      return;
    }
    if (k == "OBNA") {
      // OBNA value type: type 0 object-space NA, 1 object cone angle (degrees).
      const double v = number(l, 0, "the object-space NA or cone angle");
      const long long type = l.args.size() > 1 ? integer(l, 1, "the type (0 object-space NA, 1 object cone angle)", 0, 1) : 0;
      aperture_ = ApertureLine{type == 0 ? ApertureSpec::Kind::ObjectSpaceNA : ApertureSpec::Kind::ObjectConeAngleDeg, v, l.number};
      return;
    }
    if (k == "FTYP") return handle_ftyp(l);
    if (k == "XFLN" || k == "XFLD") {
      x_fields_ = all_numbers(l, "a field value");
      field_line_ = l.number;
      return;
    }
    if (k == "YFLN" || k == "YFLD") {
      y_fields_ = all_numbers(l, "a field value");
      field_line_ = l.number;
      return;
    }
    if (k == "VDXN" || k == "VDYN" || k == "VCXN" || k == "VCYN" || k == "VANN") {
      // Vignetting factors, one per field slot as XFLN/YFLN list them (older files: VDXF ... are unknown).
      vignetting_[std::string(k)] = all_numbers(l, "a vignetting factor");
      vignetting_line_ = l.number;
      return;
    }
    if (k == "WAVM") {
      const long long slot = integer(l, 0, "the wavelength number", 1, kMaxWavelengthSlot);
      const double um = number(l, 1, "the wavelength (micrometres)");
      wavm_[static_cast<int>(slot)] = Located{um, l.number, l.args[1].column};
      return;
    }
    if (k == "WAVL") {
      for (const Located& w : all_numbers(l, "a wavelength (micrometres)")) {
        if (wavl_.size() >= static_cast<std::size_t>(kMaxWavelengthSlot)) {
          fail(l.number, w.column, "WAVL: more than " + std::to_string(kMaxWavelengthSlot) + " wavelengths");
        }
        wavl_.push_back(w);
      }
      return;
    }
    if (k == "PWAV") {
      primary_ = Located{static_cast<double>(integer(l, 0, "the primary wavelength number", 1, kMaxWavelengthSlot)),
                         l.number, l.args[0].column};
      return;
    }
    if (k == "ENVD") return handle_envd(l);
    if (k == "MNUM") {
      if (!l.args.empty()) {
        auto n = parse_integer(l.args[0].text);
        if (n && *n > 1) {
          warn(l.number, "the file has " + std::to_string(*n) +
                             " configurations; the surface data as stored (the active configuration) is read");
        }
      }
      return;
    }
    if (k == "SCBD") return handle_scbd(l);
    if (contains(kRefusedApertureKeywords, k)) {
      fail(l.number, l.keyword.column,
           std::string(k) + ": spiders and user-defined apertures are not supported (circular, annular, rectangular and "
                           "elliptical apertures and obscurations are)");
    }
    if (contains(kZeroOnlyKeywords, k)) {
      // XDAT/YDAT are "index value ...": only the value matters. The others are values throughout.
      std::size_t first = 0;
      std::size_t last = l.args.size();
      if (k == "XDAT" && !surfaces_.empty() && surfaces_.back().type == "TOROIDAL") {
        // XDAT 1: the number of Zernike terms, 2: their normalisation radius, 3...: the terms.
        ZmxSurface& s = surfaces_.back();
        s.xdat.push_back(ParmRecord{integer(l, 0, "the extra-data number", 0, 1000), number(l, 1, "the extra-data value"), l.number,
                                    l.args.size() > 1 ? l.args[1].column : 0});
        return;
      }
      if (k == "XDAT" || k == "YDAT") {
        first = 1;
        last = std::min<std::size_t>(2, last);
      }
      for (std::size_t i = first; i < last; ++i) {
        auto v = parse_finite_number(l.args[i].text);
        if (v && *v != 0.0) {
          fail_at(l, l.args[i],
                  "decentres, tilts and extra surface data are not supported (value " + shown_text(l.args[i].text) + ")");
        }
      }
      return;
    }
    if (contains(kIgnoredKeywords, k)) return;
    record_unknown(l);
  }

  void handle_surf(const ZmxLine& l) {
    const long long n = integer(l, 0, "the surface number", 0, kMaxSurfaceNumber);
    if (n != static_cast<long long>(surfaces_.size())) {
      fail_at(l, l.args[0],
              "surface " + std::to_string(n) + " out of order: expected SURF " + std::to_string(surfaces_.size()) +
                  " (surfaces are numbered 0, 1, 2, ... in order)");
    }
    ZmxSurface s;
    s.number = static_cast<int>(n);
    s.line = l.number;
    surfaces_.push_back(std::move(s));
  }

  void handle_type(const ZmxLine& l) {
    ZmxSurface& s = current_surface(l);
    const Token& t = required_arg(l, 0, "the surface type");
    if (t.text != "STANDARD" && t.text != "EVENASPH" && t.text != "COORDBRK" && t.text != "TOROIDAL" && t.text != "BICONICX") {
      std::string why = "STANDARD, EVENASPH, TOROIDAL, BICONICX and COORDBRK surfaces are read";
      if (t.text == "QED_TYPE") why = "Forbes Q-type aspheres are not supported yet; " + why;
      fail_at(l, t,
              "surface type " + shown_text(t.text) + " on SURF " + std::to_string(s.number) + " is not supported: " + why);
    }
    s.type = std::string(t.text);
  }

  void handle_disz(const ZmxLine& l) {
    ZmxSurface& s = current_surface(l);
    const Token& t = required_arg(l, 0, "the thickness");
    s.disz_line = l.number;
    s.disz_column = t.column;
    if (to_upper_ascii(t.text) == "INFINITY") {
      s.disz.reset();
      s.disz_infinite = true;
      return;
    }
    s.disz = number(l, 0, "the thickness");
    s.disz_infinite = false;
  }

  void handle_glas(const ZmxLine& l) {
    ZmxSurface& s = current_surface(l);
    const Token& t = required_arg(l, 0, "the glass name");
    if (to_upper_ascii(t.text) == "MIRROR") {
      s.mirror = true;
      s.glass.reset();
      return;
    }
    GlassRef g;
    g.name = std::string(t.text);
    g.line = l.number;
    g.column = t.column;
    // GLAS NAME solve pickup nd Vd dPgF ...: the nd/Vd fields are optional and are read leniently
    // because OpticStudio also writes them for catalogue glasses, where they mean nothing.
    if (l.args.size() > 3) g.nd = parse_finite_number(l.args[3].text);
    if (l.args.size() > 4) g.vd = parse_finite_number(l.args[4].text);
    if (l.args.size() > 5) g.dpgf = parse_finite_number(l.args[5].text).value_or(0.0);
    s.glass = std::move(g);
  }

  // SCBD flag order dx dy tx ty tz ...: OpticStudio's surface tilt and decentre. Flag 1 is the coordinate
  // change before the surface, which is a coordinate break before it; other flags (the change after the
  // surface) are refused unless every value is zero.
  void handle_scbd(const ZmxLine& l) {
    ZmxSurface& s = current_surface(l);
    const long long flag = integer(l, 0, "the tilt/decentre flag", 0, 1000);
    std::array<double, 5> v{};
    bool any = false;
    for (std::size_t i = 0; i < v.size(); ++i) {
      v[i] = l.args.size() > i + 3 ? number(l, i + 3, "a decentre or tilt value") : 0.0;
      any = any || v[i] != 0.0;
    }
    for (std::size_t i = 8; i < l.args.size(); ++i) {
      if (number(l, i, "a tilt/decentre value") != 0.0) any = true;
    }
    if (!any) return;
    if (flag != 1) {
      fail(l.number, l.keyword.column,
           "SCBD: a tilt or decentre after SURF " + std::to_string(s.number) +
               " is not supported (give it as a coordinate break surface after it)");
    }
    CoordinateBreak b;
    b.tilt_first = l.args.size() > 1 && number(l, 1, "the order flag") != 0.0;
    b.decenter_x_mm = v[0];
    b.decenter_y_mm = v[1];
    b.tilt_x_deg = v[2];
    b.tilt_y_deg = v[3];
    b.tilt_z_deg = v[4];
    s.break_before = b;
    s.break_line = l.number;
  }

  // CLAP/OBSC min max (circular aperture / obscuration, radii), SQAP/OBSQ x y (rectangular, half
  // widths), ELAP/ELOB x y (elliptical, half widths), in lens units. SQOB is an old name of OBSQ.
  void handle_aperture(const ZmxLine& l) {
    ZmxSurface& s = current_surface(l);
    const std::string_view k = l.keyword.text;
    if (s.aperture) {
      fail(l.number, l.keyword.column,
           std::string(k) + ": a second aperture on SURF " + std::to_string(s.number) + " (the first, " + s.aperture_keyword +
               ", is on line " + std::to_string(s.aperture_line) + ")");
    }
    SurfaceAperture a;
    if (k == "CLAP" || k == "OBSC") {
      const double min_radius = number(l, 0, "the minimum radius");
      const double max_radius = number(l, 1, "the maximum radius");
      if (!(max_radius > 0.0)) fail_at(l, l.args[1], "maximum radius = " + format_number(max_radius) + ": must be > 0");
      if (!(min_radius >= 0.0 && min_radius < max_radius)) {
        fail_at(l, l.args[0], "minimum radius = " + format_number(min_radius) + ": must lie in [0, maximum radius)");
      }
      if (k == "OBSC" && min_radius > 0.0) {
        fail_at(l, l.args[0], "annular obscurations (minimum radius " + format_number(min_radius) + ") are not supported");
      }
      a.shape = SurfaceAperture::Shape::Circular;
      a.half_x_mm = a.half_y_mm = mm(max_radius);
      a.min_radius_mm = mm(min_radius);
      a.obscuration = k == "OBSC";
    } else {
      const double half_x = number(l, 0, "the x half width");
      const double half_y = number(l, 1, "the y half width");
      if (!(half_x > 0.0)) fail_at(l, l.args[0], "x half width = " + format_number(half_x) + ": must be > 0");
      if (!(half_y > 0.0)) fail_at(l, l.args[1], "y half width = " + format_number(half_y) + ": must be > 0");
      a.shape = k == "SQAP" || k == "OBSQ" || k == "SQOB" ? SurfaceAperture::Shape::Rectangular : SurfaceAperture::Shape::Elliptical;
      a.half_x_mm = mm(half_x);
      a.half_y_mm = mm(half_y);
      a.obscuration = k == "OBSQ" || k == "SQOB" || k == "ELOB";
    }
    s.aperture = a;
    s.aperture_line = l.number;
    s.aperture_keyword = std::string(k);
  }

  // RAIM <?> type ...: the second field is OpticStudio's ray aiming (0 off, 1 paraxial, 2 real).
  void handle_raim(const ZmxLine& l) {
    if (l.args.size() < 2) return;  // an old or partial line: ray aiming off
    const long long type = integer(l, 1, "the ray aiming type", 0, 2);
    if (type == 0) {
      ray_aiming_ = RayAiming::ParaxialEntrancePupil;
      return;
    }
    ray_aiming_ = RayAiming::RealStop;
    raim_line_ = l.number;
    if (type == 1) {
      note(l.number, "paraxial ray aiming (RAIM type 1) is read as real ray aiming: lensmith aims every ray onto the real "
                     "stop, which OpticStudio's paraxial aiming approximates");
    }
  }

  void handle_unit(const ZmxLine& l) {
    const Token& t = required_arg(l, 0, "the lens unit");
    const std::string u = to_upper_ascii(t.text);
    if (u == "MM") {
      mm_per_unit_ = 1.0;
    } else if (u == "CM") {
      mm_per_unit_ = mm_from_cm(1.0);
    } else if (u == "IN" || u == "INCH" || u == "INCHES") {
      mm_per_unit_ = mm_from_inch(1.0);
    } else if (u == "METER" || u == "METERS" || u == "M") {
      mm_per_unit_ = mm_from_m(1.0);
    } else {
      fail_at(l, t, "unknown lens unit \"" + shown_text(t.text) + "\" (expected MM, CM, IN or METER)");
    }
  }

  void handle_note(const ZmxLine& l) {
    // "NOTE 0 text" continues the note (OpticStudio splits long lines mid-word, so pieces join
    // without a separator); "NOTE <other>" ends a line of the note.
    std::string_view rest = l.rest;
    std::size_t digits = 0;
    while (digits < rest.size() && rest[digits] >= '0' && rest[digits] <= '9') ++digits;
    const std::string_view kind = rest.substr(0, digits);
    std::string_view text = rest.substr(digits);
    if (!text.empty() && text.front() == ' ') text.remove_prefix(1);
    while (!text.empty() && is_blank(text.back())) text.remove_suffix(1);
    if (kind == "0") {
      notes_ += text;
    } else {
      notes_ += '\n';
    }
  }

  void handle_gcat(const ZmxLine& l) {
    // Vendor catalogue names may carry a date suffix ("SUMITA_AUG2011"); other catalogues
    // (MISC, INFRARED, user catalogues) are not in lensmith and are skipped.
    for (const Token& t : l.args) {
      const std::string token = to_upper_ascii(t.text);
      for (const std::string& vendor : catalogue_.vendors()) {
        if (token == vendor || (token.size() > vendor.size() && token.compare(0, vendor.size(), vendor) == 0 &&
                                token[vendor.size()] == '_')) {
          if (std::find(vendor_order_.begin(), vendor_order_.end(), vendor) == vendor_order_.end()) {
            vendor_order_.push_back(vendor);
          }
        }
      }
    }
  }

  void handle_ftyp(const ZmxLine& l) {
    // FTYP type telecentric field-count wavelength-count ... afocal ...
    const long long type = integer(l, 0, "the field type", 0, 1000);
    if (type == 4) fail_at(l, l.args[0], "theodolite angle fields (type 4) are not supported");
    if (type > 4) fail_at(l, l.args[0], "field type " + std::to_string(type) + " is not supported");
    FieldTypeLine f;
    f.telecentric = l.args.size() > 1 && integer(l, 1, "the object-space telecentric flag (0 or 1)", 0, 1) != 0;
    f.type = type;
    f.field_count = l.args.size() > 2 ? integer(l, 2, "the number of fields", 0, kMaxFieldCount) : -1;
    f.wavelength_count = l.args.size() > 3 ? integer(l, 3, "the number of wavelengths", 0, kMaxWavelengthSlot) : -1;
    if (l.args.size() > 6 && integer(l, 6, "the afocal image space flag", 0, 1000) != 0) {
      fail_at(l, l.args[6], "afocal image space is not supported");
    }
    f.line = l.number;
    field_type_ = f;
  }

  void handle_envd(const ZmxLine& l) {
    // Catalogue indices are relative to air at 20 C and 1 atm; another environment would shift them.
    const double temperature_c = number(l, 0, "the temperature (C)");
    const double pressure_atm = l.args.size() > 1 ? number(l, 1, "the pressure (atm)") : 1.0;
    if (temperature_c != 20.0 || pressure_atm != 1.0) {
      warn(l.number, "environment " + format_number(temperature_c) + " C, " + format_number(pressure_atm) +
                         " atm ignored: indices are computed at 20 C and 1 atm");
    }
  }

  void record_unknown(const ZmxLine& l) { unknown_.record(l.keyword.text, l.number); }

  // ---- building the prescription ----------------------------------------------------------------

  double mm(double lens_units) const { return lens_units * mm_per_unit_; }

  MaterialSpec material_for(const GlassRef& g) {
    const std::string upper = to_upper_ascii(g.name);
    if (upper == "___BLANK") {
      // A model glass: nd and Vd are the glass (Vd 0 = no dispersion, as in OpticStudio).
      if (!g.nd || *g.nd < 1.0 || *g.nd > kMaxPlausibleIndex) {
        fail(g.line, g.column,
             "GLAS ___BLANK: a model glass needs an nd between 1 and 5 (GLAS ___BLANK solve pickup nd Vd ...)");
      }
      if (g.vd && *g.vd < 0.0) fail(g.line, g.column, "GLAS ___BLANK: Vd = " + format_number(*g.vd) + ": must be >= 0");
      if (g.dpgf != 0.0) note(g.line, "model glass dPgF = " + format_number(g.dpgf) + " ignored");
      return MaterialSpec::model(*g.nd, g.vd && *g.vd > 0.0 ? g.vd : std::nullopt);
    }
    if (upper == "AIR") return MaterialSpec::air();
    if (const Glass* found = catalogue_.find(g.name, {}, vendor_order_)) {
      if (!vendor_order_.empty() && std::find(vendor_order_.begin(), vendor_order_.end(), found->vendor()) == vendor_order_.end()) {
        // OpticStudio would look in the GCAT catalogues only; say what was taken instead.
        std::string listed;
        for (const std::string& v : vendor_order_) listed += (listed.empty() ? "" : ", ") + v;
        warn(g.line, "glass \"" + g.name + "\" is in none of the file's GCAT catalogues (" + listed + "); using " + found->vendor() +
                         "'s " + found->name() + " (nd " + format_rounded(found->nd(), 6) + ", Vd " + format_rounded(found->vd(), 4) + ")");
      }
      return MaterialSpec::catalog(found->name(), found->vendor());
    }
    if (const Glass* next = catalogue_.successor(g.name)) {
      warn(g.line, "glass \"" + g.name + "\" is an obsolete name in no catalogue; using its successor " + next->vendor() + " " +
                       next->name() + " (nd " + format_rounded(next->nd(), 6) + ", Vd " + format_rounded(next->vd(), 4) +
                       "), the same glass type made lead-free, whose index differs slightly from the original's");
      return MaterialSpec::catalog(next->name(), next->vendor());
    }
    // A moulded-lens vendor's name for a moulding glass ("L-TIM28_MOLD" in RPO's catalogue): the glass
    // itself, whose index a moulding lowers by the mould house's annealing (typically 1e-3 to 3e-3 in nd).
    constexpr std::string_view kMouldSuffix = "_MOLD";
    if (upper.size() > kMouldSuffix.size() && upper.ends_with(kMouldSuffix)) {
      const std::string base = g.name.substr(0, g.name.size() - kMouldSuffix.size());
      if (const Glass* found = catalogue_.find(base, {}, vendor_order_)) {
        warn(g.line, "glass \"" + g.name + "\" is a moulded variant of " + found->vendor() + " " + found->name() +
                         " (nd " + format_rounded(found->nd(), 6) + "), used here; the moulded lens's index is lower by its "
                         "moulding's index drop (typically 0.001 to 0.003), which lensmith does not know");
        return MaterialSpec::catalog(found->name(), found->vendor());
      }
    }
    const bool placeholder = g.nd && g.vd && *g.nd == kPlaceholderNd && *g.vd == kPlaceholderVd;
    const bool usable_nd = g.nd && *g.nd >= 1.0 && *g.nd <= kMaxPlausibleIndex && !placeholder;
    if (usable_nd && (!g.vd || *g.vd >= 0.0)) {
      const std::optional<double> vd = g.vd && *g.vd > 0.0 ? g.vd : std::nullopt;
      warn(g.line, "glass \"" + g.name + "\" is in no catalogue; using a model glass nd=" + format_number(*g.nd) +
                       (vd ? " Vd=" + format_number(*vd) : std::string(" without dispersion")) + " from its GLAS line" +
                       (vd ? " (Cauchy from nd and Vd: " + model_glass_accuracy(*vd) + " in index)" : std::string()));
      return MaterialSpec::model(*g.nd, vd);
    }
    std::string names;
    for (const std::string& n : catalogue_.closest_names(g.name)) names += (names.empty() ? "" : ", ") + n;
    std::string why = placeholder ? "its GLAS line carries only OpticStudio's placeholder nd 1.5 / Vd 40"
                                  : "its GLAS line gives no usable nd/Vd to fall back on";
    fail(g.line, g.column,
         "GLAS: unknown glass \"" + shown_text(g.name, 64) + "\": in no catalogue and " + why +
             "; closest catalogue names: " + (names.empty() ? "(none)" : names));
  }

  // The line a GlassError or PrescriptionError is about, from its subject.
  int line_for_subject(const ErrorSubject& subject) const {
    const int n = subject.surface;
    if (n >= 1 && n < static_cast<int>(surfaces_.size())) return surfaces_[static_cast<std::size_t>(n)].line;
    const std::string_view field = subject.field;
    if (field == "wavelengths_nm" && subject.index >= 0 && subject.index < static_cast<int>(wavelength_sources_.size())) {
      return wavelength_sources_[static_cast<std::size_t>(subject.index)].line;
    }
    if (field.starts_with("primary") && primary_) return primary_->line;
    if (field.starts_with("aperture") && aperture_) return aperture_->line;
    if (field.starts_with("object_space_telecentric") && field_type_) return field_type_->line;
    if (field.starts_with("field") && field_type_) return field_type_->line;
    if (field.starts_with("object")) return surfaces_.front().disz_line;
    return 0;
  }

  LensReadResult build() {
    if (surfaces_.empty()) {
      fail(last_line_, 0, "no SURF lines: not a Zemax sequential lens file, or the file is truncated");
    }
    if (surfaces_.size() < 3) {
      fail(surfaces_.back().line, 0,
           "a lens needs an object surface (SURF 0), at least one lens surface and an image surface; found " +
               std::to_string(surfaces_.size()) + " SURF blocks");
    }
    for (const ZmxSurface& s : surfaces_) {
      // OpticStudio writes DISZ for every surface, the image included: a missing one means a
      // truncated or hand-damaged file, never a default of zero.
      if (!s.disz && !s.disz_infinite) {
        fail(s.line, 0, "SURF " + std::to_string(s.number) + " has no DISZ (thickness) line; is the file truncated?");
      }
    }
    LensReadResult result;
    Prescription& p = result.prescription;
    p.name = name_.empty() ? lens_name_from_path(file_) : name_;  // OpticStudio often leaves NAME blank
    p.notes = std::string(trim_lines(notes_));

    const ZmxSurface& object = surfaces_.front();
    if (object.stop) fail(object.stop_line, 0, "STOP on the object surface (SURF 0)");
    if (object.break_before) fail(object.break_line, 0, "SCBD: a tilted or decentred object surface (SURF 0) is not supported");
    if (object.type == "COORDBRK" || object.mirror) fail(object.line, 0, "the object surface (SURF 0) must be a plain surface");
    if (object.disz_infinite) {
      p.object_distance_mm = kInfinity;
    } else {
      if (*object.disz <= 0.0) {
        fail(object.disz_line, object.disz_column,
             "DISZ: object distance = " + format_number(*object.disz) +
                 ": must be > 0 or INFINITY (virtual objects are not supported)");
      }
      p.object_distance_mm = mm(*object.disz);
    }
    if (object.glass) p.object_material = material_for(*object.glass);

    const ZmxSurface& image = surfaces_.back();
    if (image.stop) fail(image.stop_line, 0, "STOP on the image surface (SURF " + std::to_string(image.number) + ")");
    if (image.curvature != 0.0) {
      warn(image.curv_line, "the image surface is curved (CURV " + format_number(image.curvature) +
                                "); lensmith models a plane image surface");
    }

    for (std::size_t k = 1; k < surfaces_.size(); ++k) {
      const ZmxSurface& z = surfaces_[k];
      if (z.break_before) {
        // A surface tilt/decentre before the surface: a coordinate break of zero thickness in front of it.
        Surface b;
        b.kind = SurfaceKind::CoordinateBreak;
        b.coordinate_break = *z.break_before;
        b.coordinate_break.decenter_x_mm = mm(b.coordinate_break.decenter_x_mm);
        b.coordinate_break.decenter_y_mm = mm(b.coordinate_break.decenter_y_mm);
        b.comment = "SCBD before SURF " + std::to_string(z.number);
        if (p.surfaces.empty()) {
          fail(z.break_line, 0, "SCBD: a tilt or decentre before the first lens surface is not supported");
        }
        // Thickness 0: the surface (or the image plane, before the image surface) sits at the break.
        p.surfaces.push_back(b);
        note(z.break_line, "SCBD: the tilt and decentre before SURF " + std::to_string(z.number) + " read as a coordinate break");
      }
      if (k + 1 < surfaces_.size()) p.surfaces.push_back(make_surface(z));
    }
    if (image.mirror) fail(image.line, 0, "the image surface (SURF " + std::to_string(image.number) + ") is a mirror");

    set_aperture(p);
    set_field(p);
    set_wavelengths(p);
    p.ray_aiming = ray_aiming_;
    if (ray_aiming_ == RayAiming::RealStop) {
      if (const auto why = p.why_no_real_ray_aiming()) {
        note(raim_line_, "real ray aiming (RAIM) is implemented for rotationally symmetric refracting lenses, not for this one (" +
                             *why + "), so rays are aimed at the paraxial entrance pupil (OpticStudio's \"ray aiming off\")");
        p.ray_aiming = RayAiming::ParaxialEntrancePupil;
      }
    }
    if (field_type_ && field_type_->telecentric) {
      p.object_space_telecentric = true;
      if (ray_aiming_ == RayAiming::RealStop) {
        note(field_type_->line, "object-space telecentric: rays are aimed by their object-space direction (the entrance "
                                "pupil is at infinity), not onto the real stop");
        p.ray_aiming = RayAiming::ParaxialEntrancePupil;
      }
    }

    resolve_and_validate(p, catalogue_, file_, [this](const ErrorSubject& e) { return line_for_subject(e); });
    unknown_.report(diagnostics_, file_, "lines");
    result.diagnostics = std::move(diagnostics_);
    return result;
  }

  Surface make_surface(const ZmxSurface& z) {
    Surface s;
    if (z.type == "COORDBRK") return make_coordinate_break(z);
    s.mirror = z.mirror;
    s.curvature_per_mm = z.curvature / mm_per_unit_;
    if (z.disz_infinite) {
      fail(z.disz_line, z.disz_column,
           "DISZ INFINITY on lens surface SURF " + std::to_string(z.number) + " (afocal systems are not supported)");
    }
    s.thickness_mm = mm(*z.disz);
    if (z.glass) s.material = material_for(*z.glass);
    // Clipping follows the file, as OpticStudio's sequential ray trace does: a DIAM semi-diameter
    // sizes the surface but stops no ray unless a floating aperture (FLAP) makes it a clear aperture;
    // explicit apertures (CLAP, SQAP, ELAP, OBSC, OBSQ, ELOB, decentred by OBDC) clip.
    if (z.diam && *z.diam > 0.0) {
      s.semi_diameter_mm = mm(*z.diam);  // DIAM 0 means "not computed": no size
      s.clips_rays = z.floating_aperture;
    }
    if (z.aperture) {
      SurfaceAperture a = *z.aperture;
      if (z.aperture_decenter) {
        a.decenter_x_mm = mm((*z.aperture_decenter)[0]);
        a.decenter_y_mm = mm((*z.aperture_decenter)[1]);
      }
      const bool plain_circle = a.shape == SurfaceAperture::Shape::Circular && !a.obscuration && a.min_radius_mm == 0.0 &&
                                a.decenter_x_mm == 0.0 && a.decenter_y_mm == 0.0;
      if (plain_circle) {
        // A centred circular aperture is the clear semi-diameter itself.
        s.semi_diameter_mm = a.half_x_mm;
        s.clips_rays = true;
      } else {
        s.aperture = a;
        if (!s.semi_diameter_mm && !a.obscuration) {
          s.semi_diameter_mm = a.outer_radius_mm();  // the surface's size when the file gives no DIAM
          s.clips_rays = false;
        }
        if (s.semi_diameter_mm && !a.obscuration && a.outer_radius_mm() > *s.semi_diameter_mm) {
          // Everything the aperture passes must lie on the surface as drawn.
          s.semi_diameter_mm = std::min(a.outer_radius_mm(), s.max_semi_diameter_mm());
        }
      }
    } else if (z.aperture_decenter && ((*z.aperture_decenter)[0] != 0.0 || (*z.aperture_decenter)[1] != 0.0)) {
      warn(z.decenter_line, "OBDC: an aperture decentre on SURF " + std::to_string(z.number) + ", which has no explicit aperture: ignored");
    }
    s.is_stop = z.stop;
    s.conic = z.conic;
    if (z.type == "TOROIDAL" || z.type == "BICONICX") {
      set_toroidal_or_biconic(z, s);
      s.comment = z.comment;
      return s;
    }
    for (const ParmRecord& parm : z.parms) {
      if (parm.value == 0.0) continue;
      if (z.type != "EVENASPH") {
        fail(parm.line, parm.column,
             "PARM " + std::to_string(parm.index) + " = " + format_number(parm.value) +
                 " on a STANDARD surface (SURF " + std::to_string(z.number) +
                 "): surface parameters need TYPE EVENASPH");
      }
      if (parm.index < 1 || parm.index > static_cast<long long>(s.even_asphere.size())) {
        fail(parm.line, parm.column,
             "PARM " + std::to_string(parm.index) +
                 " is not an even-asphere coefficient (PARM 1..8 hold the r^2..r^16 terms)");
      }
      // PARM j is the r^(2j) coefficient, in lens-unit^(1 - 2j).
      const auto j = static_cast<int>(parm.index);
      s.even_asphere[static_cast<std::size_t>(j - 1)] = parm.value * std::pow(mm_per_unit_, 1 - 2 * j);
    }
    s.comment = z.comment;
    return s;
  }

  // COORDBRK: PARM 1, 2 decentre x, y (lens units); PARM 3, 4, 5 tilt about x, y, z (degrees); PARM 6 the
  // order (0 decentre then tilt, else tilt then decentre). No shape, glass or stop.
  Surface make_coordinate_break(const ZmxSurface& z) {
    Surface s;
    s.kind = SurfaceKind::CoordinateBreak;
    if (z.glass || z.mirror) fail(z.line, 0, "SURF " + std::to_string(z.number) + ": a coordinate break (COORDBRK) has no glass or mirror");
    if (z.stop) fail(z.stop_line, 0, "STOP on a coordinate break (SURF " + std::to_string(z.number) + ")");
    if (z.disz_infinite) fail(z.disz_line, z.disz_column, "DISZ INFINITY on SURF " + std::to_string(z.number));
    s.thickness_mm = mm(*z.disz);
    for (const ParmRecord& parm : z.parms) {
      CoordinateBreak& b = s.coordinate_break;
      switch (parm.index) {
        case 1: b.decenter_x_mm = mm(parm.value); break;
        case 2: b.decenter_y_mm = mm(parm.value); break;
        case 3: b.tilt_x_deg = parm.value; break;
        case 4: b.tilt_y_deg = parm.value; break;
        case 5: b.tilt_z_deg = parm.value; break;
        case 6: b.tilt_first = parm.value != 0.0; break;
        default:
          if (parm.value != 0.0) {
            fail(parm.line, parm.column, "PARM " + std::to_string(parm.index) + " of a coordinate break (SURF " + std::to_string(z.number) +
                                             "): only PARM 1-6 (decentres, tilts, order) exist");
          }
      }
    }
    s.comment = z.comment;
    return s;
  }

  // TOROIDAL: PARM 1 the radius of rotation (0: infinite, a cylinder), PARM 2..8 the y^2 ... y^14 terms;
  // XDAT 1 the number of Zernike terms (must be 0). BICONICX: PARM 1 the x radius (0: flat), PARM 2 the x conic.
  void set_toroidal_or_biconic(const ZmxSurface& z, Surface& s) {
    const bool toroidal = z.type == "TOROIDAL";
    s.kind = toroidal ? SurfaceKind::Toroidal : SurfaceKind::Biconic;
    for (const ParmRecord& parm : z.parms) {
      if (parm.index == 1) {
        s.curvature_x_per_mm = parm.value == 0.0 ? 0.0 : 1.0 / mm(parm.value);
      } else if (!toroidal && parm.index == 2) {
        s.conic_x = parm.value;
      } else if (toroidal && parm.index >= 2 && parm.index <= 8) {
        // PARM j (j >= 2) is the y^(2 (j - 1)) coefficient, lens-unit^(1 - 2 (j - 1)).
        const auto power = static_cast<int>(parm.index) - 1;
        s.even_asphere[static_cast<std::size_t>(power - 1)] = parm.value * std::pow(mm_per_unit_, 1 - 2 * power);
      } else if (parm.value != 0.0) {
        fail(parm.line, parm.column,
             "PARM " + std::to_string(parm.index) + " = " + format_number(parm.value) + " on " + z.type + " SURF " + std::to_string(z.number) +
                 (toroidal ? ": a toroidal surface reads PARM 1 (radius of rotation) and PARM 2-8 (y^2 ... y^14 terms)"
                           : ": a biconic surface reads PARM 1 (x radius) and PARM 2 (x conic)"));
      }
    }
    for (const ParmRecord& x : z.xdat) {
      if (x.index == 2 || x.value == 0.0) continue;  // the normalisation radius of no Zernike terms
      fail(x.line, x.column, "XDAT " + std::to_string(x.index) + " on TOROIDAL SURF " + std::to_string(z.number) +
                                 ": Zernike terms on a toroidal surface are not supported");
    }
  }

  void set_aperture(Prescription& p) {
    if (!aperture_) {
      warn(0, "no aperture keyword (ENPD, FNUM or FLOA); the stop's semi-diameter sets the aperture");
      p.aperture = ApertureSpec{ApertureSpec::Kind::FloatByStop, 0.0};
      return;
    }
    double value = aperture_->value;
    if (aperture_->kind == ApertureSpec::Kind::EntrancePupilDiameter) value = mm(value);
    if (aperture_->kind != ApertureSpec::Kind::FloatByStop && !(value > 0.0)) {
      fail(aperture_->line, 0, "aperture value = " + format_number(aperture_->value) + ": must be > 0");
    }
    p.aperture = ApertureSpec{aperture_->kind, value};
  }

  void set_field(Prescription& p) {
    if (y_fields_.empty() && x_fields_.empty()) return;
    const long long type = field_type_ ? field_type_->type : 0;
    std::size_t count = std::max(x_fields_.size(), y_fields_.size());
    if (field_type_ && field_type_->field_count >= 0) {
      count = static_cast<std::size_t>(field_type_->field_count);
      if (count > y_fields_.size() || (!x_fields_.empty() && count > x_fields_.size())) {
        fail(field_type_->line, 0,
             "FTYP declares " + std::to_string(count) + " fields but XFLN/YFLN list fewer values");
      }
    }
    if (count == 0) return;
    if (count > static_cast<std::size_t>(kMaxFieldCount)) {
      fail(field_line_, 0, "more than " + std::to_string(kMaxFieldCount) + " field points");
    }
    FieldSpec field;
    field.kind = type == 0   ? FieldSpec::Kind::AngleDeg
                 : type == 1 ? FieldSpec::Kind::ObjectHeightMm
                 : type == 2 ? FieldSpec::Kind::ImageHeightMm
                             : FieldSpec::Kind::RealImageHeightMm;
    bool folded = false;
    const bool symmetric = p.is_rotationally_symmetric();
    for (std::size_t i = 0; i < count; ++i) {
      const double y = i < y_fields_.size() ? y_fields_[i].value : 0.0;
      const double x = i < x_fields_.size() ? x_fields_[i].value : 0.0;
      double radial = y;
      if (x != 0.0) {
        folded = true;
        if (symmetric) radial = radial_field_value(field.kind, x, y);  // what a rotationally symmetric lens sees
      }
      field.values.push_back(type == 0 ? radial : mm(radial));
    }
    if (folded && symmetric) {
      note(field_line_,
           "fields with an x component were folded into radial fields (the lens is rotationally symmetric)");
    } else if (folded) {
      warn(field_line_, "the fields' x components are not used (lensmith's field points lie along y; fields off the y-z plane "
                        "of a system that is not rotationally symmetric are not implemented): their y components are read");
    }
    // Vignetting factors of the fields in use, when any is not zero.
    auto factor = [&](const char* key, std::size_t i) {
      auto it = vignetting_.find(key);
      return it != vignetting_.end() && i < it->second.size() ? it->second[i].value : 0.0;
    };
    std::vector<VignettingFactors> vignetting(count);
    bool any = false;
    bool on_folded = false;
    for (std::size_t i = 0; i < count; ++i) {
      vignetting[i] = {factor("VDXN", i), factor("VDYN", i), factor("VCXN", i), factor("VCYN", i), factor("VANN", i)};
      if (vignetting[i].is_none()) continue;
      any = true;
      if (i < x_fields_.size() && x_fields_[i].value != 0.0) {
        on_folded = true;  // OpticStudio's factors are in that field's own x-y frame, not along +y
        vignetting[i] = {};
      }
      if (!(vignetting[i].vcx < 1.0 && vignetting[i].vcy < 1.0)) {
        fail(vignetting_line_, 0, "vignetting factors of field " + std::to_string(i + 1) + ": a compression VCX or VCY of 1 or more closes the pupil");
      }
    }
    if (on_folded) {
      warn(vignetting_line_, "vignetting factors of fields with an x component are not used (their pupils are sampled whole)");
    }
    if (any) {
      field.vignetting = std::move(vignetting);
      note(vignetting_line_, "vignetting factors read: real-ray analyses sample each field's vignetted pupil, as OpticStudio does");
    }
    p.field = std::move(field);
  }

  void set_wavelengths(Prescription& p) {
    std::vector<Located> micrometres;
    if (!wavm_.empty()) {
      long long count = field_type_ && field_type_->wavelength_count >= 0 ? field_type_->wavelength_count
                                                                          : static_cast<long long>(wavm_.size());
      for (int slot = 1; slot <= count; ++slot) {
        auto it = wavm_.find(slot);
        if (it == wavm_.end()) {
          fail(field_type_ ? field_type_->line : 0, 0,
               "wavelength " + std::to_string(slot) + " is in use but has no WAVM line");
        }
        micrometres.push_back(it->second);
      }
    } else if (!wavl_.empty()) {
      micrometres = wavl_;
      if (field_type_ && field_type_->wavelength_count >= 0) {
        if (static_cast<std::size_t>(field_type_->wavelength_count) > wavl_.size()) {
          fail(field_type_->line, 0,
               "FTYP declares " + std::to_string(field_type_->wavelength_count) + " wavelengths but WAVL lists " +
                   std::to_string(wavl_.size()));
        }
        micrometres.resize(static_cast<std::size_t>(field_type_->wavelength_count));
      }
    }
    if (micrometres.empty()) {
      note(0, "no wavelengths in the file; using F, d, C with d primary");
      return;
    }
    p.wavelengths_nm.clear();
    wavelength_sources_ = micrometres;
    for (const Located& w : micrometres) {
      if (!(w.value > 0.0)) fail(w.line, w.column, "wavelength = " + format_number(w.value) + " um: must be > 0");
      p.wavelengths_nm.push_back(nm_from_um_rounded(w.value));
    }
    p.primary_wavelength_index = 0;
    if (primary_) {
      const auto index = static_cast<std::size_t>(primary_->value);
      if (index > p.wavelengths_nm.size()) {
        fail(primary_->line, primary_->column,
             "PWAV " + std::to_string(index) + ": only " + std::to_string(p.wavelengths_nm.size()) +
                 " wavelengths are in use");
      }
      p.primary_wavelength_index = index - 1;
    }
  }

  const std::string& file_;
  const GlassCatalog& catalogue_;
  Diagnostics diagnostics_;
  int last_line_ = 0;

  std::vector<ZmxSurface> surfaces_;
  int stop_line_ = 0;
  double mm_per_unit_ = 1.0;
  std::string name_;
  std::string notes_;
  std::vector<std::string> vendor_order_;
  std::optional<ApertureLine> aperture_;
  std::optional<FieldTypeLine> field_type_;
  std::vector<Located> x_fields_;
  std::vector<Located> y_fields_;
  int field_line_ = 0;  // the last XFLN/YFLN line
  std::map<std::string, std::vector<Located>> vignetting_;  // VDXN, VDYN, VCXN, VCYN, VANN
  int vignetting_line_ = 0;
  RayAiming ray_aiming_ = RayAiming::ParaxialEntrancePupil;
  int raim_line_ = 0;
  std::map<int, Located> wavm_;
  std::vector<Located> wavl_;
  std::optional<Located> primary_;
  std::vector<Located> wavelength_sources_;  // the wavelengths in use, where the file gives them
  UnknownKeywords unknown_;
};

}  // namespace

LensReadResult read_zemax(std::string_view bytes, const std::string& file_name, const GlassCatalog& catalogue) {
  ZemaxParser parser(file_name, catalogue);
  return parser.parse(bytes);
}

}  // namespace lensmith
