// `lensmith seidel`: the JSON schema of docs/cli.md and the Sasian triplet's published sums.
#include <catch2/catch.hpp>

#include <filesystem>

#include <nlohmann/json.hpp>

#include "run_lensmith.h"

using lensmith::testing::run_lensmith;

TEST_CASE("lensmith seidel --json has the documented keys and the Sasian triplet's sums", "[cli][seidel]") {
  const auto r = run_lensmith("seidel sasian-triplet --json");
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  for (const char* key : {"wavelength_nm", "sums", "surfaces", "wavefront_waves", "transverse_mm", "born_wolf"}) {
    INFO("key " << key);
    CHECK(j.contains(key));
  }
  for (const char* key : {"S1", "S2", "S3", "S4", "S5", "C1", "C2"}) CHECK(j["sums"].contains(key));
  for (const char* key : {"W040", "W131", "W222", "W220", "W311", "W020", "W111"}) CHECK(j["wavefront_waves"].contains(key));
  for (const char* key : {"B", "C", "D", "E", "F"}) CHECK(j["born_wolf"].contains(key));
  CHECK(j["surfaces"].size() == 6);
  // REFERENCE-VALUES.md section 2, printed to 6 decimals.
  constexpr double kSixDecimals = 1e-6;
  CHECK_THAT(j["sums"]["S1"].get<double>(), Catch::Matchers::WithinAbs(0.010973, kSixDecimals));
  CHECK_THAT(j["sums"]["S4"].get<double>(), Catch::Matchers::WithinAbs(0.036297, kSixDecimals));
  CHECK_THAT(j["surfaces"][1]["S5"].get<double>(), Catch::Matchers::WithinAbs(-0.431229, kSixDecimals));
}

TEST_CASE("lensmith seidel: --epd and --field-angle override the lens, --png writes the Seidel diagram", "[cli][seidel]") {
  namespace fs = std::filesystem;
  const fs::path png = fs::temp_directory_path() / "lensmith_cli_seidel.png";
  fs::remove(png);
  const auto full = nlohmann::json::parse(run_lensmith("seidel sasian-triplet --json").out);
  const auto r = run_lensmith("seidel sasian-triplet --json --epd 6.25 --png " + png.string() + " --quiet");
  REQUIRE(r.exit_code == 0);
  const auto half = nlohmann::json::parse(r.out);
  // S_I goes with the fourth power of the aperture.
  CHECK_THAT(half["sums"]["S1"].get<double>(), Catch::Matchers::WithinRel(full["sums"]["S1"].get<double>() / 16.0, 1e-9));
  CHECK(fs::file_size(png) > 1000);
  fs::remove(png);
  CHECK(run_lensmith("seidel sasian-triplet --epd 5 --fstop 4").exit_code == 2);
}

TEST_CASE("lensmith seidel: a lens without a field asks for one", "[cli][seidel]") {
  const auto r = run_lensmith("seidel angenieux-double-gauss-1953");
  CHECK(r.exit_code == 3);
  CHECK_THAT(r.err, Catch::Contains("field"));
  CHECK(run_lensmith("seidel angenieux-double-gauss-1953 --field-angle 10 --quiet").exit_code == 0);
}
