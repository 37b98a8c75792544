// docs/cli.md's exit-code table, one test per row, each run as a user would; and under --json an
// error is a JSON object on stdout too.
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "run_lensmith.h"

using lensmith::testing::run_lensmith;
namespace fs = std::filesystem;

namespace {

const std::string kScene = std::string(LENSMITH_SOURCE_DIR) + "/examples/bokeh-scene.exr";

struct Scratch : lensmith::testing::ScratchFolder {
  Scratch() : ScratchFolder("lensmith_exit_codes_") {}
};

}  // namespace

TEST_CASE("Exit 0: a command that does what it was asked", "[cli][exit]") {
  CHECK(run_lensmith("info sasian-triplet").exit_code == 0);
}

TEST_CASE("Exit 2: the command line itself is wrong, whatever the subcommand", "[cli][exit]") {
  const Scratch scratch;
  const auto unknown = run_lensmith("foo");
  CHECK(unknown.exit_code == 2);
  CHECK(unknown.err.find("unknown subcommand 'foo'") != std::string::npos);
  CHECK(run_lensmith("info sasian-triplet --no-such-option").exit_code == 2);
  CHECK(run_lensmith("info sasian-triplet --wavelength -5").exit_code == 2);  // out of its range
  CHECK(run_lensmith("spot sasian-triplet --fields 0,,1").exit_code == 2);    // an empty entry
  CHECK(run_lensmith("fan sasian-triplet --samples 20").exit_code == 2);      // must be odd
  // A missing required option, and one that another needs.
  CHECK(run_lensmith("bokeh --image " + kScene + " --focus 3 -o " + scratch.file("a.exr")).exit_code == 2);
  CHECK(run_lensmith("bokeh --image " + kScene + " --thin-lens --focus 3 -o " + scratch.file("b.exr")).exit_code == 2);
  // An output naming an input: the same code in every command that writes.
  const std::string lens = scratch.file("lens.json");
  REQUIRE(run_lensmith("convert sasian-triplet -o " + lens).exit_code == 0);
  CHECK(run_lensmith("convert " + lens + " -o " + lens).exit_code == 2);
  CHECK(run_lensmith("spot " + lens + " --png " + lens).exit_code == 2);
  CHECK(run_lensmith("bokeh --image " + kScene + " --thin-lens --focal-length 50 --focus 3 -o " + kScene).exit_code == 2);
}

TEST_CASE("Exit 3: an input's content is wrong, or a lens lacks what the command needs", "[cli][exit]") {
  const Scratch scratch;
  const auto malformed = run_lensmith("info " + scratch.file("bad.zmx", "VERS 190513\nSURF 0\n  CURV banana\n"));
  CHECK(malformed.exit_code == 3);
  CHECK(malformed.err.find("bad.zmx:3") != std::string::npos);
  CHECK(run_lensmith("info no-such-shipped-lens").exit_code == 3);
  // The Angenieux patent gives no field: Seidel sums and spot diagrams both need one.
  const auto seidel = run_lensmith("seidel angenieux-double-gauss-1953");
  CHECK(seidel.exit_code == 3);
  CHECK(seidel.err.find("--field-angle") != std::string::npos);
  const auto spot = run_lensmith("spot angenieux-double-gauss-1953");
  CHECK(spot.exit_code == 3);
  CHECK(spot.err.find("--field-angle") != std::string::npos);
}

TEST_CASE("Exit 4: the lens has no answer to the question", "[cli][exit]") {
  const Scratch scratch;
  // A plane-parallel plate has no power: no focal length, no focal points.
  const std::string plate = scratch.file("plate.json", R"({"format": "lensmith-lens", "version": 1, "name": "plate",
    "aperture": {"entrance_pupil_diameter_mm": 10}, "field": {"angle_deg": [5]},
    "surfaces": [{"radius_mm": "flat", "thickness_mm": 5, "material": {"nd": 1.5, "vd": 60}, "semi_diameter_mm": 10, "stop": true},
                 {"radius_mm": "flat", "thickness_mm": 10, "material": "air", "semi_diameter_mm": 10}]})");
  const auto r = run_lensmith("info " + plate);
  CHECK(r.exit_code == 4);
  CHECK(r.err.find("afocal") != std::string::npos);
}

TEST_CASE("Exit 5: a file cannot be read or written, found out before any long computation", "[cli][exit]") {
  const Scratch scratch;
  const auto missing = run_lensmith("info " + (scratch.dir / "nowhere.zmx").string());
  CHECK(missing.exit_code == 5);
  CHECK(missing.err.find("no such file") != std::string::npos);
  const auto unwritable = run_lensmith("bokeh --image " + kScene + " --thin-lens --focal-length 50 --focus 3 -o " +
                                       (scratch.dir / "no-such-folder" / "out.exr").string());
  CHECK(unwritable.exit_code == 5);
  CHECK(unwritable.err.find("does not exist") != std::string::npos);
}

TEST_CASE("Exit 6: lensmith validate misses a threshold given on its command line", "[cli][exit]") {
  const Scratch scratch;
  CHECK(run_lensmith("validate sasian-triplet --pupil-samples 16 --min-overlap 0.999 --out " + (scratch.dir / "v").string()).exit_code == 6);
}

TEST_CASE("Under --json an error is one JSON object on stdout with the exit code and the message", "[cli][exit][json]") {
  const Scratch scratch;
  for (const std::string& args : {"info " + (scratch.dir / "nowhere.zmx").string() + " --json", std::string("info sasian-triplet --json --wavelength -5"),
                                  std::string("seidel angenieux-double-gauss-1953 --json")}) {
    INFO(args);
    const auto r = run_lensmith(args);
    REQUIRE(r.exit_code != 0);
    const nlohmann::json j = nlohmann::json::parse(r.out);
    CHECK(j["error"]["exit_code"] == r.exit_code);
    CHECK_FALSE(j["error"]["message"].get<std::string>().empty());
  }
}
