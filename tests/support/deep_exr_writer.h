// Deep OpenEXR files for tests, written with OpenEXR's own deep API (never with the code under test).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace lensmith::testing {

// Per pixel (row-major) its samples, each a value per channel of `names`; deep tiles of tile_px x
// tile_px when tile_px > 0, else deep scanlines. ZIPS compression.
void write_deep_exr(const std::filesystem::path& path, int width, int height, const std::vector<std::string>& names,
                    const std::vector<std::vector<std::vector<float>>>& pixels, int tile_px = 0);

}  // namespace lensmith::testing
