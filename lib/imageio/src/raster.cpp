// Names and printing for raster.h.
#include "lensmith/imageio/raster.h"

namespace lensmith {

std::string to_string(SampleType type) {
  switch (type) {
    case SampleType::Uint8: return "uint8";
    case SampleType::Uint16: return "uint16";
    case SampleType::Uint32: return "uint32";
    case SampleType::Half: return "half";
    case SampleType::Float: return "float";
  }
  return "?";
}

bool is_floating_point(SampleType type) { return type == SampleType::Half || type == SampleType::Float; }

std::string to_string(ImageFormat format) {
  switch (format) {
    case ImageFormat::Exr: return "OpenEXR";
    case ImageFormat::Tiff: return "TIFF";
    case ImageFormat::Png: return "PNG";
    case ImageFormat::Jpeg: return "JPEG";
    case ImageFormat::Hdr: return "Radiance HDR";
    case ImageFormat::Pfm: return "PFM";
    case ImageFormat::Bmp: return "BMP";
    case ImageFormat::Tga: return "TGA";
    case ImageFormat::Pnm: return "PNM";
  }
  return "?";
}

int RasterInfo::channel_index(std::string_view name) const {
  for (std::size_t c = 0; c < channels.size(); ++c) {
    if (channels[c].name == name) return static_cast<int>(c);
  }
  return -1;
}

std::vector<std::string> RasterInfo::channel_names() const {
  std::vector<std::string> names;
  for (const RasterChannel& channel : channels) names.push_back(channel.name);
  return names;
}

std::string RasterInfo::to_string() const {
  std::string text = lensmith::to_string(format) + " " + std::to_string(width) + " x " + std::to_string(height) + ", channels";
  for (std::size_t c = 0; c < channels.size(); ++c) {
    text += (c == 0 ? " " : ", ") + channels[c].name + " " + lensmith::to_string(channels[c].type);
  }
  return text;
}

}  // namespace lensmith
