// Scores a defocused image against a reference render (PSNR and SSIM on x/(1+x) tone-mapped
// values, whole frame and a band around depth edges): the comparison of bench/blender/README.md.
//   lensmith_compare_images RESULT REFERENCE DEPTH_FILE[:CHANNEL] [BAND_RADIUS_PX]
#include <cstdlib>
#include <iostream>

#include "lensmith/camera/pinhole_frame.h"
#include "lensmith/render/image_io.h"
#include "lensmith/render/image_metrics.h"

int main(int argc, char** argv) {
  using namespace lensmith;
  if (argc < 4) {
    std::cerr << "usage: lensmith_compare_images RESULT REFERENCE DEPTH_FILE[:CHANNEL] [BAND_RADIUS_PX]\n";
    return 2;
  }
  try {
    const Image result = read_radiance_image(argv[1]);
    const Image reference = read_radiance_image(argv[2]);
    const PinholeFrame frame(result.width, result.height, 1.0);  // planar depth: framing unused
    const DepthMap depth = read_depth(DepthSource::parse(argv[3]), DepthReadOptions{}, frame);
    const double band = argc > 4 ? std::atof(argv[4]) : 8.0;
    std::cout << compare_images(result, reference, depth, band).to_string() << "\n";
  } catch (const std::exception& e) {
    std::cerr << "lensmith_compare_images: " << e.what() << "\n";
    return 3;
  }
  return 0;
}
