// Writes a small synthetic shot for the farm test (tests/farm/slurm_farm_test.sh): frames FIRST..LAST
// of the bundled all-in-focus scene (examples/bokeh-scene.exr, RGB + Z) as OpenEXR files with
//  - a camera pan: frame k is the scene rolled 3k pixels to the left, so no two frames are alike;
//  - a focus pull in the frame's own metadata: OpenEXR's standard `focus` (m, from the image plane)
//    from 1.3 m on the first frame to 4.3 m on the last, and `aperture` f/2;
//  - overscan: the data window is the whole picture, the display window 24 pixels inside it;
//  - with --acescg, colours in ACEScg (AP1, by lensmith's Bradford matrix from linear Rec.709), and
//    AP1 in the standard chromaticities attribute.
// Usage: make_test_shot SCENE.exr OUTPUT-FOLDER FIRST LAST [--acescg]
#include <array>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "lensmith/color/rgb_primaries.h"
#include "lensmith/imageio/image_file.h"
#include "lensmith/render/image.h"
#include "lensmith/render/image_io.h"

int main(int argc, char** argv) {
  const bool acescg = argc == 6 && std::string(argv[5]) == "--acescg";
  if (argc != 5 && !acescg) {
    std::cerr << "usage: make_test_shot SCENE.exr OUTPUT-FOLDER FIRST LAST [--acescg]\n";
    return 2;
  }
  const lensmith::Matrix3 to_ap1 = lensmith::rgb_conversion(lensmith::kRec709Primaries, lensmith::kAcesAp1Primaries);
  const std::string scene = argv[1];
  const std::filesystem::path folder = argv[2];
  const int first = std::stoi(argv[3]), last = std::stoi(argv[4]);
  const lensmith::Image rgb = lensmith::read_radiance_image(scene);
  const lensmith::RasterInfo info = lensmith::read_raster_info(scene);
  const int z_channel = info.channel_index("Z");
  if (z_channel < 0) {
    std::cerr << scene << ": no Z channel\n";
    return 1;
  }
  const int channels[1] = {z_channel};
  const lensmith::Raster z = lensmith::read_raster(scene, info, channels);
  const int w = rgb.width, h = rgb.height, margin = 24;
  const lensmith::PixelBox data{0, 0, w - 1, h - 1};
  const lensmith::PixelBox display{margin, margin, w - 1 - margin, h - 1 - margin};
  std::filesystem::create_directories(folder);
  for (int frame = first; frame <= last; ++frame) {
    const int shift = 3 * (frame - first);
    std::vector<float> samples(static_cast<std::size_t>(w) * h * 4);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const std::size_t from = static_cast<std::size_t>(y) * w + (x + shift) % w;
        const std::size_t to = static_cast<std::size_t>(y) * w + x;
        std::array<double, 3> colour{rgb.data[3 * from], rgb.data[3 * from + 1], rgb.data[3 * from + 2]};
        if (acescg) colour = to_ap1 * colour;
        for (int c = 0; c < 3; ++c) samples[4 * to + c] = static_cast<float>(colour[c]);
        samples[4 * to + 3] = z.samples[from];
      }
    }
    const double t = last > first ? static_cast<double>(frame - first) / (last - first) : 0.0;
    std::vector<lensmith::ImageAttribute> attributes{{"focus", 1.3 + 3.0 * t, true}, {"aperture", 2.0, true}};
    if (acescg) attributes.push_back({"chromaticities", std::string("0.713, 0.293, 0.165, 0.83, 0.128, 0.044, 0.32168, 0.33767")});
    char name[64];
    std::snprintf(name, sizeof name, "plate.%04d.exr", frame);
    lensmith::write_exr(folder / name, lensmith::PixelsView<float>{w, h, 4, samples}, {"R", "G", "B", "Z"}, attributes,
                        std::make_pair(data, display));
  }
  return 0;
}
