// `lensmith optimize` as a user runs it: the shipped example from a rough start, the optimised lens read back
// and measured independently by `lensmith spot`, the JSON report, the picture, and refused inputs.
#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "run_lensmith.h"

using lensmith::testing::run_lensmith;
using lensmith::testing::ScratchFolder;

namespace {

const std::string kExamples = std::string(LENSMITH_SOURCE_DIR) + "/examples/optimize/";

// The polychromatic RMS spot (mm) of each field as `lensmith spot --json` measures it, with clipping as the
// lens file says: an independent measurement of the optimised lens.
std::vector<double> spot_rms_mm(const std::string& lens) {
  const auto r = run_lensmith("spot " + lens + " --json");
  REQUIRE(r.exit_code == 0);
  std::vector<double> rms;
  const auto report = nlohmann::json::parse(r.out);
  for (const auto& field : report["fields"]) rms.push_back(1e-3 * field["polychromatic"]["rms_radius_centroid_um"].get<double>());
  return rms;
}

}  // namespace

TEST_CASE("lensmith optimize brings the rough triplet example to a spot like the published design's", "[cli][optimize]") {
  const ScratchFolder folder("lensmith_optimize_cli_");
  const std::string out = folder.file("triplet.json"), png = folder.file("triplet.png");
  const auto r = run_lensmith("optimize " + kExamples + "rough-triplet.json --merit " + kExamples + "triplet-merit.json -o " + out + " --png " + png + " --json");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto report = nlohmann::json::parse(r.out);
  CHECK(report["merit_result"].get<double>() < 1e-3 * report["merit_start"].get<double>());
  CHECK(report["variables"].size() == 8);
  CHECK(report["operands"][0]["operand"].get<std::string>().find("spot RMS") == 0);
  CHECK(report["history"].size() >= 2);
  CHECK(std::filesystem::file_size(png) > 10000);
  // The written lens, measured by another command: the published Sasian triplet's spot diagram against it.
  const std::vector<double> published = spot_rms_mm("sasian-triplet");
  const std::vector<double> optimised = spot_rms_mm(out);
  const std::vector<double> rough = spot_rms_mm(kExamples + "rough-triplet.json");
  REQUIRE(optimised.size() == published.size());
  double sum_published = 0.0, sum_optimised = 0.0, sum_rough = 0.0;
  for (std::size_t i = 0; i < published.size(); ++i) {
    sum_published += published[i];
    sum_optimised += optimised[i];
    sum_rough += rough[i];
  }
  INFO("mean RMS spot, um: published " << 1e3 * sum_published / 3 << ", rough " << 1e3 * sum_rough / 3 << ", optimised " << 1e3 * sum_optimised / 3);
  CHECK(sum_rough > 10.0 * sum_published);
  // The factor of tests/design's triplet test; here the lens's own clear apertures clip the field beams.
  CHECK(sum_optimised < 1.25 * sum_published);
  const auto info = nlohmann::json::parse(run_lensmith("info " + out + " --json").out);
  CHECK(std::abs(info["efl_mm"].get<double>() - 50.0) < 1e-9);
}

TEST_CASE("lensmith optimize refuses a bad merit file with its line, and never writes over an input", "[cli][optimize]") {
  const ScratchFolder folder("lensmith_optimize_bad_");
  const std::string merit = folder.file("m.json", "{\n  \"variables\": [{\"surface\": 9, \"parameter\": \"curvature\"}],\n  \"operands\": [{\"type\": \"efl\"}]\n}\n");
  auto r = run_lensmith("optimize sasian-triplet --merit " + merit + " -o " + folder.file("out.json"));
  CHECK(r.exit_code == 3);
  CHECK_THAT(r.err, Catch::Contains("m.json:3:") && Catch::Contains("target or a limit"));
  const std::string wrong_surface = folder.file("s.json", R"({"variables": [{"surface": 9, "parameter": "curvature"}], "operands": [{"type": "efl", "target": 50}]})");
  r = run_lensmith("optimize sasian-triplet --merit " + wrong_surface + " -o " + folder.file("out.json"));
  CHECK(r.exit_code == 3);
  CHECK_THAT(r.err, Catch::Contains("surfaces 1 to 6"));
  CHECK_FALSE(std::filesystem::exists(folder.file("out.json")));
  const auto size = std::filesystem::file_size(kExamples + "triplet-merit.json");
  r = run_lensmith("optimize " + kExamples + "rough-triplet.json --merit " + kExamples + "triplet-merit.json -o " + kExamples + "triplet-merit.json");
  CHECK(r.exit_code == 2);
  CHECK(std::filesystem::file_size(kExamples + "triplet-merit.json") == size);
}

TEST_CASE("lensmith optimize without its Ceres module says where it looked and how to point to it, and writes nothing", "[cli][optimize]") {
  // The command line loads Ceres from liblensmith_ceres.so when a command first solves something
  // (lib/solve/src/ceres_module.h); LENSMITH_MODULE_DIR, where set, is the only place it looks.
  const ScratchFolder folder("lensmith_optimize_module_");
  const std::string modules = (folder.dir / "modules").string();
  std::filesystem::create_directories(modules);
  struct ModuleDir {
    explicit ModuleDir(const std::string& dir) { ::setenv("LENSMITH_MODULE_DIR", dir.c_str(), 1); }
    ~ModuleDir() { ::unsetenv("LENSMITH_MODULE_DIR"); }
  } module_dir(modules);
  const std::string out = folder.file("out.json");
  const auto r = run_lensmith("optimize " + kExamples + "rough-triplet.json --merit " + kExamples + "triplet-merit.json -o " + out);
  CHECK(r.exit_code == 5);
  CHECK_THAT(r.err, Catch::Contains(modules + "/liblensmith_ceres.so") && Catch::Contains("LENSMITH_MODULE_DIR"));
  CHECK_FALSE(std::filesystem::exists(out));
  // Commands that solve nothing do not need it.
  CHECK(run_lensmith("info sasian-triplet").exit_code == 0);
}
