// `lensmith layout`: the text summary in a terminal, the picture with --png, and the documented exit codes.
#include <catch2/catch.hpp>

#include <filesystem>

#include "lensmith/imageio/image_file.h"
#include "run_lensmith.h"

using lensmith::testing::run_lensmith;

TEST_CASE("lensmith layout without --png prints the elements, the stop and the total track", "[cli][layout]") {
  const auto r = run_lensmith("layout sasian-triplet");
  REQUIRE(r.exit_code == 0);
  // The Sasian triplet: three singlets, the stop on the front of the negative lens (surface 3).
  CHECK_THAT(r.out, Catch::Contains("3 glass elements"));
  CHECK_THAT(r.out, Catch::Contains("stop: surface 3"));
  CHECK_THAT(r.out, Catch::Contains("total track"));
}

TEST_CASE("lensmith layout --png writes the drawing, never over its input", "[cli][layout]") {
  namespace fs = std::filesystem;
  const fs::path png = fs::temp_directory_path() / "lensmith_cli_layout.png";
  fs::remove(png);
  const auto r = run_lensmith("layout pbrt-dgauss-50mm --fields 0,1 --rays 7 --png " + png.string() + " --quiet");
  REQUIRE(r.exit_code == 0);
  const lensmith::RasterInfo info = lensmith::read_raster_info(png);
  CHECK(info.width == 1100);  // the layout's fixed width; the height follows the lens's proportions
  CHECK(info.height > 300);
  fs::remove(png);
}

TEST_CASE("lensmith layout: a bad option is a usage error, an unknown lens an input error", "[cli][layout]") {
  CHECK(run_lensmith("layout sasian-triplet --rays 0").exit_code == 2);
  CHECK(run_lensmith("layout sasian-triplet --fields 2").exit_code == 2);
  CHECK(run_lensmith("layout no-such-lens").exit_code == 3);
}
