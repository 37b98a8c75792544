// `lensmith validate` as a user runs it: a report and a picture, and an exit status that fails when
// a declared threshold is missed.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "run_lensmith.h"

using lensmith::testing::run_lensmith;
namespace fs = std::filesystem;

TEST_CASE("lensmith validate writes a Markdown report and a PSF picture, and fails only on a missed threshold",
          "[cli][validate]") {
  const lensmith::testing::ScratchFolder scratch("lensmith_validate_cli_");
  const fs::path dir = scratch.dir / "out";
  const std::string common = "validate sasian-triplet --fstop 8 --focus 3 --pupil-samples 24 --width 640 --height 360 --out " +
                             dir.string() + " --quiet";
  const auto ok = run_lensmith(common);
  INFO(ok.err);
  REQUIRE(ok.exit_code == 0);
  CHECK(fs::file_size(dir / "psf.png") > 1000);
  std::ifstream in(dir / "report.md");
  std::stringstream text;
  text << in.rdbuf();
  CHECK(text.str().find("| seidel |") != std::string::npos);
  CHECK(text.str().find("Image level") != std::string::npos);
  // An overlap of 1 everywhere is impossible for a real lens: exit status 6 and a message.
  const auto strict = run_lensmith(common + " --min-overlap 1");
  CHECK(strict.exit_code == 6);
  CHECK(strict.err.find("below --min-overlap") != std::string::npos);
}
