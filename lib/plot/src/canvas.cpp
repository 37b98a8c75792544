// Raster primitives with coverage-based anti-aliasing, TrueType text (stb_truetype) and PNG files
// (lensmith::imageio).
#include "lensmith/plot/canvas.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <system_error>

#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"
#include "lensmith/imageio/image_file.h"
#include "truetype_font.h"

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

// Width of a run of code points: the advances, with kerning between neighbours.
double run_width(const TrueTypeFont& font, std::u32string_view text, double size_px) {
  double width = 0.0;
  for (std::size_t i = 0; i < text.size(); ++i) width += font.advance_px(text[i], i + 1 < text.size() ? text[i + 1] : 0, size_px);
  return width;
}

// Labels are drawn at whole pixel sizes, as they were when FreeType (through OpenImageIO) drew them.
int font_size(double size_px) { return std::max(1, static_cast<int>(std::lround(size_px))); }

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

void Canvas::fill_polygon(std::span<const Point2> points, Rgb colour) {
  if (points.size() < 3) return;
  double top = points[0].y, bottom = points[0].y;
  for (const Point2& p : points) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) return;
    top = std::min(top, p.y);
    bottom = std::max(bottom, p.y);
  }
  constexpr int kSubRows = 4;
  std::vector<float> row(static_cast<std::size_t>(width_));
  std::vector<double> crossings;
  for (int y = std::max(0, static_cast<int>(std::floor(top))); y < std::min(height_, static_cast<int>(std::ceil(bottom)) + 1); ++y) {
    std::fill(row.begin(), row.end(), 0.0f);
    for (int s = 0; s < kSubRows; ++s) {
      const double sy = y + (s + 0.5) / kSubRows;
      crossings.clear();
      for (std::size_t i = 0; i < points.size(); ++i) {
        const Point2 a = points[i], b = points[(i + 1) % points.size()];
        if ((a.y <= sy) != (b.y <= sy)) crossings.push_back(a.x + (sy - a.y) / (b.y - a.y) * (b.x - a.x));
      }
      std::sort(crossings.begin(), crossings.end());
      for (std::size_t i = 0; i + 1 < crossings.size(); i += 2) {
        const double x0 = std::clamp(crossings[i], 0.0, static_cast<double>(width_));
        const double x1 = std::clamp(crossings[i + 1], 0.0, static_cast<double>(width_));
        for (int x = static_cast<int>(std::floor(x0)); x < static_cast<int>(std::ceil(x1)) && x < width_; ++x) {
          row[static_cast<std::size_t>(x)] += static_cast<float>((std::min(x1, x + 1.0) - std::max(x0, static_cast<double>(x))) / kSubRows);
        }
      }
    }
    for (int x = 0; x < width_; ++x) blend(x, y, colour, row[static_cast<std::size_t>(x)]);
  }
}

void Canvas::rect(Point2 top_left, Point2 bottom_right, const LineStyle& style) {
  const Point2 points[5] = {top_left, {bottom_right.x, top_left.y}, bottom_right, {top_left.x, bottom_right.y}, top_left};
  polyline(points, style);
}

void Canvas::set_font(std::optional<std::string> font_path) {
  face_ = font_path ? TrueTypeFont::load(*font_path) : nullptr;
  font_ = std::move(font_path);
}

double Canvas::text_width(std::string_view utf8, double size_px) const {
  if (!face_) return 0.0;
  return run_width(*face_, decode_utf8(utf8), font_size(size_px));
}

void Canvas::text(Point2 anchor, std::string_view utf8, double size_px, Rgb colour, HAlign h, VAlign v, bool vertical) {
  if (!face_ || utf8.empty()) return;
  const int size = font_size(size_px);
  const std::u32string codepoints = decode_utf8(utf8);
  const double total = run_width(*face_, codepoints, size);
  // Ascent and descent of the font at this size, from tall and deep letters.
  const InkBox box = face_->ink_box(U"Ahgjy", size);
  const int ascent = -box.y0 + 1;
  const int descent = box.y1 + 1;
  const int pad = 2;
  const int mask_width = static_cast<int>(std::ceil(total)) + 2 * pad + size / 2;
  const int mask_height = ascent + descent + 2 * pad;
  std::vector<float> mask(static_cast<std::size_t>(mask_width) * static_cast<std::size_t>(mask_height), 0.0f);
  const int baseline = pad + ascent;
  double pen = pad;
  for (std::size_t i = 0; i < codepoints.size(); ++i) {
    const double whole = std::floor(pen);
    const GlyphMask glyph = face_->render(codepoints[i], size, pen - whole);
    for (int gy = 0; gy < glyph.height; ++gy) {
      const int my = baseline + glyph.top + gy;
      if (my < 0 || my >= mask_height) continue;
      for (int gx = 0; gx < glyph.width; ++gx) {
        const int mx = static_cast<int>(whole) + glyph.left + gx;
        if (mx < 0 || mx >= mask_width) continue;
        // Neighbouring glyphs that touch a pixel cover it together: coverage composited "over".
        float& m = mask[static_cast<std::size_t>(my * mask_width + mx)];
        const float g = glyph.coverage[static_cast<std::size_t>(gy * glyph.width + gx)];
        m += g * (1.0f - m);
      }
    }
    pen += face_->advance_px(codepoints[i], i + 1 < codepoints.size() ? codepoints[i + 1] : 0, size);
  }
  // Place the mask: offsets of the anchor inside the mask, then rotate for vertical text.
  double ax = pad;
  if (h == HAlign::Centre) ax = pad + 0.5 * total;
  if (h == HAlign::Right) ax = pad + total;
  double ay = pad + ascent;  // baseline
  if (v == VAlign::Top) ay = pad;
  if (v == VAlign::Middle) ay = pad + 0.5 * (ascent + 0.35 * size);  // middle of the capital letters
  if (v == VAlign::Bottom) ay = pad + ascent + descent;
  const double ink_top = pad + 1.0, ink_bottom = pad + ascent + descent - 1.0;  // rows between the tallest and deepest letters
  if (!vertical) {
    const double left = static_cast<double>(std::lround(anchor.x - ax)) + pad, top = static_cast<double>(std::lround(anchor.y - ay));
    text_boxes_.push_back({{left, top + ink_top, left + total, top + ink_bottom}, std::string(utf8)});
    blend_mask(mask, mask_width, mask_height, static_cast<int>(std::lround(anchor.x - ax)), static_cast<int>(std::lround(anchor.y - ay)),
               colour);
    return;
  }
  // Rotated 90 degrees counter-clockwise: mask (u, w) -> canvas (x0 + w, y0 - u), centred along its length.
  const double cu = pad + 0.5 * total;
  const int x0 = static_cast<int>(std::lround(anchor.x - ay));
  const int y0 = static_cast<int>(std::lround(anchor.y + cu));
  text_boxes_.push_back({{x0 + ink_top, y0 - pad - total, x0 + ink_bottom, static_cast<double>(y0 - pad)}, std::string(utf8)});
  for (int w = 0; w < mask_height; ++w) {
    for (int u = 0; u < mask_width; ++u) blend(x0 + w, y0 - u, colour, mask[static_cast<std::size_t>(w * mask_width + u)]);
  }
}

Canvas Canvas::read_image(const std::string& path) {
  RasterInfo info;
  Raster raster;
  try {
    info = read_raster_info(path);
    if (info.width > 16384 || info.height > 16384) {
      throw IoError(path + ": image of " + std::to_string(info.width) + " x " + std::to_string(info.height) +
                    " pixels: larger than a canvas (16384 x 16384)");
    }
    const int first_three[3] = {0, 1, 2}, grey[3] = {0, 0, 0};
    raster = read_raster(path, info, info.channels.size() >= 3 ? first_three : grey);
  } catch (const ImageFileError& e) {
    throw IoError(e.what());  // a deep or cropped picture: for a canvas, a file it cannot read
  }
  Canvas canvas(info.width, info.height);
  canvas.pixels_ = std::move(raster.samples);
  return canvas;
}

void Canvas::paste(const Canvas& picture, int x0, int y0) {
  for (int y = std::max(0, -y0); y < picture.height_ && y0 + y < height_; ++y) {
    for (int x = std::max(0, -x0); x < picture.width_ && x0 + x < width_; ++x) {
      const std::size_t from = 3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(picture.width_) + static_cast<std::size_t>(x));
      const std::size_t to = 3 * (static_cast<std::size_t>(y0 + y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x0 + x));
      for (std::size_t c = 0; c < 3; ++c) pixels_[to + c] = picture.pixels_[from + c];
    }
  }
}

void Canvas::write_png(const std::string& path) const {
  // Canvas values are display values: stored as 8-bit codes, rounded.
  std::vector<std::uint8_t> codes(pixels_.size());
  for (std::size_t i = 0; i < codes.size(); ++i) {
    codes[i] = static_cast<std::uint8_t>(std::lround(std::clamp(static_cast<double>(pixels_[i]), 0.0, 1.0) * 255.0));
  }
  lensmith::write_png(path, PixelsView<std::uint8_t>{width_, height_, 3, codes}, {});
}

}  // namespace lensmith::plot
