// PNG chunks and output through libpng (PNG specification, 2nd edition: 11.3.3 gAMA and sRGB,
// 11.3.4 tEXt and iTXt). Pixels are decoded by stb_image (stb_codecs.cpp); libpng reads the chunks
// stb_image skips: the colour space and the text. libpng reports errors by longjmp, so its calls sit
// in functions whose frames hold no C++ object.
#include <png.h>

#include <algorithm>
#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <memory>

#include "codecs.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"

namespace lensmith::codecs {

namespace {

using File = std::unique_ptr<std::FILE, int (*)(std::FILE*)>;

// libpng's error callback: keeps the message and returns to the setjmp of the calling function.
void keep_error_and_jump(png_structp png, png_const_charp message) {
  *static_cast<std::string*>(png_get_error_ptr(png)) = message;
  png_longjmp(png, 1);
}

void ignore_warning(png_structp, png_const_charp) {}

// The standard keyword for a picture's description (PNG spec 11.3.4.2) and OpenImageIO's name for it.
constexpr const char* kPngDescription = "Description";
constexpr const char* kImageDescription = "ImageDescription";

bool is_ascii(const std::string& text) {
  return std::all_of(text.begin(), text.end(), [](char c) { return static_cast<unsigned char>(c) < 0x80; });
}

// The libpng calls of reading, in a frame of their own that holds no C++ object: libpng's longjmp
// comes back to the setjmp here and skips nothing that needs destroying. False, with `error` set,
// when libpng failed.
bool read_chunks(std::FILE* file, std::string* error, PngChunks* chunks) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, error, keep_error_and_jump, ignore_warning);
  if (png == nullptr) return false;
  png_infop info = png_create_info_struct(png);
  if (info == nullptr || setjmp(png_jmpbuf(png)) != 0) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  png_init_io(png, file);
  png_read_info(png, info);  // every chunk before the image data: where writers put colour and text
  // OpenImageIO's rule: an sRGB chunk means sRGB; otherwise a gAMA of exactly 1.0 means linear.
  png_fixed_point gamma = 0;
  chunks->linear = png_get_valid(png, info, PNG_INFO_sRGB) == 0 && png_get_gAMA_fixed(png, info, &gamma) != 0 &&
                   gamma == PNG_FP_1;
  png_textp text = nullptr;
  int count = 0;
  png_get_text(png, info, &text, &count);
  for (int i = 0; i < count; ++i) {
    const std::size_t length = text[i].compression >= PNG_ITXT_COMPRESSION_NONE ? text[i].itxt_length : text[i].text_length;
    chunks->text.emplace_back(std::strcmp(text[i].key, kPngDescription) == 0 ? kImageDescription : text[i].key,
                              std::string(text[i].text, length));
  }
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

// What write_png_file hands to libpng, made before any libpng call.
struct PngWriteJob {
  png_uint_32 width = 0;
  png_uint_32 height = 0;
  int colour_type = PNG_COLOR_TYPE_RGB;
  std::vector<png_text> texts;
  std::vector<png_bytep> rows;
};

// The libpng calls of writing, in a frame of their own (see read_chunks).
bool write_png_rows(std::FILE* file, std::string* error, PngWriteJob* job) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, error, keep_error_and_jump, ignore_warning);
  if (png == nullptr) return false;
  png_infop info = png_create_info_struct(png);
  if (info == nullptr || setjmp(png_jmpbuf(png)) != 0) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_init_io(png, file);
  png_set_IHDR(png, info, job->width, job->height, 8, job->colour_type, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  // The samples are sRGB codes: say so (sRGB with the gAMA and cHRM that older readers use).
  png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
  if (!job->texts.empty()) png_set_text(png, info, job->texts.data(), static_cast<int>(job->texts.size()));
  png_write_info(png, info);
  png_write_image(png, job->rows.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

}  // namespace

PngChunks read_png_chunks(const fs::path& path) {
  const File file(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!file) throw IoError(path.string() + ": cannot read the image: " + std::strerror(errno));
  std::string error = "out of memory";
  PngChunks chunks;
  if (!read_chunks(file.get(), &error, &chunks)) throw IoError(path.string() + ": cannot read the PNG image: " + error);
  return chunks;
}

void write_png_file(const fs::path& path, const std::string& file_name, const PixelsView<std::uint8_t>& pixels,
                    const std::vector<ImageAttribute>& attributes) {
  std::vector<std::string> keys, values;
  for (const ImageAttribute& attribute : attributes) {
    keys.push_back(attribute.name == kImageDescription ? kPngDescription : attribute.name);
    const auto* text = std::get_if<std::string>(&attribute.value);
    values.push_back(text != nullptr ? *text : format_number(std::get<double>(attribute.value)));
  }
  constexpr int kColourTypes[] = {PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA, PNG_COLOR_TYPE_RGB, PNG_COLOR_TYPE_RGB_ALPHA};
  PngWriteJob job;
  job.width = static_cast<png_uint_32>(pixels.width);
  job.height = static_cast<png_uint_32>(pixels.height);
  job.colour_type = kColourTypes[pixels.channels - 1];
  job.texts.resize(keys.size());
  for (std::size_t i = 0; i < keys.size(); ++i) {
    png_text& t = job.texts[i];
    t = png_text{};
    // tEXt holds Latin-1; text with other letters goes in an uncompressed UTF-8 iTXt chunk.
    const bool latin = is_ascii(values[i]);
    t.compression = latin ? PNG_TEXT_COMPRESSION_NONE : PNG_ITXT_COMPRESSION_NONE;
    t.key = keys[i].data();
    t.text = values[i].data();
    (latin ? t.text_length : t.itxt_length) = values[i].size();
  }
  const std::size_t row_bytes = static_cast<std::size_t>(pixels.width) * static_cast<std::size_t>(pixels.channels);
  for (std::size_t y = 0; y < job.height; ++y) {
    // libpng's row pointers are not const, but writing only reads them.
    job.rows.push_back(const_cast<png_bytep>(pixels.samples.data() + y * row_bytes));
  }

  File file(std::fopen(file_name.c_str(), "wb"), &std::fclose);
  if (!file) throw IoError(path.string() + ": cannot create the PNG image: " + std::strerror(errno));
  std::string error = "out of memory";
  if (!write_png_rows(file.get(), &error, &job)) throw IoError(path.string() + ": cannot write the PNG image: " + error);
  // A full disk shows up when the buffered bytes are flushed and the file is closed.
  std::FILE* raw = file.release();
  const bool failed = std::ferror(raw) != 0;
  if (std::fclose(raw) != 0 || failed) throw IoError(path.string() + ": cannot write the PNG image: " + std::strerror(errno));
}

}  // namespace lensmith::codecs
