// JPEG decoding through libjpeg-turbo (the IJG libjpeg API, version 6b as Debian 12 builds it).
// stb_image decoded JPEG before: Debian 12's copy (git 2022-09-08) writes past a Huffman table when
// a DHT segment declares more than 256 codes, which lensmith's fuzzer found in an 18-byte file;
// libjpeg-turbo is fuzzed continuously by OSS-Fuzz and is what OpenImageIO reads JPEG with.
// libjpeg reports errors by longjmp, so its calls sit in functions whose frames hold no C++ object
// (as png_codec.cpp does for libpng); the C++ side (allocation, exceptions) stays outside them.
#include <cstddef>
#include <csetjmp>
#include <cstdio>
#include <memory>
#include <string>

// jpeglib.h needs size_t and FILE declared before it.
#include <jerror.h>
#include <jpeglib.h>

#include "codecs.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/text_file.h"

namespace lensmith::codecs {

namespace {

// Progressive JPEG lets a file ask for any number of scans, each a pass over the whole picture; a
// few hundred bytes can then keep a decoder busy for minutes. libjpeg-turbo's own fuzzers and
// its TurboJPEG API (TJPARAM_SCANLIMIT) stop at a limit; real encoders write at most a few dozen.
constexpr int kMaxScans = 500;

// libjpeg's error manager, the message of the error that stopped it, and where to jump back to.
struct JpegErrors {
  jpeg_error_mgr manager{};
  std::jmp_buf jump{};
  char message[JMSG_LENGTH_MAX] = {};
};

[[noreturn]] void keep_error_and_jump(j_common_ptr jpeg) {
  auto* errors = reinterpret_cast<JpegErrors*>(jpeg->err);
  (*jpeg->err->format_message)(jpeg, errors->message);
  std::longjmp(errors->jump, 1);
}

// libjpeg warns and goes on, filling with gray, where the entropy-coded data ends early (a
// truncated download) or is cut by a marker (a damaged file): that picture is not the file's, so
// those two are errors here. Its other warnings (stray bytes between segments, unusual but
// decodable parameters) leave the pixels whole and are passed over, as every viewer does.
void stop_on_missing_data(j_common_ptr jpeg, int level) {
  if (level < 0 && (jpeg->err->msg_code == JWRN_JPEG_EOF || jpeg->err->msg_code == JWRN_HIT_MARKER)) {
    keep_error_and_jump(jpeg);
  }
}

void limit_scans(j_common_ptr jpeg) {
  const auto* decompress = reinterpret_cast<j_decompress_ptr>(jpeg);
  if (jpeg->is_decompressor && decompress->input_scan_number > kMaxScans) {
    std::snprintf(reinterpret_cast<JpegErrors*>(jpeg->err)->message, JMSG_LENGTH_MAX,
                  "more than %d progressive scans (encoders write at most a few dozen): a damaged or hostile file", kMaxScans);
    std::longjmp(reinterpret_cast<JpegErrors*>(jpeg->err)->jump, 1);
  }
}

// One decompression: libjpeg's state, its error manager and its scan limit.
struct JpegReader {
  jpeg_decompress_struct jpeg{};
  JpegErrors errors;
  jpeg_progress_mgr progress{};
  bool created = false;
};

// Reads the header and chooses the output colour space: after it, jpeg.output_width/height/components
// say what read_jpeg_rows fills. Only the header: a progressive file's scans are all decoded by
// jpeg_start_decompress, which read_jpeg_rows calls, so asking for the size costs no decoding.
// False, with errors.message set, when libjpeg failed.
bool read_jpeg_header(JpegReader* reader, const unsigned char* bytes, std::size_t size) {
  j_decompress_ptr jpeg = &reader->jpeg;
  jpeg->err = jpeg_std_error(&reader->errors.manager);
  reader->errors.manager.error_exit = keep_error_and_jump;
  reader->errors.manager.emit_message = stop_on_missing_data;
  if (setjmp(reader->errors.jump) != 0) return false;
  jpeg_create_decompress(jpeg);
  reader->created = true;
  reader->progress.progress_monitor = limit_scans;
  jpeg->progress = &reader->progress;
  jpeg_mem_src(jpeg, bytes, static_cast<unsigned long>(size));
  jpeg_read_header(jpeg, TRUE);
  switch (jpeg->jpeg_color_space) {
    case JCS_GRAYSCALE: jpeg->out_color_space = JCS_GRAYSCALE; break;
    // Four channels are CMYK or YCCK (Adobe's APP14), which libjpeg hands out as CMYK.
    case JCS_CMYK:
    case JCS_YCCK: jpeg->out_color_space = JCS_CMYK; break;
    default: jpeg->out_color_space = JCS_RGB; break;
  }
  jpeg_calc_output_dimensions(jpeg);
  return true;
}

// Decodes every row into `pixels` (output_width x output_height x output_components bytes).
bool read_jpeg_rows(JpegReader* reader, unsigned char* pixels) {
  j_decompress_ptr jpeg = &reader->jpeg;
  if (setjmp(reader->errors.jump) != 0) return false;
  jpeg_start_decompress(jpeg);
  const std::size_t row_bytes = static_cast<std::size_t>(jpeg->output_width) * static_cast<std::size_t>(jpeg->output_components);
  while (jpeg->output_scanline < jpeg->output_height) {
    JSAMPROW row = pixels + static_cast<std::size_t>(jpeg->output_scanline) * row_bytes;
    jpeg_read_scanlines(jpeg, &row, 1);
  }
  jpeg_finish_decompress(jpeg);
  return true;
}

// A reader of `bytes` past their header; throws IoError naming the file when libjpeg refuses it.
std::unique_ptr<JpegReader, void (*)(JpegReader*)> reader_past_header(const fs::path& path, const std::string& bytes) {
  std::unique_ptr<JpegReader, void (*)(JpegReader*)> reader(new JpegReader, [](JpegReader* r) {
    if (r->created) jpeg_destroy_decompress(&r->jpeg);
    delete r;
  });
  if (!read_jpeg_header(reader.get(), reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size())) {
    throw IoError(path.string() + ": cannot read the JPEG image: " + reader->errors.message);
  }
  const int components = reader->jpeg.output_components;
  if (components != 1 && components != 3 && components != 4) {
    throw ImageFileError(path.string() + ": a JPEG of " + std::to_string(components) +
                         " components; lensmith reads gray (1), colour (3) and CMYK (4) JPEG");
  }
  return reader;
}

RasterInfo info_of(const JpegReader& reader) {
  RasterInfo info;
  info.format = ImageFormat::Jpeg;
  info.width = static_cast<int>(reader.jpeg.output_width);
  info.height = static_cast<int>(reader.jpeg.output_height);
  // CMYK is converted to RGB, as OpenImageIO and stb_image do.
  const std::vector<std::string> names = reader.jpeg.output_components == 1 ? std::vector<std::string>{"Y"}
                                                                            : std::vector<std::string>{"R", "G", "B"};
  for (const std::string& name : names) info.channels.push_back({name, SampleType::Uint8});
  return info;
}

}  // namespace

RasterInfo read_jpeg_info(const fs::path& path) {
  const std::string bytes = read_file_bytes(path.string());
  return info_of(*reader_past_header(path, bytes));
}

Decoded read_jpeg(const fs::path& path) {
  const std::string bytes = read_file_bytes(path.string());
  const auto reader = reader_past_header(path, bytes);
  Decoded decoded{info_of(*reader), {}};
  const std::size_t pixels = static_cast<std::size_t>(decoded.info.width) * static_cast<std::size_t>(decoded.info.height);
  const auto components = static_cast<std::size_t>(reader->jpeg.output_components);
  std::vector<unsigned char> bytes_out(pixels * components);
  if (!read_jpeg_rows(reader.get(), bytes_out.data())) {
    throw IoError(path.string() + ": cannot read the JPEG image: " + reader->errors.message);
  }
  const std::size_t channels = decoded.info.channels.size();
  decoded.samples.resize(pixels * channels);
  if (components == 4) {
    // Adobe's CMYK, stored inverted (255 is no ink) as every CMYK JPEG in practice is: the light
    // left is (stored C) x (stored K), the conversion stb_image and OpenImageIO make.
    for (std::size_t p = 0; p < pixels; ++p) {
      const unsigned char* cmyk = &bytes_out[p * 4];
      for (std::size_t c = 0; c < 3; ++c) {
        decoded.samples[p * 3 + c] = static_cast<float>(cmyk[c]) * static_cast<float>(cmyk[3]) / (255.0f * 255.0f);
      }
    }
  } else {
    for (std::size_t i = 0; i < bytes_out.size(); ++i) decoded.samples[i] = static_cast<float>(bytes_out[i]) / 255.0f;
  }
  return decoded;
}

}  // namespace lensmith::codecs
