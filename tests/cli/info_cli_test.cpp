// `lensmith info` and friends, run as a user would: the JSON schema of docs/cli.md, exit codes,
// and the published first-order values of the shipped reference lenses.
#include <catch2/catch.hpp>

#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "run_lensmith.h"

using lensmith::testing::run_lensmith;

TEST_CASE("lensmith info --json has every documented key, z measured from surface 1", "[cli]") {
  const auto r = run_lensmith("info sasian-triplet --json");
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  for (const char* key : {"name", "wavelength_nm", "efl_mm", "bfl_mm", "ffl_mm", "z_front_focal_mm", "z_rear_focal_mm",
                          "z_front_principal_mm", "z_rear_principal_mm", "z_front_nodal_mm", "z_rear_nodal_mm",
                          "z_last_surface_mm", "stop_surface", "entrance_pupil", "exit_pupil", "f_number", "lagrange_invariant"}) {
    INFO("key " << key);
    CHECK(j.contains(key));
  }
  // z_last_surface is the sum of the first five thicknesses; BFL = z_rear_focal - z_last_surface.
  constexpr double kArithmetic = 1e-9;  // sums of a few doubles
  CHECK_THAT(j["z_last_surface_mm"].get<double>(), Catch::Matchers::WithinAbs(19.615, kArithmetic));
  CHECK_THAT(j["bfl_mm"].get<double>(),
             Catch::Matchers::WithinAbs(j["z_rear_focal_mm"].get<double>() - j["z_last_surface_mm"].get<double>(), kArithmetic));
  CHECK_THAT(j["ffl_mm"].get<double>(), Catch::Matchers::WithinAbs(j["z_front_focal_mm"].get<double>(), kArithmetic));
  CHECK(j["stop_surface"] == 3);
  CHECK(j["wavelength_nm"] == 587.5618);
}

TEST_CASE("lensmith info: the Sasian triplet's published first-order values (ray-optics docs)", "[cli]") {
  const auto r = run_lensmith("info sasian-triplet --json");
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  const double z_last = j["z_last_surface_mm"].get<double>();
  // ray-optics prints these rounded to 3-4 significant digits; allow half a unit of the last digit.
  CHECK_THAT(j["efl_mm"].get<double>(), Catch::Matchers::WithinAbs(50.0, 0.05));
  CHECK_THAT(j["bfl_mm"].get<double>(), Catch::Matchers::WithinAbs(41.24, 0.005));
  CHECK_THAT(j["ffl_mm"].get<double>(), Catch::Matchers::WithinAbs(-37.1, 0.05));
  CHECK_THAT(j["z_front_principal_mm"].get<double>(), Catch::Matchers::WithinAbs(12.9, 0.05));
  CHECK_THAT(j["z_rear_principal_mm"].get<double>() - z_last, Catch::Matchers::WithinAbs(-8.763, 0.0005));
  CHECK_THAT(j["f_number"].get<double>(), Catch::Matchers::WithinAbs(4.0, 0.005));
  CHECK_THAT(j["entrance_pupil"]["z_mm"].get<double>(), Catch::Matchers::WithinAbs(11.68, 0.005));
  CHECK_THAT(j["entrance_pupil"]["diameter_mm"].get<double>(), Catch::Matchers::WithinAbs(12.5, 1e-9));
  CHECK_THAT(j["exit_pupil"]["z_mm"].get<double>() - z_last, Catch::Matchers::WithinAbs(-10.01, 0.005));
  CHECK_THAT(j["exit_pupil"]["diameter_mm"].get<double>(), Catch::Matchers::WithinAbs(2 * 6.406, 0.001));
  CHECK_THAT(j["lagrange_invariant"].get<double>(), Catch::Matchers::WithinAbs(2.275, 0.0005));
}

TEST_CASE("lensmith info: the Smith triplet's EFL and BFL (Modern Optical Engineering, ch. 6)", "[cli]") {
  const auto r = run_lensmith("info smith-cooke-triplet --json");
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  constexpr double kPrinted = 0.0005;  // Smith prints three decimals
  CHECK_THAT(j["efl_mm"].get<double>(), Catch::Matchers::WithinAbs(101.181, kPrinted));
  CHECK_THAT(j["bfl_mm"].get<double>(), Catch::Matchers::WithinAbs(77.405, kPrinted));
}

TEST_CASE("lensmith info: --object-distance in metres moves the image and gives a magnification", "[cli]") {
  const auto r = run_lensmith("info sasian-triplet --json --object-distance 1");
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j["object_distance_mm"] == 1000.0);
  CHECK(j["image_distance_mm"].get<double>() > j["bfl_mm"].get<double>());  // a near object focuses further back
  CHECK(j["magnification"].get<double>() < 0.0);                             // real image is inverted
}

TEST_CASE("lensmith info: an unknown lens exits 3 naming the closest shipped lenses", "[cli]") {
  const auto r = run_lensmith("info sasian-tripplet");
  CHECK(r.exit_code == 3);
  CHECK_THAT(r.err, Catch::Contains("sasian-triplet"));
}

TEST_CASE("lensmith info: a malformed lens file exits 3 with file:line", "[cli]") {
  const auto path = std::filesystem::temp_directory_path() / "lensmith_cli_bad_lens.json";
  std::ofstream(path) << "{\n  \"format\": \"lensmith-lens\",\n  \"version\": 1,\n  \"name\": 5\n}\n";
  const auto r = run_lensmith("info " + path.string());
  CHECK(r.exit_code == 3);
  CHECK_THAT(r.err, Catch::Contains(path.string() + ":4:") && Catch::Contains("name: expected a string"));
  std::filesystem::remove(path);
}

TEST_CASE("lensmith info: a bad option value exits 2", "[cli]") {
  CHECK(run_lensmith("info sasian-triplet --wavelength -5").exit_code == 2);
  CHECK(run_lensmith("info").exit_code == 2);
}

TEST_CASE("lensmith lenses lists every shipped lens", "[cli]") {
  const auto r = run_lensmith("lenses --json");
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j.size() >= 10);
}

TEST_CASE("lensmith convert writes a file that reads back to the same analysis, and never overwrites its input", "[cli]") {
  namespace fs = std::filesystem;
  const fs::path out = fs::temp_directory_path() / "lensmith_cli_convert.json";
  fs::remove(out);
  REQUIRE(run_lensmith("convert sasian-triplet -o " + out.string() + " --quiet").exit_code == 0);
  const auto a = nlohmann::json::parse(run_lensmith("info sasian-triplet --json").out);
  const auto b = nlohmann::json::parse(run_lensmith("info " + out.string() + " --json").out);
  CHECK(a["efl_mm"] == b["efl_mm"]);
  CHECK(a["exit_pupil"] == b["exit_pupil"]);
  const auto before = fs::file_size(out);
  const auto r = run_lensmith("convert " + out.string() + " -o " + out.string());
  CHECK(r.exit_code == 2);
  CHECK(fs::file_size(out) == before);
  fs::remove(out);
}

TEST_CASE("an ANSI-encoded Zemax file's name reaches info --json and convert as UTF-8, not as an internal error", "[cli][info]") {
  // Issue 17: a NAME with "Ø" saved by OpticStudio as Windows-1252 (byte 0xD8) made nlohmann's dump
  // throw (exit 70). The Sasian triplet (tests/data/zemax) with such a name.
  std::ifstream in(std::string(LENSMITH_TEST_DATA_DIR) + "/zemax/sasian_triplet.zmx", std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t at = text.find("NAME");
  text.replace(at, text.find('\n', at) - at, "NAME \xD8" "25 Triplet");
  const lensmith::testing::ScratchFolder folder("lensmith_ansi_cli_");
  const std::string lens = folder.file("ansi.zmx", text), out = folder.file("ansi.json");
  const auto info = lensmith::testing::run_lensmith("info " + lens + " --json");
  INFO(info.err);
  REQUIRE(info.exit_code == 0);
  CHECK(nlohmann::json::parse(info.out)["name"] == "\xC3\x98" "25 Triplet");
  const auto convert = lensmith::testing::run_lensmith("convert " + lens + " -o " + out);
  REQUIRE(convert.exit_code == 0);
  std::ifstream written(out);
  CHECK(nlohmann::json::parse(written)["name"] == "\xC3\x98" "25 Triplet");
}

TEST_CASE("a user's Zemax .agf catalogue (--glass-catalog or LENSMITH_GLASS_CATALOGS) supplies the glasses a lens file names", "[cli][info]") {
  // The Sasian triplet with its N-LAK9 renamed MYLAK9 from a catalogue MYCAT.agf that holds
  // SCHOTT's N-LAK9 coefficients (Sellmeier 1): the same lens, so the same EFL to the last digit.
  const lensmith::testing::ScratchFolder folder("lensmith_agf_cli_");
  const std::string agf = folder.file("MYCAT.agf",
                                      "CC a user's catalogue\nNM MYLAK9 2 691547 1.691 54.71 0 0 0\n"
                                      "CD 1.46231905 0.00724270156 0.344399589 0.0243353131 1.15508372 85.4686868 0 0 0 0\nLD 0.3 2.5\n");
  std::ifstream in(std::string(LENSMITH_TEST_DATA_DIR) + "/zemax/sasian_triplet.zmx", std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text.replace(text.find("GCAT SCHOTT"), 11, "GCAT MYCAT SCHOTT");
  for (std::size_t at; (at = text.find("GLAS N-LAK9")) != std::string::npos;) text.replace(at, 11, "GLAS MYLAK9");
  const std::string lens = folder.file("mine.zmx", text);
  const auto reference = lensmith::testing::run_lensmith("info " + std::string(LENSMITH_TEST_DATA_DIR) + "/zemax/sasian_triplet.zmx --json");
  REQUIRE(reference.exit_code == 0);
  const auto without = lensmith::testing::run_lensmith("info " + lens + " --json");
  CHECK(without.exit_code == 3);  // MYLAK9 is in no catalogue
  const auto with = lensmith::testing::run_lensmith("--glass-catalog " + agf + " info " + lens + " --json");
  INFO(with.err);
  REQUIRE(with.exit_code == 0);
  CHECK(nlohmann::json::parse(with.out)["efl_mm"] == nlohmann::json::parse(reference.out)["efl_mm"]);
  setenv("LENSMITH_GLASS_CATALOGS", folder.dir.string().c_str(), 1);  // a folder of .agf
  const auto env = lensmith::testing::run_lensmith("info " + lens + " --json");
  unsetenv("LENSMITH_GLASS_CATALOGS");
  CHECK(env.exit_code == 0);
  // A catalogue named like a built-in vendor would be ambiguous: refused, saying how to rename it.
  const std::string clash = folder.file("SCHOTT.agf", "NM X 2 0 1.5 60 0 0 0\nCD 1 0.006 0 0 0 0 0 0 0 0\nLD 0.3 2.5\n");
  const auto refused = lensmith::testing::run_lensmith("--glass-catalog " + clash + " info " + lens);
  CHECK(refused.exit_code == 3);
  CHECK(refused.err.find("SCHOTT_2024.agf") != std::string::npos);
}
