// A small raster canvas for analysis plots: an RGB float image with anti-aliased thick lines
// (coverage from the distance to each segment, so joints are not drawn twice), filled discs and
// rectangles, and anti-aliased TrueType text (stb_truetype, the font's own outlines). Pixel
// coordinates: origin at the top-left corner, x to the right, y down; pixel (i, j) covers
// [i, i + 1) x [j, j + 1). Written to PNG atomically (a temporary file in the same folder, renamed).
#pragma once

#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace lensmith::plot {

class TrueTypeFont;

struct Rgb {
  float r = 0.0f;
  float g = 0.0f;
  float b = 0.0f;
  friend bool operator==(const Rgb&, const Rgb&) = default;
};

inline constexpr Rgb kWhite{1.0f, 1.0f, 1.0f};
inline constexpr Rgb kBlack{0.0f, 0.0f, 0.0f};

struct Point2 {
  double x = 0.0;  // pixels
  double y = 0.0;
};

struct LineStyle {
  Rgb colour = kBlack;
  double width_px = 1.5;  // full width, > 0
  double dash_px = 0.0;   // dash length; 0 = solid
  double gap_px = 0.0;    // gap between dashes
};

// A pixel rectangle [x0, x1) x [y0, y1): where a label was drawn (Canvas::text_boxes).
struct PixelBox {
  double x0 = 0.0, y0 = 0.0, x1 = 0.0, y1 = 0.0;
  bool intersects(const PixelBox& o) const { return x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1; }
};

enum class HAlign { Left, Centre, Right };
enum class VAlign { Top, Middle, Baseline, Bottom };

class Canvas {
 public:
  // Throws OptionsError unless 1 <= width, height <= 16384.
  Canvas(int width_px, int height_px, Rgb background = kWhite);

  int width() const { return width_; }
  int height() const { return height_; }
  Rgb pixel(int x, int y) const;  // for tests; x, y inside the canvas

  // Font for text: a TrueType (or OpenType) file, read here. Empty: text calls draw nothing (pictures
  // without labels). Throws IoError naming the file when it cannot be read or is not such a font.
  // The rasteriser (stb_truetype) trusts the font's tables: give it installed fonts, not untrusted files.
  void set_font(std::optional<std::string> font_path);
  const std::optional<std::string>& font() const { return font_; }
  bool has_font() const { return font_.has_value(); }
  // DejaVu Sans from the usual system folders (Debian fonts-dejavu-core), or empty when not found.
  static std::optional<std::string> find_default_font();

  void line(Point2 a, Point2 b, const LineStyle& style);
  // Consecutive points joined; a dash pattern continues across vertices.
  void polyline(std::span<const Point2> points, const LineStyle& style);
  void fill_disc(Point2 centre, double radius_px, Rgb colour);
  void circle(Point2 centre, double radius_px, const LineStyle& style);
  void fill_rect(Point2 top_left, Point2 bottom_right, Rgb colour);
  // The inside of a closed polygon (even-odd rule, the last point joined to the first), anti-aliased
  // along y by 4 sub-rows per pixel and along x by the exact coverage of each span's end pixels.
  void fill_polygon(std::span<const Point2> points, Rgb colour);
  void rect(Point2 top_left, Point2 bottom_right, const LineStyle& style);

  // UTF-8 text at size_px (the em height, rounded to whole pixels), kerned; any letter the font
  // has is drawn (DejaVu Sans has micro, degree, plus-minus, the minus sign and lambda), others as
  // '?'. `vertical`: rotated to read bottom to top, centred on `anchor` along its length. No-op
  // without a font.
  void text(Point2 anchor, std::string_view utf8, double size_px, Rgb colour, HAlign h = HAlign::Left,
            VAlign v = VAlign::Baseline, bool vertical = false);
  // Width of `utf8` drawn at `size_px`, pixels (0 without a font).
  double text_width(std::string_view utf8, double size_px) const;
  // The box of every label drawn so far (advance width by ascent + descent; rotated for vertical
  // text), with its text: pictures are tested for labels that collide.
  struct TextBox {
    PixelBox box;
    std::string text;
  };
  const std::vector<TextBox>& text_boxes() const { return text_boxes_; }

  // Copies `picture`'s pixels with its top-left corner at (x0, y0), clipped to this canvas (contact
  // sheets of rendered pictures).
  void paste(const Canvas& picture, int x0, int y0);

  // Writes an 8-bit sRGB-encoded PNG through a temporary file in the same folder and a rename.
  // Throws IoError naming the path.
  void write_png(const std::string& path) const;
  // Reads an image file (any format lensmith::imageio reads: kReadableImageFormats) as a canvas:
  // the first three channels, or the first one repeated for gray (+ alpha); integers by their full
  // scale, no colour conversion. For tests and reference pictures. Throws IoError naming the path.
  static Canvas read_image(const std::string& path);

 private:
  // Blends `colour` over the pixel with coverage `alpha` in [0, 1].
  void blend(int x, int y, Rgb colour, float alpha);
  // Blends a coverage mask (mask_width x mask_height, row-major) whose top-left is at (x0, y0).
  void blend_mask(const std::vector<float>& mask, int mask_width, int mask_height, int x0, int y0, Rgb colour);

  int width_ = 0;
  int height_ = 0;
  std::vector<float> pixels_;  // RGB, row-major, linear values in [0, 1] treated as display values
  std::optional<std::string> font_;
  std::shared_ptr<const TrueTypeFont> face_;
  std::vector<TextBox> text_boxes_;  // font_ parsed; shared by copies of the canvas
};

}  // namespace lensmith::plot
