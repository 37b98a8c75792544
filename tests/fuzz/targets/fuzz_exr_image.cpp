// libFuzzer target: lensmith's OpenEXR reading, flat and deep (lensmith::imageio on OpenEXR, and the
// renderer's checks of deep samples). The bytes go to a file, as the readers take paths. Pictures
// that declare more than 2048 x 2048 pixels, 2^25 samples (pixels x channels: 128 MiB of floats)
// or 2^20 deep samples are read only as far as their header: the sizes are the fuzzer's memory
// limit, not a bug.
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "lensmith/core/errors.h"
#include "lensmith/imageio/deep_raster.h"
#include "lensmith/imageio/image_file.h"
#include "lensmith/render/deep_image.h"

namespace {
constexpr long kMaxPixels = 2048L * 2048L;
constexpr long kMaxFlatSamples = 1L << 25;
constexpr std::uint64_t kMaxSamples = std::uint64_t{1} << 20;
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("lensmith_fuzz_exr_" + std::to_string(getpid()) + ".exr");
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    if (lensmith::is_deep_image(path)) {
      const lensmith::DeepRaster header = lensmith::read_deep_header(path);
      if (static_cast<long>(header.width) * header.height > kMaxPixels) return 0;
      const lensmith::DeepRaster raster = lensmith::read_deep_raster(path, kMaxSamples);
      const lensmith::DeepImage deep =
          lensmith::deep_image_from(raster, path, {}, lensmith::PinholeFrame(raster.width, raster.height, 100.0));
      (void)deep.flatten();
    } else {
      const lensmith::RasterInfo info = lensmith::read_raster_info(path);
      const long pixels = static_cast<long>(info.width) * info.height;
      if (pixels > kMaxPixels || pixels * static_cast<long>(info.channels.size()) > kMaxFlatSamples) return 0;
      std::vector<int> all(info.channels.size());
      for (std::size_t c = 0; c < all.size(); ++c) all[c] = static_cast<int>(c);
      (void)lensmith::read_raster(path, info, all);
    }
  } catch (const lensmith::Error&) {
  }
  return 0;
}
