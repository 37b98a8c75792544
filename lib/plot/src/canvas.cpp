// Raster primitives with coverage-based anti-aliasing and OpenImageIO text and PNG output.
#include "lensmith/plot/canvas.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <system_error>

#include "lensmith/core/errors.h"
#include "lensmith/core/text_file.h"
#include "lensmith/core/units.h"

namespace lensmith::plot {

namespace {

float clamp01(double v) { return static_cast<float>(std::clamp(v, 0.0, 1.0)); }

// Distance from p to the segment ab.
double segment_distance(double px, double py, Point2 a, Point2 b) {
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double len2 = dx * dx + dy * dy;
  double t = len2 > 0.0 ? ((px - a.x) * dx + (py - a.y) * dy) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  const double ex = a.x + t * dx - px, ey = a.y + t * dy - py;
  return std::sqrt(ex * ex + ey * ey);
}

// A coverage mask over a rectangle of the canvas.
struct Mask {
  int x0 = 0, y0 = 0, width = 0, height = 0;
  std::vector<float> values;
  Mask(double left, double top, double right, double bottom, int canvas_width, int canvas_height) {
    x0 = std::max(0, static_cast<int>(std::floor(left)));
    y0 = std::max(0, static_cast<int>(std::floor(top)));
    const int x1 = std::min(canvas_width, static_cast<int>(std::ceil(right)) + 1);
    const int y1 = std::min(canvas_height, static_cast<int>(std::ceil(bottom)) + 1);
    width = std::max(0, x1 - x0);
    height = std::max(0, y1 - y0);
    values.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0.0f);
  }
  // Max-combines the coverage of a thick segment (so overlapping pieces do not darken).
  void add_segment(Point2 a, Point2 b, double width_px) {
    const double half = 0.5 * width_px + 1.0;
    const int xa = std::max(x0, static_cast<int>(std::floor(std::min(a.x, b.x) - half)));
    const int xb = std::min(x0 + width - 1, static_cast<int>(std::ceil(std::max(a.x, b.x) + half)));
    const int ya = std::max(y0, static_cast<int>(std::floor(std::min(a.y, b.y) - half)));
    const int yb = std::min(y0 + height - 1, static_cast<int>(std::ceil(std::max(a.y, b.y) + half)));
    for (int y = ya; y <= yb; ++y) {
      for (int x = xa; x <= xb; ++x) {
        const double d = segment_distance(x + 0.5, y + 0.5, a, b);
        const float c = clamp01(0.5 * width_px + 0.5 - d);
        float& v = values[static_cast<std::size_t>((y - y0) * width + (x - x0))];
        v = std::max(v, c);
      }
    }
  }
};

// Splits a polyline into the pieces a dash pattern keeps.
std::vector<std::pair<Point2, Point2>> dashed_pieces(std::span<const Point2> points, double dash, double gap) {
  std::vector<std::pair<Point2, Point2>> pieces;
  bool on = true;
  double left = dash;  // length left in the current dash or gap
  for (std::size_t i = 1; i < points.size(); ++i) {
    Point2 a = points[i - 1];
    const Point2 b = points[i];
    double length = std::hypot(b.x - a.x, b.y - a.y);
    while (length > 0.0) {
      const double take = std::min(left, length);
      const double t = take / length;
      const Point2 m{a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t};
      if (on) pieces.push_back({a, m});
      a = m;
      length -= take;
      left -= take;
      if (left <= 0.0) {
        on = !on;
        left = on ? dash : gap;
      }
    }
  }
  return pieces;
}

// A UTF-8 string as pieces the FreeType path can draw (ASCII) and glyphs drawn by hand.
struct TextPiece {
  enum class Kind { Ascii, Micro, Degree, Lambda, PlusMinus } kind = Kind::Ascii;
  std::string ascii;
};

std::vector<TextPiece> split_text(std::string_view s) {
  std::vector<TextPiece> out;
  auto ascii = [&](char c) {
    if (out.empty() || out.back().kind != TextPiece::Kind::Ascii) out.push_back({TextPiece::Kind::Ascii, {}});
    out.back().ascii += c;
  };
  for (std::size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x80) {
      ascii(static_cast<char>(c));
      ++i;
      continue;
    }
    std::size_t len = c >= 0xF0 ? 4 : c >= 0xE0 ? 3 : c >= 0xC0 ? 2 : 1;
    const std::string_view seq = s.substr(i, len);
    if (seq == "\xC2\xB5" || seq == "\xCE\xBC") {
      out.push_back({TextPiece::Kind::Micro, {}});
    } else if (seq == "\xC2\xB0") {
      out.push_back({TextPiece::Kind::Degree, {}});
    } else if (seq == "\xCE\xBB") {
      out.push_back({TextPiece::Kind::Lambda, {}});
    } else if (seq == "\xE2\x88\x92") {
      ascii('-');
    } else if (seq == "\xC2\xB1") {
      out.push_back({TextPiece::Kind::PlusMinus, {}});
    } else {
      ascii('?');
    }
    i += len;
  }
  return out;
}

// Advance width of ASCII text: the box of text + "x" minus the box of "x", so spaces count.
double ascii_advance(const std::string& text, int size, const std::string& font) {
  if (text.empty()) return 0.0;
  const OIIO::ROI with = OIIO::ImageBufAlgo::text_size(text + "x", size, font);
  const OIIO::ROI x = OIIO::ImageBufAlgo::text_size("x", size, font);
  if (!with.defined() || !x.defined()) return 0.0;
  return static_cast<double>(with.xend - x.xend);
}

double piece_advance(const TextPiece& p, int size, const std::string& font) {
  switch (p.kind) {
    case TextPiece::Kind::Ascii: return ascii_advance(p.ascii, size, font);
    case TextPiece::Kind::Micro: return ascii_advance("u", size, font);
    case TextPiece::Kind::Degree: return 0.42 * size;
    case TextPiece::Kind::Lambda: return ascii_advance("v", size, font);
    case TextPiece::Kind::PlusMinus: return ascii_advance("+", size, font);
  }
  return 0.0;
}

}  // namespace

Canvas::Canvas(int width_px, int height_px, Rgb background) : width_(width_px), height_(height_px) {
  if (width_px < 1 || width_px > 16384 || height_px < 1 || height_px > 16384) {
    throw OptionsError("Canvas size " + std::to_string(width_px) + " x " + std::to_string(height_px) + ": each side must be 1 to 16384 px");
  }
  pixels_.resize(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) * 3);
  for (std::size_t i = 0; i < pixels_.size(); i += 3) {
    pixels_[i] = background.r;
    pixels_[i + 1] = background.g;
    pixels_[i + 2] = background.b;
  }
}

std::optional<std::string> Canvas::find_default_font() {
  for (const char* path : {"/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf", "/usr/share/fonts/TTF/DejaVuSans.ttf",
                           "/usr/share/fonts/dejavu/DejaVuSans.ttf", "/usr/local/share/fonts/DejaVuSans.ttf",
                           "/Library/Fonts/DejaVuSans.ttf"}) {
    std::error_code ec;
    if (std::filesystem::is_regular_file(path, ec)) return std::string(path);
  }
  return std::nullopt;
}

Rgb Canvas::pixel(int x, int y) const {
  const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)) * 3;
  return {pixels_.at(i), pixels_.at(i + 1), pixels_.at(i + 2)};
}

void Canvas::blend(int x, int y, Rgb c, float alpha) {
  if (x < 0 || y < 0 || x >= width_ || y >= height_ || alpha <= 0.0f) return;
  alpha = std::min(alpha, 1.0f);
  const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)) * 3;
  pixels_[i] += (c.r - pixels_[i]) * alpha;
  pixels_[i + 1] += (c.g - pixels_[i + 1]) * alpha;
  pixels_[i + 2] += (c.b - pixels_[i + 2]) * alpha;
}

void Canvas::blend_mask(const std::vector<float>& mask, int mask_width, int mask_height, int x0, int y0, Rgb colour) {
  for (int y = 0; y < mask_height; ++y) {
    for (int x = 0; x < mask_width; ++x) blend(x0 + x, y0 + y, colour, mask[static_cast<std::size_t>(y * mask_width + x)]);
  }
}

void Canvas::line(Point2 a, Point2 b, const LineStyle& style) {
  const Point2 points[2] = {a, b};
  polyline(points, style);
}

void Canvas::polyline(std::span<const Point2> points, const LineStyle& style) {
  if (points.size() < 2 || !(style.width_px > 0.0)) return;
  double left = points[0].x, right = points[0].x, top = points[0].y, bottom = points[0].y;
  for (const Point2& p : points) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) return;
    left = std::min(left, p.x);
    right = std::max(right, p.x);
    top = std::min(top, p.y);
    bottom = std::max(bottom, p.y);
  }
  const double pad = 0.5 * style.width_px + 2.0;
  Mask mask(left - pad, top - pad, right + pad, bottom + pad, width_, height_);
  if (mask.width == 0 || mask.height == 0) return;
  if (style.dash_px > 0.0) {
    for (const auto& [a, b] : dashed_pieces(points, style.dash_px, std::max(style.gap_px, 0.5))) mask.add_segment(a, b, style.width_px);
  } else {
    for (std::size_t i = 1; i < points.size(); ++i) mask.add_segment(points[i - 1], points[i], style.width_px);
  }
  blend_mask(mask.values, mask.width, mask.height, mask.x0, mask.y0, style.colour);
}

void Canvas::fill_disc(Point2 centre, double radius_px, Rgb colour) {
  if (!(radius_px > 0.0) || !std::isfinite(centre.x) || !std::isfinite(centre.y)) return;
  const int xa = static_cast<int>(std::floor(centre.x - radius_px - 1.0)), xb = static_cast<int>(std::ceil(centre.x + radius_px + 1.0));
  const int ya = static_cast<int>(std::floor(centre.y - radius_px - 1.0)), yb = static_cast<int>(std::ceil(centre.y + radius_px + 1.0));
  for (int y = std::max(0, ya); y <= std::min(height_ - 1, yb); ++y) {
    for (int x = std::max(0, xa); x <= std::min(width_ - 1, xb); ++x) {
      const double d = std::hypot(x + 0.5 - centre.x, y + 0.5 - centre.y);
      // A disc smaller than a pixel keeps its area as coverage, so tiny dots stay visible but faint.
      const double peak = std::min(1.0, kPi * radius_px * radius_px);
      blend(x, y, colour, clamp01(std::min(peak, radius_px + 0.5 - d)));
    }
  }
}

void Canvas::circle(Point2 centre, double radius_px, const LineStyle& style) {
  if (!(radius_px > 0.0)) return;
  const int segments = std::clamp(static_cast<int>(radius_px * 1.5), 24, 720);
  std::vector<Point2> points;
  for (int i = 0; i <= segments; ++i) {
    const double phi = 2.0 * kPi * i / segments;
    points.push_back({centre.x + radius_px * std::cos(phi), centre.y + radius_px * std::sin(phi)});
  }
  polyline(points, style);
}

void Canvas::fill_rect(Point2 top_left, Point2 bottom_right, Rgb colour) {
  const double x0 = std::min(top_left.x, bottom_right.x), x1 = std::max(top_left.x, bottom_right.x);
  const double y0 = std::min(top_left.y, bottom_right.y), y1 = std::max(top_left.y, bottom_right.y);
  for (int y = std::max(0, static_cast<int>(std::floor(y0))); y < std::min(height_, static_cast<int>(std::ceil(y1))); ++y) {
    const double cy = std::min(y1, y + 1.0) - std::max(y0, static_cast<double>(y));
    for (int x = std::max(0, static_cast<int>(std::floor(x0))); x < std::min(width_, static_cast<int>(std::ceil(x1))); ++x) {
      const double cx = std::min(x1, x + 1.0) - std::max(x0, static_cast<double>(x));
      blend(x, y, colour, clamp01(cx * cy));
    }
  }
}

void Canvas::rect(Point2 top_left, Point2 bottom_right, const LineStyle& style) {
  const Point2 points[5] = {top_left, {bottom_right.x, top_left.y}, bottom_right, {top_left.x, bottom_right.y}, top_left};
  polyline(points, style);
}

double Canvas::text_width(std::string_view utf8, double size_px) const {
  if (!font_) return 0.0;
  const int size = std::max(1, static_cast<int>(std::lround(size_px)));
  double w = 0.0;
  for (const TextPiece& p : split_text(utf8)) w += piece_advance(p, size, *font_);
  return w;
}

void Canvas::text(Point2 anchor, std::string_view utf8, double size_px, Rgb colour, HAlign h, VAlign v, bool vertical) {
  if (!font_ || utf8.empty()) return;
  const int size = std::max(1, static_cast<int>(std::lround(size_px)));
  const std::vector<TextPiece> pieces = split_text(utf8);
  double total = 0.0;
  for (const TextPiece& p : pieces) total += piece_advance(p, size, *font_);
  // Ascent and descent of the font at this size, from tall and deep letters.
  const OIIO::ROI box = OIIO::ImageBufAlgo::text_size("Ahgjy", size, *font_);
  if (!box.defined()) return;
  const int ascent = -box.ybegin + 1;
  const int descent = box.yend + 1;
  const int pad = 2;
  const int mask_width = static_cast<int>(std::ceil(total)) + 2 * pad + size / 2;
  const int mask_height = ascent + descent + 2 * pad;
  std::vector<float> mask(static_cast<std::size_t>(mask_width) * static_cast<std::size_t>(mask_height), 0.0f);
  {
    OIIO::ImageBuf buffer(OIIO::ImageSpec(mask_width, mask_height, 1, OIIO::TypeDesc::FLOAT), mask.data());
    const float white[1] = {1.0f};
    const int baseline = pad + ascent;
    double x = pad;
    auto stroke = [&](Point2 a, Point2 b, double width) {
      Mask m(0, 0, mask_width - 1, mask_height - 1, mask_width, mask_height);
      m.add_segment(a, b, width);
      for (std::size_t i = 0; i < mask.size(); ++i) mask[i] = std::max(mask[i], m.values[i]);
    };
    for (const TextPiece& p : pieces) {
      const double advance = piece_advance(p, size, *font_);
      switch (p.kind) {
        case TextPiece::Kind::Ascii:
          OIIO::ImageBufAlgo::render_text(buffer, static_cast<int>(std::lround(x)), baseline, p.ascii, size, *font_, white);
          break;
        case TextPiece::Kind::Micro: {
          // A 'u' with a descender on its left stem: the micro sign.
          OIIO::ImageBufAlgo::render_text(buffer, static_cast<int>(std::lround(x)), baseline, "u", size, *font_, white);
          const OIIO::ROI u = OIIO::ImageBufAlgo::text_size("u", size, *font_);
          const double stem_x = std::round(x) + u.xbegin + 0.055 * size;
          stroke({stem_x, baseline - 0.3 * size}, {stem_x, baseline + 0.21 * size}, 0.095 * size);
          break;
        }
        case TextPiece::Kind::Degree: {
          const double r = 0.11 * size;
          const Point2 c{x + 0.2 * size, baseline - 0.62 * size};
          for (int i = 0; i < 24; ++i) {
            const double a0 = 2.0 * kPi * i / 24, a1 = 2.0 * kPi * (i + 1) / 24;
            stroke({c.x + r * std::cos(a0), c.y + r * std::sin(a0)}, {c.x + r * std::cos(a1), c.y + r * std::sin(a1)}, 0.07 * size);
          }
          break;
        }
        case TextPiece::Kind::Lambda: {
          // Two strokes: the long one from the top left to the bottom right, a short leg to the left.
          const double top = baseline - 0.74 * size, w = advance;
          stroke({x + 0.12 * w, top}, {x + 0.9 * w, static_cast<double>(baseline)}, 0.085 * size);
          stroke({x + 0.52 * w, baseline - 0.42 * size}, {x + 0.1 * w, static_cast<double>(baseline)}, 0.085 * size);
          break;
        }
        case TextPiece::Kind::PlusMinus: {
          // A plus raised a little, with a bar under it.
          const OIIO::ROI plus = OIIO::ImageBufAlgo::text_size("+", size, *font_);
          OIIO::ImageBufAlgo::render_text(buffer, static_cast<int>(std::lround(x)), baseline - static_cast<int>(std::lround(0.1 * size)), "+",
                                          size, *font_, white);
          const double bar_y = baseline - 0.03 * size;
          stroke({std::round(x) + plus.xbegin, bar_y}, {std::round(x) + plus.xend, bar_y}, 0.075 * size);
          break;
        }
      }
      x += advance;
    }
  }
  // Place the mask: offsets of the anchor inside the mask, then rotate for vertical text.
  double ax = pad;
  if (h == HAlign::Centre) ax = pad + 0.5 * total;
  if (h == HAlign::Right) ax = pad + total;
  double ay = pad + ascent;  // baseline
  if (v == VAlign::Top) ay = pad;
  if (v == VAlign::Middle) ay = pad + 0.5 * (ascent + 0.35 * size);  // middle of the capital letters
  if (v == VAlign::Bottom) ay = pad + ascent + descent;
  if (!vertical) {
    blend_mask(mask, mask_width, mask_height, static_cast<int>(std::lround(anchor.x - ax)), static_cast<int>(std::lround(anchor.y - ay)),
               colour);
    return;
  }
  // Rotated 90 degrees counter-clockwise: mask (u, w) -> canvas (x0 + w, y0 - u), centred along its length.
  const double cu = pad + 0.5 * total;
  const int x0 = static_cast<int>(std::lround(anchor.x - ay));
  const int y0 = static_cast<int>(std::lround(anchor.y + cu));
  for (int w = 0; w < mask_height; ++w) {
    for (int u = 0; u < mask_width; ++u) blend(x0 + w, y0 - u, colour, mask[static_cast<std::size_t>(w * mask_width + u)]);
  }
}

Canvas Canvas::read_image(const std::string& path) {
  OIIO::ImageBuf buffer(path);
  if (!buffer.read(0, 0, true, OIIO::TypeDesc::FLOAT)) throw IoError(path + ": cannot read the image: " + buffer.geterror());
  const OIIO::ImageSpec& spec = buffer.spec();
  if (spec.width < 1 || spec.height < 1 || spec.width > 16384 || spec.height > 16384 || spec.nchannels < 1) {
    throw IoError(path + ": image of " + std::to_string(spec.width) + " x " + std::to_string(spec.height) + " pixels and " +
                  std::to_string(spec.nchannels) + " channels: not a picture lensmith can read");
  }
  Canvas canvas(spec.width, spec.height);
  std::vector<float> pixel(static_cast<std::size_t>(spec.nchannels));
  for (int y = 0; y < spec.height; ++y) {
    for (int x = 0; x < spec.width; ++x) {
      buffer.getpixel(spec.x + x, spec.y + y, pixel.data(), spec.nchannels);
      const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(spec.width) + static_cast<std::size_t>(x)) * 3;
      for (std::size_t c = 0; c < 3; ++c) canvas.pixels_[i + c] = pixel[std::min(c, pixel.size() - 1)];
    }
  }
  return canvas;
}

void Canvas::write_png(const std::string& path) const {
  // The temporary name ends in .png so OpenImageIO picks the format.
  write_atomically(path, ".png", [&](const std::string& temporary) {
    // OIIO only reads the buffer; the const_cast is for its wrapping constructor's signature.
    OIIO::ImageBuf buffer(OIIO::ImageSpec(width_, height_, 3, OIIO::TypeDesc::FLOAT), const_cast<float*>(pixels_.data()));
    if (!buffer.write(temporary, OIIO::TypeDesc::UINT8, "png")) {
      throw IoError(path + ": cannot write the PNG image: " + buffer.geterror());
    }
  });
}

}  // namespace lensmith::plot
