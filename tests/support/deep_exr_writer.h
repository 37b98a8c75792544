// Deep OpenEXR files for tests, written with OpenEXR's own deep API (never with the code under test).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace lensmith::testing {

// Per pixel (row-major) its samples, each a value per channel of `names`; deep tiles of tile_px x
// tile_px when tile_px > 0, else deep scanlines. ZIPS compression. The pixels are the data window,
// width x height at (data_x, data_y) of a display window of display_width x display_height at (0, 0)
// (0: the data window's size).
void write_deep_exr(const std::filesystem::path& path, int width, int height, const std::vector<std::string>& names,
                    const std::vector<std::vector<std::vector<float>>>& pixels, int tile_px = 0, int display_width = 0,
                    int display_height = 0, int data_x = 0, int data_y = 0);

}  // namespace lensmith::testing
