// `lensmith fit` as a user runs it: the held-out errors and timings the issue names, a fit file that
// bokeh and validate read back for --model poly, and clear refusals of fits that do not match.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "run_lensmith.h"

using lensmith::testing::run_lensmith;
namespace fs = std::filesystem;

namespace {
const std::string kScene = std::string(LENSMITH_SOURCE_DIR) + "/examples/bokeh-scene.exr";
// A small fit: enough for the files and the model to work, quick on two cores.
const std::string kSmall = " --degree 5 --terms 20 --training-rays 3000 --test-rays 1000 --quiet";
}  // namespace

TEST_CASE("lensmith fit --json reports held-out errors and both timings, and writes a fit file", "[cli][fit]") {
  const fs::path dir = fs::temp_directory_path() / ("lensmith_fit_cli_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path fit = dir / "triplet.fit.json";
  const auto r = run_lensmith("fit sasian-triplet --json -o " + fit.string() + kSmall);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  for (const char* key : {"position_rms_um", "position_p99_um", "direction_rms_mrad", "sensor_position_rms_um",
                          "fit_seconds", "exact_ns_per_ray", "poly_ns_per_ray"}) {
    INFO(key);
    REQUIRE(j.contains(key));
    CHECK(std::isfinite(j[key].get<double>()));
    CHECK(j[key].get<double>() > 0.0);
  }
  CHECK(j["degree"] == 5);
  CHECK(j["terms"] == 20);
  CHECK(j["position_p99_um"].get<double>() >= j["position_rms_um"].get<double>() * 0.5);
  REQUIRE(fs::exists(fit));

  // The file drives --model poly in bokeh; a fit of another lens is refused with exit 3.
  const auto b = run_lensmith("bokeh --image " + kScene + " --lens sasian-triplet --fstop 8 --focus 3 --model poly --fit " +
                              fit.string() + " -o " + (dir / "poly.png").string() + " --quiet");
  INFO(b.err);
  CHECK(b.exit_code == 0);
  CHECK(fs::file_size(dir / "poly.png") > 1000);
  const auto other = run_lensmith("bokeh --image " + kScene + " --lens zeiss-biotar-1927 --fstop 8 --focus 3 --model poly --fit " +
                                  fit.string() + " -o " + (dir / "x.png").string() + " --quiet");
  CHECK(other.exit_code == 3);
  CHECK(other.err.find("not for") != std::string::npos);
  // --fit without --model poly is a mistake, not something to ignore.
  const auto stray = run_lensmith("bokeh --image " + kScene + " --lens sasian-triplet --fstop 8 --focus 3 --fit " +
                                  fit.string() + " -o " + (dir / "x.png").string() + " --quiet");
  CHECK(stray.exit_code == 2);
  fs::remove_all(dir);
}

TEST_CASE("lensmith fit prints a readable summary and refuses bad options", "[cli][fit]") {
  const auto r = run_lensmith("fit sasian-triplet" + kSmall);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.out.find("position RMS") != std::string::npos);
  CHECK(r.out.find("x faster") != std::string::npos);
  CHECK(run_lensmith("fit sasian-triplet --degree 12").exit_code == 2);
  CHECK(run_lensmith("fit sasian-triplet --terms 0").exit_code == 2);  // 0 is the library's "automatic", not a budget
}

TEST_CASE("lensmith fit never writes its output over the lens it reads", "[cli][fit]") {
  const fs::path dir = fs::temp_directory_path() / ("lensmith_fit_cli_in_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path lens = dir / "lens.json";
  const auto c = run_lensmith("convert sasian-triplet -o " + lens.string());
  REQUIRE(c.exit_code == 0);
  std::ifstream before_in(lens);
  std::stringstream before;
  before << before_in.rdbuf();
  const auto r = run_lensmith("fit " + lens.string() + " -o " + lens.string() + kSmall);
  CHECK(r.exit_code != 0);
  std::ifstream after_in(lens);
  std::stringstream after;
  after << after_in.rdbuf();
  CHECK(after.str() == before.str());
  fs::remove_all(dir);
}

TEST_CASE("lensmith validate scores the poly model next to paraxial and seidel", "[cli][fit][validate]") {
  const fs::path dir = fs::temp_directory_path() / ("lensmith_validate_poly_" + std::to_string(::getpid()));
  const fs::path fit = dir / "triplet.fit.json";
  fs::create_directories(dir);
  REQUIRE(run_lensmith("fit sasian-triplet --fstop 8 -o " + fit.string() + kSmall).exit_code == 0);
  const auto r = run_lensmith("validate sasian-triplet --fstop 8 --focus 3 --pupil-samples 24 --width 640 --height 360 "
                              "--models paraxial poly --fit " + fit.string() + " --out " + dir.string() + " --quiet");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  std::ifstream in(dir / "report.md");
  std::stringstream text;
  text << in.rdbuf();
  CHECK(text.str().find("| poly |") != std::string::npos);
  fs::remove_all(dir);
}
