// Image-level validation: the bokeh of a defocused scene comes closer to the ground truth rendered
// through the lens than the unblurred input does, and the report says so in numbers.
#include <catch2/catch.hpp>

#include "lensmith/prescription/lens_library.h"
#include "lensmith/validate/image_validation.h"

using namespace lensmith;

TEST_CASE("Bokeh of the occluder scene scores closer to the exact-lens render than the pinhole input does", "[validate]") {
  CameraOptions camera;
  camera.focus_distance_m = 1.0;
  camera.f_number = 4.0;
  ImageValidationOptions o;
  o.scenes = {std::string(LENSMITH_SOURCE_DIR) + "/examples/scenes/occluder.json"};
  o.models = {RayModelKind::Paraxial};
  o.width_px = 160;
  o.height_px = 90;
  o.spp = 1024;
  const ImageValidation v = validate_images(LensLibrary::load("sasian-triplet").prescription, camera, o);
  REQUIRE(v.entries.size() == 1);
  REQUIRE(v.unblurred.size() == 1);
  INFO(v.to_markdown());
  CHECK(v.entries[0].comparison.psnr_db > v.unblurred[0].psnr_db + 3.0);
  CHECK(v.entries[0].comparison.ssim > v.unblurred[0].ssim);
  CHECK(v.to_markdown().find("| occluder | paraxial |") != std::string::npos);
}
