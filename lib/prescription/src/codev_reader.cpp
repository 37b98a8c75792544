// Reader for CODE V sequential lens files (.seq). A .seq file is a list of CODE V commands: a keyword
// and blank-separated arguments. ';' separates commands on a line, '!' starts a comment, '&' at the
// end of a line continues the command on the next, '...' or "..." quote a string. CODE V matches a
// longer keyword by its first three letters (TITLE = TIT, STOP = STO). SO is the object surface, each
// S line one lens surface, SI the image surface; surface commands (RDY, THI, GLA, CIR, K, A, ...) act
// on the surface last entered, or on the one an S k / SO / SI qualifier names. Lengths are in the unit
// of DIM, wavelengths in nanometres. The keyword table (read, ignored, refused) is in
// docs/lens-formats-foreign.md, section "CODE V".
#include "lensmith/core/ascii_text.h"
#include "lensmith/prescription/codev_reader.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/text_file.h"
#include "lensmith/core/units.h"
#include "lensmith/glass/glass.h"

namespace lensmith {
namespace {

// Limits that keep hostile input from asking for unbounded work or memory; CODE V itself allows a
// few hundred surfaces, 25 fields and 21 wavelengths.
constexpr std::size_t kMaxSurfaces = 10000;
constexpr std::size_t kMaxWavelengths = 1000;
constexpr std::size_t kMaxFields = 1000;
constexpr std::size_t kMaxPrivateGlasses = 1000;
constexpr std::size_t kMaxShownLength = 32;

// CODE V treats a thickness of 1e10 lens units or more as infinite (its listings print INFINITY).
constexpr double kInfiniteThickness = 1.0e10;
// Indices outside this range are not optical glass.
constexpr double kMaxPlausibleIndex = 5.0;
// Digits a fictitious glass code may carry on either side of its point ("61272.58633" is 1.61272, 58.633).
constexpr std::size_t kMaxGlassCodeDigits = 20;

// Commands that change nothing lensmith models: solve and variable codes (the file holds the
// solved values), pickups (the picked-up values are written too), derivatives, weights, colours,
// drawing, mirror substrates, bookkeeping. Sorted for binary search.
// clang-format off
constexpr auto kIgnoredKeywords = std::to_array<std::string_view>({
    "AC", "BC", "CA", "CC", "CCX", "CCY", "CLS", "CUM", "CWL", "DC", "DER", "EC", "FC", "GC", "GLC", "HC",
    "INI", "JC", "KC", "PIK", "PIM", "POL", "PUI", "PUX", "PUY", "THC", "THM", "WID", "WTF", "WTW",
});
// Vignetting factors: CODE V shrinks its off-axis pupils by them; they become FieldSpec::vignetting (VRO: noted).
constexpr auto kVignettingKeywords = std::to_array<std::string_view>({"VLX", "VLY", "VRO", "VUX", "VUY"});
// Decentres and tilts: an error unless zero.
constexpr auto kDecentreKeywords = std::to_array<std::string_view>({"ADE", "BDE", "CDE", "XDE", "YDE", "ZDE"});
// clang-format on
static_assert(std::ranges::is_sorted(kIgnoredKeywords) && std::ranges::is_sorted(kVignettingKeywords) &&
              std::ranges::is_sorted(kDecentreKeywords));

// Commands that would change the optics in a way lensmith cannot represent, and why.
struct Refusal {
  std::string_view keyword;
  std::string_view why;
};
constexpr auto kRefusedKeywords = std::to_array<Refusal>({
    {"CUX", "x curvatures (toroidal and cylindrical surfaces) are not supported"},
    {"DEL", "editing commands that delete surfaces are not read; save the lens from CODE V and read that file"},
    {"DIF", "diffractive surfaces are not supported"},
    {"HCC", "diffractive (holographic) surfaces are not supported"},
    {"HCO", "diffractive (holographic) surfaces are not supported"},
    {"HCT", "diffractive (holographic) surfaces are not supported"},
    {"HOE", "holographic surfaces are not supported"},
    {"HOR", "diffractive (holographic) surfaces are not supported"},
    {"HWL", "diffractive (holographic) surfaces are not supported"},
    {"INS", "editing commands that insert surfaces are not read; save the lens from CODE V and read that file"},
    {"NA", "image-space NA apertures are not supported (use EPD or FNO)"},
    {"RDX", "x radii (toroidal and cylindrical surfaces) are not supported"},
    {"RET", "returning to another surface's coordinate system (RET) is not supported (rotationally symmetric systems only)"},
    {"SPS", "special surface types are not supported (only SPH, CON and ASP surfaces are read)"},
    {"UDS", "user-defined surfaces are not supported"},
    {"XRI", "real image height fields are not supported (use YIM, paraxial image height)"},
    {"XTO", "toroidal surfaces are not supported"},
    {"YRI", "real image height fields are not supported (use YIM, paraxial image height)"},
    {"YTO", "toroidal surfaces are not supported"},
    {"ZOO", "zoom lenses are not supported: save one zoom position from CODE V and read that file"},
});

template <std::size_t N>
bool contains(const std::array<std::string_view, N>& sorted, std::string_view key) {
  return std::binary_search(sorted.begin(), sorted.end(), key);
}

bool is_digit(char c) { return c >= '0' && c <= '9'; }
bool is_letter(char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z'); }
bool is_quote(char c) { return c == '\'' || c == '"'; }

std::string shown(std::string_view s, std::size_t max_length = kMaxShownLength) { return shown_text(s, max_length); }

// A glass name as CODE V writes Schott's, Ohara's and CDGM's (N-BK7 as NBK7, S-LAL8 as SLAL8):
// upper case without '-' and blanks.
std::string normalised_glass_name(std::string_view name) {
  std::string out;
  for (char c : to_upper_ascii(name)) {
    if (c != '-' && c != ' ') out += c;
  }
  return out;
}

struct Token {
  std::string text;  // a wholly quoted token without its quotes
  int line = 0;
  int column = 0;    // 1-based byte column
  bool quoted = false;
};

// One command: keyword, arguments and where it ends (for "missing argument" errors).
struct Command {
  Token keyword;
  std::string name;  // upper case, a longer alphabetic keyword cut to its first three letters; empty when quoted
  std::vector<Token> args;
  int end_line = 0;
  int end_column = 0;
};

struct Located {
  double value = 0.0;
  int line = 0;
  int column = 0;
};

struct GlassRef {
  std::string name;
  bool quoted = false;
  int line = 0;
  int column = 0;
};

// One aperture as entered (lens units): CIR (circle), REX/REY (rectangle), ELX/ELY (ellipse), with
// ADX/ADY decentres and an ARO rotation.
struct ApertureInput {
  std::optional<SurfaceAperture::Shape> shape;
  std::optional<double> half_x;  // CIR: the radius
  std::optional<double> half_y;
  double decenter_x = 0.0;
  double decenter_y = 0.0;
  double rotation_deg = 0.0;
  int line = 0;  // the first command that set it
  int rotation_line = 0;
};

// CODE V's apertures on one surface: the clear aperture, an obscuration (OBS) and the edge (EDG).
enum ApertureRole { kClear = 0, kObscuration = 1, kEdge = 2 };

// One surface (SO, S or SI) as entered, in lens units.
struct CvSurface {
  int line = 0;
  double curvature = 0.0;  // 1 / lens unit
  int curvature_line = 0;
  double thickness = 0.0;
  int thickness_line = 0;
  int thickness_column = 0;
  std::optional<GlassRef> glass;  // empty = air
  bool mirror = false;            // REFL (as the glass or the refract mode): the surface reflects
  int mirror_line = 0;
  double conic = 0.0;
  // A, B, ..., J (no I): the r^4, r^6, ..., r^20 coefficients, lens-unit^(1 - power).
  std::array<Located, 9> coefficients{};
  std::array<std::optional<ApertureInput>, 3> apertures;
  std::string label;
};

struct PrivateGlass {
  std::string name;
  int line = 0;
  std::vector<double> wavelengths_nm;
  std::vector<double> indices;
  std::string formula;  // a dispersion formula (LAU, ...) instead of indices: refused where the glass is used
};

class CodeVParser {
 public:
  CodeVParser(const std::string& file_name, const GlassCatalog& catalogue) : file_(file_name), catalogue_(catalogue) {}

  LensReadResult parse(std::string_view bytes) {
    lex(decode_text(bytes, file_));
    for (const Command& c : commands_) {
      if (after_go_) {
        note(c.keyword.line, "commands after GO are not read (" + shown(c.keyword.text) + " and on)");
        break;
      }
      handle(c);
    }
    return build();
  }

 private:
  // ---- errors ----------------------------------------------------------------------------------

  [[noreturn]] void fail(int line, int column, const std::string& message) const {
    throw FileError(SourceLocation{file_, line, column}, message);
  }
  [[noreturn]] void fail_at(const Command& c, const Token& t, const std::string& message) const {
    fail(t.line, t.column, shown(to_upper_ascii(c.keyword.text)) + ": " + message);
  }
  [[noreturn]] void fail_keyword(const Command& c, const std::string& message) const {
    fail_at(c, c.keyword, message);
  }
  void warn(int line, const std::string& message) {
    diagnostics_.push_back(Diagnostic{Diagnostic::Severity::Warning, SourceLocation{file_, line, 0}, message});
  }
  void note(int line, const std::string& message) {
    diagnostics_.push_back(Diagnostic{Diagnostic::Severity::Note, SourceLocation{file_, line, 0}, message});
  }

  // ---- text to commands --------------------------------------------------------------------------

  struct Position {
    int line = 0;
    int column = 0;
  };

  // Splits the text into logical lines (comments removed, '&' continuations joined), each into
  // commands at ';', each command into tokens.
  void lex(const std::string& text) {
    std::string chars;
    std::vector<Position> where;
    int line_number = 0;
    std::size_t pos = 0;
    while (pos <= text.size()) {
      std::size_t end = text.find('\n', pos);
      if (end == std::string::npos) end = text.size();
      const std::string_view line(text.data() + pos, end - pos);
      ++line_number;
      if (line.find('\0') != std::string_view::npos) {
        fail(line_number, static_cast<int>(line.find('\0')) + 1,
             "NUL byte in the text: not a CODE V .seq text file");
      }
      char quote = 0;
      Position quote_at;
      for (std::size_t i = 0; i < line.size(); ++i) {
        const char c = line[i];
        if (quote == 0 && c == '!') break;  // a comment to the end of the line
        if (quote != 0 && c == quote) {
          quote = 0;
        } else if (quote == 0 && is_quote(c)) {
          quote = c;
          quote_at = {line_number, static_cast<int>(i) + 1};
        }
        chars += c;
        where.push_back({line_number, static_cast<int>(i) + 1});
      }
      if (quote != 0) fail(quote_at.line, quote_at.column, std::string("unterminated quoted string (no closing ") + quote + ")");
      while (!chars.empty() && is_blank(chars.back())) {
        chars.pop_back();
        where.pop_back();
      }
      const bool continued = !chars.empty() && chars.back() == '&';
      if (continued) {
        chars.pop_back();
        where.pop_back();
      } else {
        split_commands(chars, where, Position{line_number, static_cast<int>(line.size()) + 1});
        chars.clear();
        where.clear();
      }
      if (end == text.size()) break;
      pos = end + 1;
    }
    last_line_ = line_number;
    if (!chars.empty()) split_commands(chars, where, Position{line_number, 0});
  }

  void split_commands(const std::string& chars, const std::vector<Position>& where, Position line_end) {
    std::size_t start = 0;
    char quote = 0;
    for (std::size_t i = 0; i <= chars.size(); ++i) {
      if (i < chars.size()) {
        const char c = chars[i];
        if (quote != 0) {
          if (c == quote) quote = 0;
          continue;
        }
        if (is_quote(c)) {
          quote = c;
          continue;
        }
        if (c != ';') continue;
      }
      const Position end = i < chars.size() ? where[i] : line_end;
      tokenize(chars, where, start, i, end);
      start = i + 1;
    }
  }

  void tokenize(const std::string& chars, const std::vector<Position>& where, std::size_t begin, std::size_t end,
                Position command_end) {
    std::vector<Token> tokens;
    std::size_t i = begin;
    while (i < end) {
      while (i < end && is_blank(chars[i])) ++i;
      if (i >= end) break;
      Token t;
      t.line = where[i].line;
      t.column = where[i].column;
      if (is_quote(chars[i])) {
        const char q = chars[i];
        std::size_t j = i + 1;
        while (j < end && chars[j] != q) ++j;
        t.text = chars.substr(i + 1, j - i - 1);
        t.quoted = true;
        i = std::min(j + 1, end);
      } else {
        const std::size_t start = i;
        while (i < end && !is_blank(chars[i])) {
          if (is_quote(chars[i])) {  // a quoted part inside a word: L'label'
            const char q = chars[i];
            ++i;
            while (i < end && chars[i] != q) ++i;
          }
          if (i < end) ++i;
        }
        t.text = chars.substr(start, i - start);
      }
      tokens.push_back(std::move(t));
    }
    if (tokens.empty()) return;
    Command c;
    c.keyword = std::move(tokens.front());
    c.args.assign(std::make_move_iterator(tokens.begin() + 1), std::make_move_iterator(tokens.end()));
    c.end_line = command_end.line;
    c.end_column = command_end.column;
    if (!c.keyword.quoted) {
      c.name = to_upper_ascii(c.keyword.text);
      if (c.name.size() > 3 && std::all_of(c.name.begin(), c.name.end(), is_letter)) c.name.resize(3);
    }
    commands_.push_back(std::move(c));
  }

  // ---- arguments ---------------------------------------------------------------------------------

  const Token& required_arg(const Command& c, std::size_t i, const std::string& what) const {
    if (i >= c.args.size()) fail(c.end_line, c.end_column, shown(to_upper_ascii(c.keyword.text)) + ": missing " + what);
    return c.args[i];
  }
  double number(const Command& c, std::size_t i, const std::string& what) const {
    const Token& t = required_arg(c, i, what);
    auto v = t.quoted ? std::nullopt : parse_finite_number(t.text);
    if (!v) fail_at(c, t, "expected a finite number for " + what + ", got \"" + shown(t.text) + "\"");
    return *v;
  }
  Located located_number(const Command& c, std::size_t i, const std::string& what) const {
    const double v = number(c, i, what);
    return Located{v, c.args[i].line, c.args[i].column};
  }
  // The arguments from `first` on, all numbers.
  std::vector<Located> numbers_from(const Command& c, std::size_t first, const std::string& what,
                                    std::size_t max_count) const {
    std::vector<Located> out;
    for (std::size_t i = first; i < c.args.size(); ++i) {
      if (out.size() >= max_count) {
        fail_at(c, c.args[i], "more than " + std::to_string(max_count) + " values");
      }
      out.push_back(located_number(c, i, what));
    }
    if (out.empty()) fail(c.end_line, c.end_column, shown(to_upper_ascii(c.keyword.text)) + ": missing " + what);
    return out;
  }
  void no_more_args(const Command& c, std::size_t used) const {
    if (c.args.size() > used) fail_at(c, c.args[used], "unexpected argument \"" + shown(c.args[used].text) + "\"");
  }

  // The surface a surface command acts on: the last one entered, or the one its S k / SO / SI
  // qualifier names. Consumes the qualifiers (and a Z1 zoom qualifier) from args[i].
  std::size_t surface_for(const Command& c, std::size_t& i) {
    std::optional<std::size_t> index = current_;
    while (i < c.args.size() && !c.args[i].quoted) {
      const Token& t = c.args[i];
      const std::string q = to_upper_ascii(t.text);
      if (q == "SO") {
        if (surfaces_.empty()) fail_at(c, t, "SO qualifier before the SO line");
        index = 0;
      } else if (q == "SI") {
        if (!has_image_) fail_at(c, t, "SI qualifier before the SI line");
        index = surfaces_.size() - 1;
      } else if (q.size() >= 2 && q[0] == 'S' && is_digit(q[1])) {
        if (q.find("..") != std::string::npos) fail_at(c, t, "surface ranges (" + shown(t.text) + ") are not supported");
        auto k = parse_finite_number(std::string_view(q).substr(1));
        if (!k || *k != std::floor(*k) || *k < 1.0 || *k >= static_cast<double>(surfaces_.size())) {
          fail_at(c, t, "surface " + shown(t.text) + " does not exist (surfaces are SO, S1 ... in the order of the S lines, then SI)");
        }
        index = static_cast<std::size_t>(*k);
      } else if (q.size() >= 2 && q[0] == 'Z' && is_digit(q[1])) {
        if (q != "Z1") fail_at(c, t, "zoom position " + shown(t.text) + ": zoom lenses are not supported");
      } else {
        break;
      }
      ++i;
    }
    if (!index) fail_keyword(c, "surface data before the first surface (SO)");
    return *index;
  }
  CvSurface& surface(const Command& c, std::size_t& i) { return surfaces_[surface_for(c, i)]; }

  // After the surface qualifiers of RDY, CUY and THI, a word instead of a number is a solve
  // (THI HMY 0, CUY UMY 0.1): the file also holds the solved value, so the solve is skipped.
  bool is_solve(const Command& c, std::size_t i) const {
    return i < c.args.size() && !c.args[i].quoted && !c.args[i].text.empty() && is_letter(c.args[i].text[0]);
  }

  // ---- one command -------------------------------------------------------------------------------

  void handle(const Command& c) {
    if (in_private_ && handle_private(c)) return;
    const std::string& k = c.name;
    if (k.empty()) fail(c.keyword.line, c.keyword.column, "a quoted string \"" + shown(c.keyword.text) + "\" where a command was expected");
    if (k == "SO") return handle_object(c);
    if (k == "S") return handle_surface(c);
    if (k == "SI") return handle_image(c);
    if (k == "GO") {
      after_go_ = true;
      return;
    }
    if (k == "RDM") return handle_rdm(c);
    if (k == "TIT") {
      std::string title;
      for (const Token& t : c.args) title += (title.empty() ? "" : " ") + t.text;
      name_ = title;
      return;
    }
    if (k == "LEN") {
      for (const Token& t : c.args) {
        if (t.quoted && !t.text.empty()) notes_ += (notes_.empty() ? "" : "\n") + t.text;
      }
      return;
    }
    if (k == "DIM") return handle_dim(c);
    if (k == "EPD" || k == "FNO" || k == "NAO") {
      // NAO: the object-space NA, n sin of the axial marginal ray's angle (finite objects; validation says so).
      const Located v = located_number(c, 0, k == "EPD" ? "the entrance-pupil diameter" : k == "FNO" ? "the F-number" : "the object-space NA");
      no_more_args(c, 1);
      if (!(v.value > 0.0)) fail_at(c, c.args[0], format_number(v.value) + ": must be > 0");
      aperture_kind_ = k == "EPD"   ? ApertureSpec::Kind::EntrancePupilDiameter
                       : k == "FNO" ? ApertureSpec::Kind::ImageSpaceFNumber
                                    : ApertureSpec::Kind::ObjectSpaceNA;
      aperture_ = v;
      return;
    }
    if (k == "YAN" || k == "XAN" || k == "YOB" || k == "XOB" || k == "YIM" || k == "XIM") return handle_field(c);
    if (k == "WL") {
      wavelengths_ = numbers_from(c, 0, "a wavelength (nm)", kMaxWavelengths);
      wavelength_line_ = c.keyword.line;
      return;
    }
    if (k == "REF") {
      const Located v = located_number(c, 0, "the reference wavelength number");
      no_more_args(c, 1);
      if (v.value != std::floor(v.value) || v.value < 1.0 || v.value > static_cast<double>(kMaxWavelengths)) {
        fail_at(c, c.args[0], "reference wavelength " + format_number(v.value) + ": must be a whole number from 1");
      }
      reference_ = v;
      return;
    }
    if (k == "TEM" || k == "PRE") return handle_environment(c);
    if (k == "PRV") {
      in_private_ = true;
      private_wavelengths_.clear();
      return;
    }
    if (k == "PWL") fail_keyword(c, "private catalogue wavelengths outside a PRV ... END block");
    if (k == "END") return;  // ends a PRV block; harmless elsewhere
    if (k == "RDY" || k == "CUY") return handle_curvature(c);
    if (k == "THI") return handle_thickness(c);
    if (k == "GLA") {
      std::size_t i = 0;
      CvSurface& s = surface(c, i);
      const Token& t = required_arg(c, i, "the glass name");
      no_more_args(c, i + 1);
      set_glass(c, s, t);
      return;
    }
    if (k == "RMD") {
      std::size_t i = 0;
      const std::size_t index = surface_for(c, i);
      const Token& t = required_arg(c, i, "the refract mode");
      set_refract_mode(c, t, surfaces_[index]);
      return;
    }
    if (k == "STO") {
      std::size_t i = 0;
      const std::size_t index = surface_for(c, i);
      no_more_args(c, i);
      if (stop_ && *stop_ != index) note(c.keyword.line, "STO moves the aperture stop (set before on line " + std::to_string(stop_line_) + ")");
      stop_ = index;
      stop_line_ = c.keyword.line;
      return;
    }
    if (k == "SLB") {
      std::size_t i = 0;
      CvSurface& s = surface(c, i);
      s.label = i < c.args.size() ? c.args[i].text : std::string();
      return;
    }
    if (k == "SPH" || k == "CON" || k == "ASP") {
      std::size_t i = 0;
      CvSurface& s = surface(c, i);
      no_more_args(c, i);
      if (k == "SPH") {
        // The surface becomes a sphere again: CODE V drops its conic and aspheric terms.
        s.conic = 0.0;
        s.coefficients = {};
      }
      return;
    }
    if (k == "K") {
      std::size_t i = 0;
      CvSurface& s = surface(c, i);
      s.conic = number(c, i, "the conic constant");
      no_more_args(c, i + 1);
      return;
    }
    if (k.size() == 1 && k[0] >= 'A' && k[0] <= 'J' && k[0] != 'I') {
      std::size_t i = 0;
      CvSurface& s = surface(c, i);
      const std::size_t slot = static_cast<std::size_t>(k[0] > 'I' ? k[0] - 'A' - 1 : k[0] - 'A');
      s.coefficients[slot] = located_number(c, i, "the aspheric coefficient");
      no_more_args(c, i + 1);
      return;
    }
    if (k == "CUF") {
      std::size_t i = 0;
      surface_for(c, i);
      if (number(c, i, "the curvature") != 0.0) fail_at(c, c.args[i], "Fresnel surfaces are not supported");
      return;
    }
    if (k == "CIR" || k == "REX" || k == "REY" || k == "ELX" || k == "ELY" || k == "ADX" || k == "ADY" || k == "ARO") {
      return handle_aperture(c);
    }
    if (contains(kDecentreKeywords, k)) {
      std::size_t i = 0;
      const std::size_t index = surface_for(c, i);
      const double v = number(c, i, "the decentre or tilt");
      if (v != 0.0) {
        fail_at(c, c.args[i], "decentres and tilts are not supported (rotationally symmetric systems only; " +
                                  format_number(v) + " on " + surface_name(index) + ")");
      }
      return;
    }
    if (k == "DAR" || k == "BEN" || k == "REV") {
      // How a decentre applies; with every decentre zero (anything else is refused) they change nothing.
      std::size_t i = 0;
      surface_for(c, i);
      return;
    }
    for (const Refusal& r : kRefusedKeywords) {
      if (r.keyword == k) fail_keyword(c, std::string(r.why));
    }
    if (contains(kVignettingKeywords, k)) {
      // VUY/VLY/VUX/VLX: the fraction of the pupil cut from its upper, lower, +x and -x edges, per field.
      std::vector<Located> values = numbers_from(c, 0, "a vignetting factor", kMaxFields);
      if (k == "VRO") {
        for (const Located& v : values) {
          if (v.value != 0.0 && !vignetting_noted_) {
            vignetting_noted_ = true;
            note(c.keyword.line, "VRO (rotated vignetting) ignored: the vignetted pupils are not turned");
          }
        }
        return;
      }
      vignetting_[k] = std::move(values);
      vignetting_line_ = c.keyword.line;
      return;
    }
    if (contains(kIgnoredKeywords, k)) return;
    record_unknown(c);
  }

  void handle_object(const Command& c) {
    if (!surfaces_.empty()) fail_keyword(c, "a second object surface (the first is on line " + std::to_string(surfaces_.front().line) + ")");
    CvSurface s;
    read_surface_line(c, s);
    surfaces_.push_back(std::move(s));
    current_ = 0;
  }

  void handle_surface(const Command& c) {
    if (surfaces_.empty()) fail_keyword(c, "a lens surface before the object surface (SO)");
    if (has_image_) fail_keyword(c, "a lens surface after the image surface (SI, line " + std::to_string(surfaces_.back().line) + ")");
    if (surfaces_.size() > kMaxSurfaces) fail_keyword(c, "more than " + std::to_string(kMaxSurfaces) + " surfaces");
    CvSurface s;
    read_surface_line(c, s);
    surfaces_.push_back(std::move(s));
    current_ = surfaces_.size() - 1;
  }

  void handle_image(const Command& c) {
    if (surfaces_.empty()) fail_keyword(c, "the image surface before the object surface (SO)");
    if (has_image_) fail_keyword(c, "a second image surface (the first is on line " + std::to_string(surfaces_.back().line) + ")");
    CvSurface s;
    read_surface_line(c, s);
    surfaces_.push_back(std::move(s));
    has_image_ = true;
    current_ = surfaces_.size() - 1;
  }

  // S, SO and SI lines: radius (or curvature, RDM N), thickness, glass and refract mode.
  void read_surface_line(const Command& c, CvSurface& s) {
    s.line = c.keyword.line;
    const double first = number(c, 0, radius_mode_ ? "the radius" : "the curvature");
    s.curvature = radius_mode_ ? (first == 0.0 ? 0.0 : 1.0 / first) : first;
    s.curvature_line = c.keyword.line;
    if (!rdm_seen_ && first != 0.0 && !rdm_noted_) {
      rdm_noted_ = true;
      note(c.keyword.line, "no RDM command: the first number on S lines is read as a curvature (CODE V's default; RDM Y reads radii)");
    }
    s.thickness = number(c, 1, "the thickness");
    s.thickness_line = c.args[1].line;
    s.thickness_column = c.args[1].column;
    if (c.args.size() > 2) set_glass(c, s, c.args[2]);
    if (c.args.size() > 3) set_refract_mode(c, c.args[3], s);
    no_more_args(c, 4);
  }

  // REFL in the glass field makes a mirror (the medium before it continues), as RMD REFL does.
  void set_glass(const Command& c, CvSurface& s, const Token& t) {
    const std::string upper = to_upper_ascii(t.text);
    if (!t.quoted && upper == "REFL") {
      s.mirror = true;
      s.mirror_line = c.keyword.line;
      s.glass.reset();
      return;
    }
    s.glass = GlassRef{t.text, t.quoted, t.line, t.column};
  }

  void set_refract_mode(const Command& c, const Token& t, CvSurface& s) const {
    const std::string mode = to_upper_ascii(t.text);
    if (mode == "TIR") fail_at(c, t, "total-internal-reflection surfaces are not supported");
    if (mode != "REFR" && mode != "REFL") fail_at(c, t, "unknown refract mode \"" + shown(t.text) + "\" (expected REFR or REFL)");
    s.mirror = mode == "REFL";
    s.mirror_line = c.keyword.line;
  }

  void handle_rdm(const Command& c) {
    rdm_seen_ = true;
    if (c.args.empty()) {
      radius_mode_ = true;
      return;
    }
    const std::string v = to_upper_ascii(c.args[0].text);
    if (v == "Y" || v == "YES") {
      radius_mode_ = true;
    } else if (v == "N" || v == "NO") {
      radius_mode_ = false;
    } else {
      fail_at(c, c.args[0], "expected Y or N, got \"" + shown(c.args[0].text) + "\"");
    }
    no_more_args(c, 1);
  }

  void handle_dim(const Command& c) {
    const Token& t = required_arg(c, 0, "the lens unit");
    no_more_args(c, 1);
    const std::string u = to_upper_ascii(t.text);
    if (u == "M" || u == "MM") {
      mm_per_unit_ = 1.0;
    } else if (u == "C" || u == "CM") {
      mm_per_unit_ = mm_from_cm(1.0);
    } else if (u == "I" || u == "IN" || u == "INCH") {
      mm_per_unit_ = mm_from_inch(1.0);
    } else {
      fail_at(c, t, "unknown lens unit \"" + shown(t.text) + "\" (expected M (mm), C (cm) or I (inch))");
    }
  }

  void handle_environment(const Command& c) {
    // Catalogue indices are relative to air at 20 C and 1 atm; another environment would shift them.
    const double v = number(c, 0, c.name == "TEM" ? "the temperature (C)" : "the pressure (atm)");
    if ((c.name == "TEM" && v != 20.0) || (c.name == "PRE" && v != 1.0)) {
      warn(c.keyword.line, c.name + " " + format_number(v) + " ignored: indices are computed at 20 C and 1 atm");
    }
  }

  void handle_curvature(const Command& c) {
    std::size_t i = 0;
    CvSurface& s = surface(c, i);
    if (is_solve(c, i)) return;
    const double v = number(c, i, c.name == "RDY" ? "the radius" : "the curvature");
    no_more_args(c, i + 1);
    s.curvature = c.name == "RDY" ? (v == 0.0 ? 0.0 : 1.0 / v) : v;
    s.curvature_line = c.keyword.line;
  }

  void handle_thickness(const Command& c) {
    std::size_t i = 0;
    CvSurface& s = surface(c, i);
    if (is_solve(c, i)) return;
    s.thickness = number(c, i, "the thickness");
    no_more_args(c, i + 1);
    s.thickness_line = c.args[i].line;
    s.thickness_column = c.args[i].column;
  }

  void handle_field(const Command& c) {
    const FieldSpec::Kind kind = c.name[1] == 'A'   ? FieldSpec::Kind::AngleDeg
                                 : c.name[1] == 'O' ? FieldSpec::Kind::ObjectHeightMm
                                                    : FieldSpec::Kind::ImageHeightMm;
    std::vector<Located> values = numbers_from(c, 0, "a field value", kMaxFields);
    FieldAxis& axis = c.name[0] == 'X' ? x_field_ : y_field_;
    axis = FieldAxis{kind, std::move(values), c.keyword.line, c.name};
  }

  void handle_aperture(const Command& c) {
    std::size_t i = 0;
    const std::size_t index = surface_for(c, i);
    CvSurface& s = surfaces_[index];
    ApertureRole role = kClear;
    for (; i < c.args.size() && !c.args[i].quoted; ++i) {
      const std::string q = to_upper_ascii(c.args[i].text);
      if (q == "OBS") {
        role = kObscuration;
      } else if (q == "EDG") {
        role = kEdge;
      } else if (q == "HOL") {
        fail_at(c, c.args[i], "holes (HOL apertures) are not supported");
      } else if (q.size() >= 2 && q[0] == 'L' && is_quote(q[1])) {
        continue;  // an aperture label
      } else {
        break;
      }
    }
    const Located v = located_number(c, i, c.name == "ARO" ? "the rotation (degrees)" : "the size");
    no_more_args(c, i + 1);
    std::optional<ApertureInput>& slot = s.apertures[static_cast<std::size_t>(role)];
    if (!slot) {
      slot = ApertureInput{};
      slot->line = c.keyword.line;
    }
    const std::string& k = c.name;
    if (k == "ADX" || k == "ADY") {
      (k == "ADX" ? slot->decenter_x : slot->decenter_y) = v.value;
      return;
    }
    if (k == "ARO") {
      slot->rotation_deg = v.value;
      slot->rotation_line = c.keyword.line;
      return;
    }
    if (!(v.value > 0.0)) fail_at(c, c.args[i], format_number(v.value) + ": must be > 0");
    const SurfaceAperture::Shape shape = k == "CIR"   ? SurfaceAperture::Shape::Circular
                                         : k[0] == 'R' ? SurfaceAperture::Shape::Rectangular
                                                       : SurfaceAperture::Shape::Elliptical;
    if (slot->shape && *slot->shape != shape) {
      fail_keyword(c, "a second, differently shaped " + std::string(role == kClear ? "clear aperture" : role == kObscuration ? "obscuration" : "edge") +
                          " on " + surface_name(index) + " (from line " + std::to_string(slot->line) +
                          "): lensmith models one aperture of each kind per surface");
    }
    slot->shape = shape;
    if (k == "CIR" || k[2] == 'X') {
      slot->half_x = v.value;
    } else {
      slot->half_y = v.value;
    }
  }

  // A PRV block: PWL lists wavelengths (nm), then each 'NAME' n1 n2 ... row a glass's indices at them.
  // Returns false for commands that are not part of the block's syntax (handled as usual).
  bool handle_private(const Command& c) {
    if (c.name == "END") {
      in_private_ = false;
      return true;
    }
    if (c.name == "PWL") {
      private_wavelengths_ = numbers_from(c, 0, "a wavelength (nm)", kMaxWavelengths);
      for (const Located& w : private_wavelengths_) {
        if (!(w.value > 0.0)) fail(w.line, w.column, "PWL: wavelength " + format_number(w.value) + " nm: must be > 0");
      }
      return true;
    }
    if (!c.keyword.quoted) return false;
    if (private_wavelengths_.empty()) fail_keyword(c, "a private glass before the PWL line giving its wavelengths");
    if (private_glasses_.size() >= kMaxPrivateGlasses) fail_keyword(c, "more than " + std::to_string(kMaxPrivateGlasses) + " private glasses");
    PrivateGlass g;
    g.name = c.keyword.text;
    g.line = c.keyword.line;
    if (!c.args.empty() && !c.args[0].quoted && !c.args[0].text.empty() && is_letter(c.args[0].text[0])) {
      g.formula = shown(c.args[0].text);
      private_glasses_[to_upper_ascii(g.name)] = std::move(g);
      return true;
    }
    for (const Located& n : numbers_from(c, 0, "an index", kMaxWavelengths)) {
      if (!(n.value >= 1.0 && n.value <= kMaxPlausibleIndex)) {
        fail(n.line, n.column, shown(g.name) + ": index " + format_number(n.value) + ": must be in [1, 5]");
      }
      g.indices.push_back(n.value);
    }
    if (g.indices.size() != private_wavelengths_.size()) {
      fail_keyword(c, std::to_string(g.indices.size()) + " indices for " + std::to_string(private_wavelengths_.size()) +
                          " PWL wavelengths");
    }
    for (const Located& w : private_wavelengths_) g.wavelengths_nm.push_back(w.value);
    private_glasses_[to_upper_ascii(g.name)] = std::move(g);
    return true;
  }

  void record_unknown(const Command& c) { unknown_.record(to_upper_ascii(shown(c.keyword.text)), c.keyword.line); }

  std::string surface_name(std::size_t index) const {
    if (index == 0) return "the object surface (SO)";
    if (has_image_ && index + 1 == surfaces_.size()) return "the image surface (SI)";
    return "surface " + std::to_string(index);
  }

  // ---- glasses -----------------------------------------------------------------------------------

  // nd and Vd of a fictitious glass code: CODE V's "nnn.vvv" (nd = 1.nnn, Vd = vv.v: 569.631 is nd
  // 1.569, Vd 63.1; more digits give more precision), a six-digit glass code "nnnvvv" (517642: nd 1.517,
  // Vd 64.2), or "nd:Vd". Empty when the text is none of these.
  static std::optional<std::pair<double, double>> glass_code(std::string_view text) {
    const auto all_digits = [](std::string_view s) { return !s.empty() && std::all_of(s.begin(), s.end(), is_digit); };
    if (const auto colon = text.find(':'); colon != std::string_view::npos) {
      auto nd = parse_finite_number(text.substr(0, colon));
      auto vd = parse_finite_number(text.substr(colon + 1));
      if (nd && vd) return std::make_pair(*nd, *vd);
      return std::nullopt;
    }
    const auto dot = text.find('.');
    const std::string_view index_digits = text.substr(0, std::min(dot, text.size()));
    std::string_view abbe_digits = dot == std::string_view::npos ? std::string_view() : text.substr(dot + 1);
    if (dot == std::string_view::npos) {
      if (text.size() != 6 || !all_digits(text)) return std::nullopt;
      abbe_digits = text.substr(3);
      return std::make_pair(*parse_finite_number("1." + std::string(text.substr(0, 3))),
                            *parse_finite_number(std::string(abbe_digits.substr(0, 2)) + "." + std::string(abbe_digits.substr(2))));
    }
    if (!all_digits(index_digits) || !all_digits(abbe_digits) || index_digits.size() > kMaxGlassCodeDigits ||
        abbe_digits.size() > kMaxGlassCodeDigits) {
      return std::nullopt;
    }
    std::string abbe(abbe_digits);
    while (abbe.size() < 2) abbe += '0';
    return std::make_pair(*parse_finite_number("1." + std::string(index_digits)),
                          *parse_finite_number(abbe.substr(0, 2) + "." + abbe.substr(2)));
  }

  // The catalogue glass whose name is `name` as CODE V writes it (NBK7 for N-BK7), at `vendor`
  // (upper case; empty = any, in the catalogue's vendor order).
  const Glass* find_glass(std::string_view name, const std::string& vendor) {
    if (const Glass* exact = catalogue_.find(name, vendor)) return exact;
    if (normalised_.empty()) {
      for (const Glass& g : catalogue_.glasses()) normalised_[normalised_glass_name(g.name())].push_back(&g);
    }
    const auto it = normalised_.find(normalised_glass_name(name));
    if (it == normalised_.end()) return nullptr;
    const Glass* best = nullptr;
    std::size_t best_rank = 0;
    for (const Glass* g : it->second) {
      if (!vendor.empty() && g->vendor() != vendor) continue;
      const auto rank = static_cast<std::size_t>(
          std::find(catalogue_.vendors().begin(), catalogue_.vendors().end(), g->vendor()) - catalogue_.vendors().begin());
      if (best == nullptr || rank < best_rank) {
        best = g;
        best_rank = rank;
      }
    }
    return best;
  }

  static std::string describe(const Glass& g) {
    return g.vendor() + " " + g.name() + " (nd " + format_rounded(g.nd(), 6) + ", Vd " + format_rounded(g.vd(), 4) + ")";
  }

  MaterialSpec material_for(const GlassRef& g) {
    const std::string key = (g.quoted ? "'" : "") + to_upper_ascii(g.name);
    if (auto it = materials_.find(key); it != materials_.end()) return it->second;
    MaterialSpec m = resolve_glass(g);
    materials_.emplace(key, m);
    return m;
  }

  MaterialSpec resolve_glass(const GlassRef& g) {
    const std::string upper = to_upper_ascii(g.name);
    if (auto it = private_glasses_.find(upper); it != private_glasses_.end()) return private_material(it->second, g.line);
    if (upper == "AIR") return MaterialSpec::air();
    if (auto code = glass_code(g.name)) return fictitious_material(g, code->first, code->second);
    if (const Glass* whole = catalogue_.find(g.name)) return MaterialSpec::catalog(whole->name(), whole->vendor());
    // NAME_CATALOGUE, as CODE V names catalogue glasses: NBK7_SCHOTT, SLAL8_OHARA.
    std::string base = g.name;
    std::string vendor;
    if (const auto underscore = g.name.rfind('_'); underscore != std::string::npos && underscore > 0) {
      base = g.name.substr(0, underscore);
      vendor = to_upper_ascii(g.name.substr(underscore + 1));
    }
    const auto& vendors = catalogue_.vendors();
    const bool known_vendor = !vendor.empty() && std::find(vendors.begin(), vendors.end(), vendor) != vendors.end();
    if (known_vendor) {
      if (const Glass* found = find_glass(base, vendor)) return MaterialSpec::catalog(found->name(), found->vendor());
    }
    // SCHOTT renamed its glasses when it made them lead-free (SK16 -> N-SK16). Another maker may
    // still sell a glass under the old name (HIKARI's SK16), but the file names SCHOTT's.
    const Glass* next = vendor.empty() ? catalogue_.successor(base) : nullptr;
    if (vendor == "SCHOTT") {
      next = find_glass("N-" + base, vendor);
      if (next == nullptr) next = find_glass("N-" + base + "A", vendor);
    }
    if (next != nullptr) {
      warn(g.line, "glass \"" + g.name + "\" is an obsolete name in no catalogue; using its successor " + describe(*next) +
                       ", the same glass type made lead-free, whose index differs slightly from the original's");
      return MaterialSpec::catalog(next->name(), next->vendor());
    }
    if (const Glass* elsewhere = find_glass(base, {})) {
      if (!vendor.empty()) {
        warn(g.line, "glass \"" + g.name + "\": " +
                         (known_vendor ? "not in the " + vendor + " catalogue" : "catalogue " + vendor + " is not among lensmith's") +
                         "; using " + describe(*elsewhere));
      }
      return MaterialSpec::catalog(elsewhere->name(), elsewhere->vendor());
    }
    std::string names;
    for (const std::string& n : catalogue_.closest_names(base)) names += (names.empty() ? "" : ", ") + n;
    fail(g.line, g.column,
         "GLA: unknown glass \"" + shown(g.name, 64) + "\" (no catalogue has it, it is no private glass of a PRV block and no "
         "glass code such as 517.642); closest catalogue names: " + (names.empty() ? "(none)" : names));
  }

  MaterialSpec fictitious_material(const GlassRef& g, double nd, double vd) {
    if (!(nd >= 1.0 && nd <= kMaxPlausibleIndex)) {
      fail(g.line, g.column, "glass code " + shown(g.name) + ": nd = " + format_number(nd) + ": must be in [1, 5]");
    }
    if (vd < 0.0) fail(g.line, g.column, "glass code " + shown(g.name) + ": Vd = " + format_number(vd) + ": must be >= 0");
    const std::optional<double> abbe = vd > 0.0 ? std::optional<double>(vd) : std::nullopt;
    // CODE V models a fictitious glass's dispersion its own way; lensmith's model glass is Cauchy.
    warn(g.line, "fictitious glass " + g.name + ": model glass nd=" + format_number(nd) +
                     (abbe ? " Vd=" + format_number(vd) + " (Cauchy from nd and Vd: " + model_glass_accuracy(vd) + " in index)"
                           : std::string(" without dispersion")));
    return MaterialSpec::model(nd, abbe);
  }

  // Index at `wavelength_nm` from a private glass's table, linear in 1/lambda^2 (Cauchy's variable)
  // between the neighbouring wavelengths; the table must bracket the wavelength.
  static double interpolate_index(const PrivateGlass& g, double wavelength_nm) {
    std::vector<std::pair<double, double>> rows;
    for (std::size_t i = 0; i < g.indices.size(); ++i) rows.emplace_back(g.wavelengths_nm[i], g.indices[i]);
    std::sort(rows.begin(), rows.end());
    const auto upper = std::lower_bound(rows.begin(), rows.end(), std::make_pair(wavelength_nm, 0.0));
    if (upper != rows.end() && upper->first == wavelength_nm) return upper->second;
    const auto& [l1, n1] = *(upper - 1);
    const auto& [l2, n2] = *upper;
    const double x = 1.0 / (wavelength_nm * wavelength_nm);
    const double x1 = 1.0 / (l1 * l1);
    const double x2 = 1.0 / (l2 * l2);
    return n1 + (n2 - n1) * (x - x1) / (x2 - x1);
  }

  MaterialSpec private_material(const PrivateGlass& g, int use_line) {
    if (!g.formula.empty()) {
      fail(use_line, 0, "private glass " + shown(g.name) + " (line " + std::to_string(g.line) + ") is given by a formula (" +
                            g.formula + "), which lensmith does not read; give its indices at the PWL wavelengths");
    }
    const auto [shortest, longest] = std::minmax_element(g.wavelengths_nm.begin(), g.wavelengths_nm.end());
    if (g.indices.size() == 1) {
      warn(use_line, "private glass " + g.name + " (line " + std::to_string(g.line) + ") has one index, n = " +
                         format_number(g.indices.front()) + " at " + format_number(g.wavelengths_nm.front()) +
                         " nm: read as an index without dispersion");
      return MaterialSpec::model(g.indices.front(), std::nullopt);
    }
    if (!(*shortest <= kWavelengthF_nm && *longest >= kWavelengthC_nm)) {
      fail(use_line, 0, "private glass " + shown(g.name) + " (line " + std::to_string(g.line) + "): its PWL wavelengths (" +
                            format_number(*shortest) + " to " + format_number(*longest) +
                            " nm) do not span the F and C lines (486.13 to 656.27 nm) that a model glass needs");
    }
    const double nd = interpolate_index(g, kWavelengthD_nm);
    const double dispersion = interpolate_index(g, kWavelengthF_nm) - interpolate_index(g, kWavelengthC_nm);
    if (!(dispersion > 0.0)) {
      fail(use_line, 0, "private glass " + shown(g.name) + " (line " + std::to_string(g.line) +
                            "): its index does not fall from the F to the C line; lensmith cannot model it");
    }
    const double vd = (nd - 1.0) / dispersion;
    warn(use_line, "private glass " + g.name + " (line " + std::to_string(g.line) + "): model glass nd=" + format_rounded(nd, 6) +
                       " Vd=" + format_rounded(vd, 4) + " from its index table (Cauchy from nd and Vd: " +
                       model_glass_accuracy(vd) + " in index)");
    return MaterialSpec::model(nd, vd);
  }

  // ---- building the prescription -----------------------------------------------------------------

  double mm(double lens_units) const { return lens_units * mm_per_unit_; }

  // The line a GlassError or PrescriptionError is about, from its subject.
  int line_for_subject(const ErrorSubject& subject) const {
    const int n = subject.surface;
    if (n >= 1 && n + 1 < static_cast<int>(surfaces_.size())) return surfaces_[static_cast<std::size_t>(n)].line;
    const std::string_view field = subject.field;
    if (field.starts_with("primary")) return reference_ ? reference_->line : wavelength_line_;
    if (field.starts_with("wavelength")) return wavelength_line_;
    if (field.starts_with("aperture") && aperture_) return aperture_->line;
    if (field.starts_with("field")) return std::max(x_field_.line, y_field_.line);
    if (field.starts_with("object") && !surfaces_.empty()) return surfaces_.front().line;
    return 0;
  }

  LensReadResult build() {
    if (surfaces_.empty()) fail(last_line_, 0, "no SO line (object surface): not a CODE V sequence file, or the file is truncated");
    if (!has_image_) {
      // CODE V's lens always has an image surface: a sequence that inserts S lines and no SI keeps the
      // default one, a plane at the last surface's thickness. Say so, since a truncated file looks alike.
      note(last_line_, "no SI line: the image surface is CODE V's default plane, at the last surface's thickness");
      CvSurface image;
      image.line = last_line_;
      surfaces_.push_back(std::move(image));
      has_image_ = true;
    }
    if (surfaces_.size() < 3) {
      fail(surfaces_.back().line, 0, "a lens needs at least one S line between SO (object) and SI (image)");
    }
    LensReadResult result;
    Prescription& p = result.prescription;
    p.name = name_.empty() ? lens_name_from_path(file_) : name_;
    p.notes = notes_;

    const CvSurface& object = surfaces_.front();
    if (stop_ && *stop_ == 0) fail(stop_line_, 0, "STO on the object surface (SO)");
    if (object.thickness >= kInfiniteThickness) {
      p.object_distance_mm = kInfinity;
    } else {
      if (!(object.thickness > 0.0)) {
        fail(object.thickness_line, object.thickness_column,
             "SO: object distance = " + format_number(object.thickness) +
                 ": must be > 0, or 1e10 or more for an object at infinity (virtual objects are not supported)");
      }
      if (object.curvature != 0.0) {
        fail(object.curvature_line, 0, "a curved object surface (curvature " + format_number(object.curvature) +
                                           ") at a finite distance is not supported: lensmith's object is a plane");
      }
      p.object_distance_mm = mm(object.thickness);
    }
    if (object.glass) p.object_material = material_for(*object.glass);
    if (object.mirror) fail(object.mirror_line, 0, "REFL on the object surface (SO): the object cannot be a mirror");
    if (surfaces_.back().mirror) fail(surfaces_.back().mirror_line, 0, "REFL on the image surface (SI): the image cannot be a mirror");

    const CvSurface& image = surfaces_.back();
    const std::size_t image_index = surfaces_.size() - 1;
    if (stop_ && *stop_ == image_index) fail(stop_line_, 0, "STO on the image surface (SI)");
    if (image.curvature != 0.0) {
      warn(image.curvature_line, "the image surface is curved (curvature " + format_number(image.curvature) +
                                     "); lensmith models a plane image surface");
    }

    for (std::size_t k = 1; k < image_index; ++k) p.surfaces.push_back(make_surface(k));
    if (!stop_) {
      p.surfaces.front().is_stop = true;
      note(surfaces_[1].line, "no STO: surface 1 is the aperture stop (CODE V's default)");
    }
    // CODE V places the image surface its own thickness beyond the last surface's (a defocus); its
    // first-order listing's IMG DIS is the sum.
    if (image.thickness != 0.0) {
      p.surfaces.back().thickness_mm += mm(image.thickness);
      note(image.thickness_line, "SI thickness " + format_number(image.thickness) +
                                     " (a defocus) added to the last surface's: the image plane is " +
                                     format_rounded(p.surfaces.back().thickness_mm, 10) + " mm behind it");
    }

    set_aperture(p);
    set_field(p);
    set_wavelengths(p);
    p.ray_aiming = RayAiming::RealStop;

    resolve_and_validate(p, catalogue_, file_, [this](const ErrorSubject& e) { return line_for_subject(e); });
    unknown_.report(diagnostics_, file_, "commands");
    result.diagnostics = std::move(diagnostics_);
    return result;
  }

  Surface make_surface(std::size_t index) {
    const CvSurface& cv = surfaces_[index];
    Surface s;
    s.curvature_per_mm = cv.curvature / mm_per_unit_;
    if (cv.thickness >= kInfiniteThickness) {
      fail(cv.thickness_line, cv.thickness_column,
           "thickness " + format_number(cv.thickness) + " on surface " + std::to_string(index) +
               " is infinite (1e10 or more): afocal systems are not supported");
    }
    s.thickness_mm = mm(cv.thickness);
    if (cv.glass) s.material = material_for(*cv.glass);
    s.mirror = cv.mirror;
    s.is_stop = stop_ && *stop_ == index;
    s.conic = cv.conic;
    for (std::size_t m = 0; m < cv.coefficients.size(); ++m) {
      const Located& a = cv.coefficients[m];
      if (a.value == 0.0) continue;
      const int power = 4 + 2 * static_cast<int>(m);  // A is the r^4 term
      const std::size_t slot = static_cast<std::size_t>(power / 2 - 1);
      if (slot >= s.even_asphere.size()) {
        fail(a.line, a.column, std::string(1, static_cast<char>('A' + m + (m >= 8 ? 1 : 0))) + " = " + format_number(a.value) +
                                   ": the r^" + std::to_string(power) + " term is not supported (lensmith's even asphere ends at r^16, G)");
      }
      s.even_asphere[slot] = a.value * std::pow(mm_per_unit_, 1 - power);
    }
    s.comment = cv.label;
    set_apertures(s, index);
    return s;
  }

  // One aperture as lensmith's SurfaceAperture (mm).
  SurfaceAperture to_aperture(const ApertureInput& a, bool obscuration, std::size_t index) const {
    if (!a.shape) fail(a.line, 0, "ADX/ADY/ARO on " + surface_name(index) + " without an aperture (CIR, REX/REY or ELX/ELY)");
    SurfaceAperture out;
    out.shape = *a.shape;
    out.obscuration = obscuration;
    const bool circle = out.shape == SurfaceAperture::Shape::Circular;
    const char* x_name = out.shape == SurfaceAperture::Shape::Rectangular ? "REX" : "ELX";
    const char* y_name = out.shape == SurfaceAperture::Shape::Rectangular ? "REY" : "ELY";
    if (!circle && (!a.half_x || !a.half_y)) {
      fail(a.line, 0, std::string(a.half_x ? y_name : x_name) + " missing on " + surface_name(index) + ": a " +
                          (out.shape == SurfaceAperture::Shape::Rectangular ? "rectangular" : "elliptical") +
                          " aperture needs both half widths (" + x_name + " and " + y_name + ")");
    }
    out.half_x_mm = mm(*a.half_x);
    out.half_y_mm = circle ? out.half_x_mm : mm(*a.half_y);
    out.decenter_x_mm = mm(a.decenter_x);
    out.decenter_y_mm = mm(a.decenter_y);
    const bool centred_circle = circle && a.decenter_x == 0.0 && a.decenter_y == 0.0;
    if (a.rotation_deg != 0.0 && !centred_circle) {
      fail(a.rotation_line, 0, "ARO " + format_number(a.rotation_deg) + " on " + surface_name(index) +
                                   ": rotated apertures are not supported");
    }
    return out;
  }

  // CIR is a clear aperture that clips rays (Surface::clips_rays); an obscuration (OBS) or a
  // non-circular or decentred aperture becomes Surface::aperture; an edge (EDG) only sizes the surface.
  void set_apertures(Surface& s, std::size_t index) const {
    const auto& slots = surfaces_[index].apertures;
    const auto& clear = slots[kClear];
    const auto& obscuration = slots[kObscuration];
    const auto& edge = slots[kEdge];
    if (clear) {
      SurfaceAperture a = to_aperture(*clear, false, index);
      const bool centred_circle = a.shape == SurfaceAperture::Shape::Circular && a.decenter_x_mm == 0.0 && a.decenter_y_mm == 0.0;
      s.clips_rays = true;
      if (obscuration) {
        const SurfaceAperture o = to_aperture(*obscuration, true, index);
        const bool centred_obscuration =
            o.shape == SurfaceAperture::Shape::Circular && o.decenter_x_mm == 0.0 && o.decenter_y_mm == 0.0;
        if (!centred_circle || !centred_obscuration) {
          fail(obscuration->line, 0, "a clear aperture and an obscuration on " + surface_name(index) +
                                         ": lensmith models one aperture per surface, which can be an annulus (a centred CIR "
                                         "with a centred CIR OBS) but no other combination");
        }
        a.min_radius_mm = o.half_x_mm;  // an annulus
        s.aperture = a;
        s.semi_diameter_mm = a.half_x_mm;
        return;
      }
      if (centred_circle) {
        s.semi_diameter_mm = a.half_x_mm;
      } else {
        s.aperture = a;
        s.semi_diameter_mm = a.outer_radius_mm();
      }
      return;
    }
    if (obscuration) s.aperture = to_aperture(*obscuration, true, index);
    if (edge) {
      s.semi_diameter_mm = to_aperture(*edge, false, index).outer_radius_mm();
      s.clips_rays = false;
    }
  }

  void set_aperture(Prescription& p) {
    if (!aperture_) {
      warn(0, "no aperture command (EPD or FNO); the stop's clear aperture (CIR) sets the aperture");
      p.aperture = ApertureSpec{ApertureSpec::Kind::FloatByStop, 0.0};
      return;
    }
    const double value = aperture_kind_ == ApertureSpec::Kind::EntrancePupilDiameter ? mm(aperture_->value) : aperture_->value;
    p.aperture = ApertureSpec{aperture_kind_, value};
  }

  void set_field(Prescription& p) {
    if (x_field_.values.empty() && y_field_.values.empty()) return;
    const bool both = !x_field_.values.empty() && !y_field_.values.empty();
    const FieldAxis& later = x_field_.line > y_field_.line ? x_field_ : y_field_;
    if (both && x_field_.kind != y_field_.kind) {
      fail(later.line, 0, later.keyword + ": field type differs from the " + (&later == &x_field_ ? y_field_ : x_field_).keyword +
                              " line's; x and y fields must both be angles (XAN/YAN), object heights (XOB/YOB) or image heights (XIM/YIM)");
    }
    if (both && x_field_.values.size() != y_field_.values.size()) {
      fail(later.line, 0, x_field_.keyword + " lists " + std::to_string(x_field_.values.size()) + " fields and " +
                              y_field_.keyword + " " + std::to_string(y_field_.values.size()) + "; they must list the same number");
    }
    const FieldSpec::Kind kind = y_field_.values.empty() ? x_field_.kind : y_field_.kind;
    const std::size_t count = std::max(x_field_.values.size(), y_field_.values.size());
    FieldSpec field;
    field.kind = kind;
    bool folded = false;
    for (std::size_t i = 0; i < count; ++i) {
      const double y = i < y_field_.values.size() ? y_field_.values[i].value : 0.0;
      const double x = i < x_field_.values.size() ? x_field_.values[i].value : 0.0;
      folded = folded || x != 0.0;
      const double radial = radial_field_value(kind, x, y);
      field.values.push_back(kind == FieldSpec::Kind::AngleDeg ? radial : mm(radial));
    }
    if (folded) note(later.line, "fields with an x component were folded into radial fields (the lens is rotationally symmetric)");
    // CODE V's vignetting factors as OpticStudio's: the pupil spans [-(1 - VLY), 1 - VUY] in y, so its
    // centre is (VLY - VUY) / 2 and its half height 1 - (VUY + VLY) / 2; the same in x.
    auto factor = [&](const char* key, std::size_t i) {
      auto it = vignetting_.find(key);
      return it != vignetting_.end() && i < it->second.size() ? it->second[i].value : 0.0;
    };
    std::vector<VignettingFactors> vignetting(count);
    bool any = false;
    for (std::size_t i = 0; i < count; ++i) {
      const double uy = factor("VUY", i), ly = factor("VLY", i), ux = factor("VUX", i), lx = factor("VLX", i);
      vignetting[i] = {(lx - ux) / 2.0, (ly - uy) / 2.0, (ux + lx) / 2.0, (uy + ly) / 2.0, 0.0};
      if (vignetting[i].is_none()) continue;
      any = true;
      if (!(vignetting[i].vcx < 1.0 && vignetting[i].vcy < 1.0)) {
        fail(vignetting_line_, 0, "vignetting of field " + std::to_string(i + 1) + " closes the pupil (VUY + VLY or VUX + VLX >= 2)");
      }
      if (i < x_field_.values.size() && x_field_.values[i].value != 0.0) {
        vignetting[i] = {};  // defined in that field's own frame, not along +y
        warn(vignetting_line_, "vignetting of field " + std::to_string(i + 1) + ", which has an x component, is not used");
      }
    }
    if (any) field.vignetting = std::move(vignetting);
    p.field = std::move(field);
  }

  void set_wavelengths(Prescription& p) {
    if (wavelengths_.empty()) {
      if (reference_) fail(reference_->line, reference_->column, "REF without a WL line");
      note(0, "no WL command; using F, d, C with d the reference wavelength");
      return;
    }
    p.wavelengths_nm.clear();
    for (const Located& w : wavelengths_) {
      if (!(w.value > 0.0)) fail(w.line, w.column, "WL: wavelength " + format_number(w.value) + " nm: must be > 0");
      p.wavelengths_nm.push_back(w.value);
    }
    if (reference_) {
      const auto index = static_cast<std::size_t>(reference_->value);
      if (index > p.wavelengths_nm.size()) {
        fail(reference_->line, reference_->column,
             "REF " + std::to_string(index) + ": WL lists only " + std::to_string(p.wavelengths_nm.size()) + " wavelengths");
      }
      p.primary_wavelength_index = index - 1;
    } else {
      // CODE V's default reference is wavelength 2 of its default three (656.3, 587.6, 486.1 nm).
      p.primary_wavelength_index = (p.wavelengths_nm.size() - 1) / 2;
      if (p.wavelengths_nm.size() > 1) {
        warn(wavelength_line_, "no REF command: the middle wavelength, " + format_number(p.primary_wavelength_nm()) +
                                   " nm, is the reference");
      }
    }
  }

  struct FieldAxis {
    FieldSpec::Kind kind = FieldSpec::Kind::AngleDeg;
    std::vector<Located> values;
    int line = 0;
    std::string keyword;
  };

  const std::string& file_;
  const GlassCatalog& catalogue_;
  Diagnostics diagnostics_;
  std::vector<Command> commands_;
  int last_line_ = 0;
  bool after_go_ = false;

  std::vector<CvSurface> surfaces_;  // SO, the S lines, then SI once read
  bool has_image_ = false;
  std::optional<std::size_t> current_;
  std::optional<std::size_t> stop_;
  int stop_line_ = 0;
  bool radius_mode_ = false;  // CODE V reads curvatures until RDM (Y) says radii
  bool rdm_seen_ = false;
  bool rdm_noted_ = false;
  double mm_per_unit_ = 1.0;
  std::string name_;
  std::string notes_;
  ApertureSpec::Kind aperture_kind_ = ApertureSpec::Kind::FloatByStop;
  std::optional<Located> aperture_;
  FieldAxis x_field_;
  FieldAxis y_field_;
  std::vector<Located> wavelengths_;
  int wavelength_line_ = 0;
  std::optional<Located> reference_;
  bool vignetting_noted_ = false;
  std::map<std::string, std::vector<Located>> vignetting_;  // VUY, VLY, VUX, VLX as given, per field
  int vignetting_line_ = 0;

  bool in_private_ = false;
  std::vector<Located> private_wavelengths_;
  std::map<std::string, PrivateGlass> private_glasses_;  // by upper-case name
  std::map<std::string, MaterialSpec> materials_;        // resolved glasses by name as written
  std::unordered_map<std::string, std::vector<const Glass*>> normalised_;  // normalised_glass_name -> glasses

  UnknownKeywords unknown_;
};

}  // namespace

LensReadResult read_codev(std::string_view bytes, const std::string& file_name, const GlassCatalog& catalogue) {
  CodeVParser parser(file_name, catalogue);
  return parser.parse(bytes);
}

}  // namespace lensmith
