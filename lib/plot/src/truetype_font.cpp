// TrueType glyphs through stb_truetype (Sean Barrett's single-file rasteriser, the copy in Debian's
// libstb-dev): the font's own outlines, anti-aliased by exact area coverage, positioned to a
// fraction of a pixel. A code point the font lacks is drawn as '?'.
#define STBTT_STATIC
#define STB_TRUETYPE_IMPLEMENTATION
#include <stb_truetype.h>

#include "truetype_font.h"

#include <algorithm>

#include "lensmith/core/errors.h"
#include "lensmith/core/text_file.h"

namespace lensmith::plot {

struct TrueTypeFont::Face {
  std::string bytes;  // stb_truetype reads the font in place: it must outlive `info`
  stbtt_fontinfo info{};

  int glyph(char32_t c) const {
    const int index = stbtt_FindGlyphIndex(&info, static_cast<int>(c));
    return index != 0 ? index : stbtt_FindGlyphIndex(&info, '?');
  }
  float scale(double size_px) const { return stbtt_ScaleForMappingEmToPixels(&info, static_cast<float>(size_px)); }
};

TrueTypeFont::TrueTypeFont(std::unique_ptr<Face> face) : face_(std::move(face)) {}
TrueTypeFont::~TrueTypeFont() = default;

std::shared_ptr<const TrueTypeFont> TrueTypeFont::load(const std::string& path) {
  auto face = std::make_unique<Face>();
  face->bytes = read_file_bytes(path);
  const auto* data = reinterpret_cast<const unsigned char*>(face->bytes.data());
  const int offset = stbtt_GetFontOffsetForIndex(data, 0);
  if (offset < 0 || stbtt_InitFont(&face->info, data, offset) == 0) {
    throw IoError(path + ": not a TrueType or OpenType font that lensmith can draw text with; set another font");
  }
  return std::shared_ptr<const TrueTypeFont>(new TrueTypeFont(std::move(face)));
}

double TrueTypeFont::advance_px(char32_t c, char32_t next, double size_px) const {
  const int glyph = face_->glyph(c);
  int advance = 0, left_bearing = 0;
  stbtt_GetGlyphHMetrics(&face_->info, glyph, &advance, &left_bearing);
  const int kern = next != 0 ? stbtt_GetGlyphKernAdvance(&face_->info, glyph, face_->glyph(next)) : 0;
  return static_cast<double>(advance + kern) * face_->scale(size_px);
}

GlyphMask TrueTypeFont::render(char32_t c, double size_px, double shift_px) const {
  const int glyph = face_->glyph(c);
  const float scale = face_->scale(size_px);
  const auto shift = static_cast<float>(shift_px);
  GlyphMask mask;
  int x1 = 0, y1 = 0;
  stbtt_GetGlyphBitmapBoxSubpixel(&face_->info, glyph, scale, scale, shift, 0.0f, &mask.left, &mask.top, &x1, &y1);
  mask.width = std::max(0, x1 - mask.left);
  mask.height = std::max(0, y1 - mask.top);
  if (mask.width == 0 || mask.height == 0) return mask;  // a space
  std::vector<unsigned char> bitmap(static_cast<std::size_t>(mask.width) * static_cast<std::size_t>(mask.height));
  stbtt_MakeGlyphBitmapSubpixel(&face_->info, bitmap.data(), mask.width, mask.height, mask.width, scale, scale, shift, 0.0f,
                                glyph);
  mask.coverage.resize(bitmap.size());
  std::transform(bitmap.begin(), bitmap.end(), mask.coverage.begin(), [](unsigned char v) { return static_cast<float>(v) / 255.0f; });
  return mask;
}

InkBox TrueTypeFont::ink_box(std::u32string_view text, double size_px) const {
  const float scale = face_->scale(size_px);
  InkBox box;
  bool first = true;
  for (const char32_t c : text) {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    stbtt_GetGlyphBitmapBox(&face_->info, face_->glyph(c), scale, scale, &x0, &y0, &x1, &y1);
    if (x1 <= x0 || y1 <= y0) continue;
    box = first ? InkBox{x0, y0, x1, y1} : InkBox{std::min(box.x0, x0), std::min(box.y0, y0), std::max(box.x1, x1), std::max(box.y1, y1)};
    first = false;
  }
  return box;
}

std::u32string decode_utf8(std::string_view utf8) {
  std::u32string out;
  for (std::size_t i = 0; i < utf8.size();) {
    const auto lead = static_cast<unsigned char>(utf8[i]);
    const std::size_t length = lead < 0x80 ? 1 : (lead >> 5) == 0x6 ? 2 : (lead >> 4) == 0xE ? 3 : (lead >> 3) == 0x1E ? 4 : 0;
    char32_t c = length == 1 ? lead : length == 2 ? lead & 0x1Fu : length == 3 ? lead & 0x0Fu : lead & 0x07u;
    bool valid = length != 0 && i + length <= utf8.size();
    for (std::size_t k = 1; valid && k < length; ++k) {
      const auto next = static_cast<unsigned char>(utf8[i + k]);
      valid = (next >> 6) == 0x2;
      c = (c << 6) | (next & 0x3Fu);
    }
    out.push_back(valid ? c : U'\uFFFD');
    i += valid ? length : 1;
  }
  return out;
}

}  // namespace lensmith::plot
