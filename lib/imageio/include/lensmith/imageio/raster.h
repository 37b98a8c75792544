// A flat picture as its file stores it: width x height pixels of named channels, each channel held
// as 8/16/32-bit unsigned integers or 16/32-bit IEEE floats. Raster carries the decoded samples as
// float (integers normalised to [0, 1] by their full scale), row-major, top row first, channels
// interleaved; RasterInfo is what the file's header says, enough to choose channels before decoding.
#pragma once

#include <cstddef>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "lensmith/core/errors.h"

namespace lensmith {

// An image or depth file was read but its contents are not what lensmith can use (a NaN pixel,
// a missing channel, integer depth, a size that does not match, a deep or cropped image): the
// message names the file, the pixel and value where there is one, and what to do. Files that
// cannot be opened or decoded at all are IoError.
class ImageFileError : public Error {
 public:
  using Error::Error;
};

// How a channel's samples are stored in the file.
enum class SampleType { Uint8, Uint16, Uint32, Half, Float };
// "uint8", "uint16", "uint32", "half", "float".
std::string to_string(SampleType type);
bool is_floating_point(SampleType type);

struct RasterChannel {
  std::string name;  // as the file names it ("R", "depth.Z"); Y, A, R, G, B for formats without names
  SampleType type = SampleType::Uint8;
};

// The file formats lensmith reads, recognised by their first bytes (never by the file name).
enum class ImageFormat { Exr, Tiff, Png, Jpeg, Hdr, Pfm, Bmp, Tga, Pnm };
// "OpenEXR", "TIFF", "PNG", "JPEG", "Radiance HDR", "PFM", "BMP", "TGA", "PNM".
std::string to_string(ImageFormat format);

// A rectangle of pixels in a file's pixel space, corners inclusive (OpenEXR's Box2i).
struct PixelBox {
  int min_x = 0;
  int min_y = 0;
  int max_x = -1;
  int max_y = -1;
  int width() const { return max_x - min_x + 1; }
  int height() const { return max_y - min_y + 1; }
  bool contains(const PixelBox& other) const {
    return min_x <= other.min_x && min_y <= other.min_y && max_x >= other.max_x && max_y >= other.max_y;
  }
  friend bool operator==(const PixelBox&, const PixelBox&) = default;
  std::string to_string() const;  // "640 x 360 at (0, 0)"
};

struct RasterInfo {
  ImageFormat format = ImageFormat::Exr;
  int width = 0;   // pixels, >= 1 (the data window's)
  int height = 0;  // pixels, >= 1
  // OpenEXR's windows as the file has them: the data window holds the pixels read (width x height),
  // the display window is the frame. They differ for overscan (data beyond the frame); a crop
  // (data inside the frame) is refused when reading. Other formats: both are the picture.
  PixelBox data_window;
  PixelBox display_window;
  bool has_overscan() const { return !(data_window == display_window); }
  // In the order OpenImageIO and Nuke present them: for OpenEXR layer by layer, each layer's
  // R, G, B, (Y), A, ..., Z first; for other formats as stored.
  std::vector<RasterChannel> channels;
  // The file says its integer codes are linear light (OpenEXR always; a PNG with a gAMA chunk of 1.0
  // and no sRGB chunk). Integer codes of every other file are display-referred (sRGB).
  bool integers_are_linear = false;

  int channel_index(std::string_view name) const;  // -1 when absent
  std::vector<std::string> channel_names() const;
  std::string to_string() const;  // "PNG 640 x 360, channels R uint8, G uint8, B uint8"
  friend std::ostream& operator<<(std::ostream& os, const RasterInfo& i) { return os << i.to_string(); }
};

// Decoded samples of some channels of a picture, in the order they were asked for.
struct Raster {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<float> samples;  // samples[(y * width + x) * channels + c]

  float at(int x, int y, int c) const {
    return samples[(static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) *
                       static_cast<std::size_t>(channels) +
                   static_cast<std::size_t>(c)];
  }
};

}  // namespace lensmith
