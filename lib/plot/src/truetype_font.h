// A TrueType font for the canvas's labels, rasterised by stb_truetype: anti-aliased glyph coverage
// and metrics in pixels. A size is the em square's height in pixels, as FreeType's
// FT_Set_Pixel_Sizes takes it, so labels keep the sizes they had when OpenImageIO drew them.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace lensmith::plot {

// A glyph's coverage in [0, 1], row-major, and where its top-left pixel sits relative to the pen
// (on the baseline; y down, so `top` is negative for ink above the baseline).
struct GlyphMask {
  int left = 0;
  int top = 0;
  int width = 0;
  int height = 0;
  std::vector<float> coverage;
};

// The ink box of a glyph or a run of text relative to the pen at the baseline (y down), pixels.
struct InkBox {
  int x0 = 0;
  int y0 = 0;
  int x1 = 0;
  int y1 = 0;
};

class TrueTypeFont {
 public:
  // Reads and parses the font (the first face of a collection). Throws IoError naming the path when
  // the file cannot be read or is not a font stb_truetype can use.
  static std::shared_ptr<const TrueTypeFont> load(const std::string& path);
  ~TrueTypeFont();
  TrueTypeFont(const TrueTypeFont&) = delete;
  TrueTypeFont& operator=(const TrueTypeFont&) = delete;

  // Horizontal pen movement after `c` when `next` follows (0 = nothing follows), kerning included.
  double advance_px(char32_t c, char32_t next, double size_px) const;
  // The ink of `c` drawn with the pen `shift_px` (in [0, 1)) to the right of a pixel boundary.
  GlyphMask render(char32_t c, double size_px, double shift_px) const;
  // The union of the ink boxes of `text`'s glyphs, each drawn at the pen's start.
  InkBox ink_box(std::u32string_view text, double size_px) const;

 private:
  struct Face;
  explicit TrueTypeFont(std::unique_ptr<Face> face);
  std::unique_ptr<Face> face_;
};

// The code points of UTF-8 text; a malformed byte becomes U+FFFD.
std::u32string decode_utf8(std::string_view utf8);

}  // namespace lensmith::plot
