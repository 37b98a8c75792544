// `lensmith trace`, `spot`, `fan` and `analyze` run as a user would: the JSON schemas of docs/cli.md,
// the status of a ray that dies, PNG pictures written, and errors for bad options.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "run_lensmith.h"

using Catch::Matchers::WithinAbs;
using lensmith::testing::run_lensmith;

namespace {

struct ScratchFolder : lensmith::testing::ScratchFolder {
  ScratchFolder() : lensmith::testing::ScratchFolder("lensmith_trace_cli_test_") {}
};

struct PngHeader {
  bool valid = false;
  std::uint32_t width = 0, height = 0;
};

// The PNG signature and the size from the IHDR chunk (PNG spec, sec. 5.2 and 11.2.2).
PngHeader read_png_header(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char b[24] = {};
  in.read(reinterpret_cast<char*>(b), sizeof b);
  PngHeader h;
  const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  h.valid = in.gcount() == 24 && std::equal(signature, signature + 8, b) && std::string(reinterpret_cast<char*>(b + 12), 4) == "IHDR";
  auto be32 = [&](int i) { return std::uint32_t{b[i]} << 24 | std::uint32_t{b[i + 1]} << 16 | std::uint32_t{b[i + 2]} << 8 | b[i + 3]; };
  h.width = be32(16);
  h.height = be32(20);
  return h;
}

}  // namespace

TEST_CASE("lensmith trace --json: status, points at every surface in the info frame, and the image point", "[cli][trace]") {
  const auto r = run_lensmith("trace sasian-triplet --field-angle 14 --pupil 0,0.5 --json");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j["status"] == "ok");
  CHECK(j["surface"].is_null());
  CHECK(j["wavelength_nm"] == 587.5618);
  REQUIRE(j["points"].size() == 6);
  for (std::size_t i = 0; i < 6; ++i) {
    const auto& p = j["points"][i];
    CHECK(p["surface"] == i + 1);
    for (const char* key : {"x_mm", "y_mm", "z_mm", "l", "m", "n"}) CHECK(p.contains(key));
    const double l = p["l"], m = p["m"], n = p["n"];
    CHECK_THAT(l * l + m * m + n * n, WithinAbs(1.0, 1e-12));  // direction cosines of a unit vector
  }
  // Surface 1's vertex is z = 0 (conventions.h): a ray 3 mm off axis meets it within its sag.
  CHECK(std::abs(j["points"][0]["z_mm"].get<double>()) < 1.0);
  REQUIRE(j["image"].is_object());
  CHECK_THAT(j["image"]["z_mm"].get<double>(), WithinAbs(j["image_plane_z_mm"].get<double>(), 1e-9));
  // The info command puts the image plane at the last vertex plus the last thickness.
  const auto info = nlohmann::json::parse(run_lensmith("info sasian-triplet --json").out);
  CHECK_THAT(j["image_plane_z_mm"].get<double>(),
             WithinAbs(info["z_last_surface_mm"].get<double>() + info["image_plane_distance_mm"].get<double>(), 1e-9));
}

TEST_CASE("lensmith trace: a ray that dies exits 0 with its status and surface, and no image", "[cli][trace]") {
  // The f/1.1 double Gauss cuts the top of its beam 20 degrees off axis (its cat's-eye bokeh).
  const auto r = run_lensmith("trace angenieux-double-gauss-1953 --field-angle 20 --pupil 0,0.999 --json");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j["status"] == "vignetted");
  REQUIRE(j["surface"].is_number_integer());
  CHECK(j["surface"].get<int>() >= 1);
  CHECK(j["image"].is_null());
  const auto text = run_lensmith("trace angenieux-double-gauss-1953 --field-angle 20 --pupil 0,0.999");
  CHECK(text.exit_code == 0);
  CHECK(text.out.find("vignetted at surface") != std::string::npos);
}

TEST_CASE("lensmith trace: --image paraxial moves the image plane to the paraxial focus", "[cli][trace]") {
  const auto r = run_lensmith("trace sasian-triplet --image paraxial --json");
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  const auto info = nlohmann::json::parse(run_lensmith("info sasian-triplet --json").out);
  CHECK_THAT(j["image"]["z_mm"].get<double>(), WithinAbs(info["z_image_mm"].get<double>(), 1e-9));
  CHECK_THAT(j["image"]["y_mm"].get<double>(), WithinAbs(0.0, 1e-12));
}

TEST_CASE("lensmith trace: bad options exit 2 and say what is wrong", "[cli][trace]") {
  const auto outside = run_lensmith("trace sasian-triplet --pupil 2,0");
  CHECK(outside.exit_code == 2);
  CHECK(outside.err.find("--pupil") != std::string::npos);
  CHECK(outside.err.find("2,0: must lie in the unit disc") != std::string::npos);
  const auto garbled = run_lensmith("trace sasian-triplet --pupil 0.5");
  CHECK(garbled.exit_code == 2);
  CHECK(garbled.err.find("PX,PY") != std::string::npos);
  CHECK(run_lensmith("trace sasian-triplet --aim sideways").exit_code == 2);
  CHECK(run_lensmith("trace sasian-triplet --field-angle 10 --field 0.5").exit_code == 2);
}

TEST_CASE("lensmith spot --json: hexapolar ray counts, radii in micrometres, lost rays counted", "[cli][spot]") {
  const auto r = run_lensmith("spot sasian-triplet --rings 5 --json");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j["sampling"]["kind"] == "hexapolar");
  CHECK(j["sampling"]["rays"] == 91);  // OpticStudio: 5 rings = 91 rays
  REQUIRE(j["fields"].size() == 3);
  for (const auto& f : j["fields"]) {
    for (const auto& s : f["spots"]) {
      CHECK(s["traced"] == 91);
      CHECK(s["passed"].get<int>() + s["lost"]["total"].get<int>() == 91);
      CHECK(s["rays"]["x_mm"].size() == s["passed"].get<std::size_t>());
      CHECK(s["rms_radius_centroid_um"].get<double>() <= s["rms_radius_chief_um"].get<double>() * (1 + 1e-12));
    }
  }
}

TEST_CASE("lensmith spot --random is reproducible with --seed, and --rings with --random is refused", "[cli][spot]") {
  const auto a = run_lensmith("spot sasian-triplet --random 50 --seed 3 --json");
  const auto b = run_lensmith("spot sasian-triplet --random 50 --seed 3 --json");
  REQUIRE(a.exit_code == 0);
  CHECK(a.out == b.out);
  CHECK(nlohmann::json::parse(a.out)["sampling"]["seed"] == 3);
  CHECK(run_lensmith("spot sasian-triplet --random 50 --rings 3").exit_code == 2);
  CHECK(run_lensmith("spot sasian-triplet --seed 3").exit_code == 2);  // --seed needs --random
  CHECK(run_lensmith("spot sasian-triplet --fields 0,1.5").exit_code == 2);
}

TEST_CASE("lensmith spot --png writes a PNG of the picture's size, the input is never overwritten", "[cli][spot][png]") {
  ScratchFolder scratch;
  const std::string png = scratch.file("spot.png");
  const auto r = run_lensmith("spot sasian-triplet --png " + png);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const PngHeader h = read_png_header(png);
  CHECK(h.valid);
  CHECK(h.width > 900);   // four columns of 230-px panels
  CHECK(h.height > 700);  // three rows
  CHECK(r.err.find("wrote " + png) != std::string::npos);
  CHECK(run_lensmith("--quiet spot sasian-triplet --png " + png).err.empty());

  // A lens file given as LENS and as --png: refused with exit 2, the file untouched.
  const std::string lens = scratch.file("lens.json");
  REQUIRE(run_lensmith("convert sasian-triplet -o " + lens).exit_code == 0);
  const auto size_before = std::filesystem::file_size(lens);
  const auto refused = run_lensmith("spot " + lens + " --png " + lens);
  CHECK(refused.exit_code == 2);
  CHECK(refused.err.find("never overwrites") != std::string::npos);
  CHECK(std::filesystem::file_size(lens) == size_before);
}

TEST_CASE("lensmith fan --json: the fan through the chief ray is zero, dead rays are null with a status", "[cli][fan]") {
  const auto r = run_lensmith("fan angenieux-double-gauss-1953 --field-angle 20 --fields 0,0.5,1 --samples 21 --json");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  REQUIRE(j["fields"].size() == 3);
  for (const auto& f : j["fields"]) {
    for (const auto& c : f["curves"]) {
      REQUIRE(c["tangential"].size() == 21);
      const auto& chief = c["tangential"][10];
      CHECK(chief["py"] == 0.0);
      INFO("field " << f["relative_field"] << ", " << c["wavelength_nm"] << " nm");
      if (f["relative_field"] == 1.0) {
        // At 20 degrees the f/1.1 lens passes only a cat's eye below the pupil centre: even the chief
        // ray is vignetted (the reference is traced without clipping, so the fan still has one).
        CHECK(chief["status"] == "vignetted");
        CHECK(chief["ey_um"].is_null());
        CHECK(chief["surface"].is_number_integer());
      } else if (c["wavelength_nm"] == j["reference_wavelength_nm"]) {
        CHECK_THAT(chief["ey_um"].get<double>(), WithinAbs(0.0, 1e-9));
      }
    }
  }
  CHECK(run_lensmith("fan sasian-triplet --samples 20").exit_code == 2);  // odd counts only
}

TEST_CASE("lensmith analyze: each --what prints JSON with its curve and writes its picture", "[cli][analyze][png]") {
  ScratchFolder scratch;
  for (const std::string what : {"distortion", "field-curves", "focal-shift", "illumination", "pupil"}) {
    INFO(what);
    const std::string png = scratch.file(what + ".png");
    const auto r = run_lensmith("analyze sasian-triplet --what " + what + " --samples 5 --grid 16 --json --png " + png);
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    const auto j = nlohmann::json::parse(r.out);
    CHECK(j["analysis"] == what);
    CHECK(read_png_header(png).valid);
  }
  const auto d = nlohmann::json::parse(run_lensmith("analyze sasian-triplet --what distortion --samples 3 --json").out);
  REQUIRE(d["points"].size() == 3);
  CHECK(std::abs(d["points"][0]["distortion_percent"].get<double>()) < 0.01);  // the on-axis limit
  CHECK(d["points"][0]["real_height_mm"] == 0.0);
  const auto f = nlohmann::json::parse(run_lensmith("analyze sasian-triplet --what focal-shift --json").out);
  for (const auto& p : f["points"]) {
    if (p["wavelength_nm"] == 587.5618) CHECK(p["shift_mm"] == 0.0);
  }
}

TEST_CASE("lensmith analyze: a lens without a field needs --field-angle, unknown analyses are refused", "[cli][analyze]") {
  const auto r = run_lensmith("analyze angenieux-double-gauss-1953 --what distortion");
  CHECK(r.exit_code == 3);
  CHECK(r.err.find("--field-angle") != std::string::npos);
  CHECK(run_lensmith("analyze angenieux-double-gauss-1953 --what distortion --field-angle 15 --samples 3").exit_code == 0);
  CHECK(run_lensmith("analyze sasian-triplet --what sharpness").exit_code == 2);
  CHECK(run_lensmith("analyze sasian-triplet").exit_code == 2);  // --what is required
}

TEST_CASE("lensmith wavefront: a map, RMS and Zernike coefficients per field and wavelength, as JSON and a picture", "[cli][wavefront]") {
  const ScratchFolder folder;
  const std::string png = (folder.dir / "wavefront.png").string();
  const auto r = run_lensmith("wavefront sasian-triplet --grid 16 --terms 16 --json --json-map --png " + png);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j["analysis"] == "wavefront");
  CHECK(j["zernike_ordering"] == "fringe");
  REQUIRE(j["maps"].size() == 9);  // 3 fields x 3 wavelengths
  for (const auto& m : j["maps"]) {
    CHECK(m["zernike"].size() == 16);
    CHECK(m["map_waves"].size() == 256);
    CHECK(m["rms_waves"].get<double>() >= 0.0);
    CHECK(m["pv_waves"].get<double>() >= m["rms_waves"].get<double>());
    // The fans pass through the chief ray, where the OPD is 0 by definition of the reference.
    CHECK_THAT(m["tangential_fan"][20]["opd_waves"].get<double>(), WithinAbs(0.0, 1e-9));
  }
  CHECK(read_png_header(png).valid);
  // Bad options: the Fringe set has 37 terms; --json-map needs --json.
  const auto many = run_lensmith("wavefront sasian-triplet --terms 40");
  CHECK(many.exit_code == 2);
  CHECK(many.err.find("1 to 37") != std::string::npos);
  CHECK(run_lensmith("wavefront sasian-triplet --json-map").exit_code == 2);
  CHECK(run_lensmith("wavefront sasian-triplet --zernike zebra").exit_code == 2);
}

TEST_CASE("lensmith mtf: tangential, sagittal and diffraction-limit curves with Strehl ratios, as JSON and a picture", "[cli][mtf]") {
  const ScratchFolder folder;
  const std::string png = (folder.dir / "mtf.png").string();
  const auto r = run_lensmith("mtf sasian-triplet --pupil-samples 32 --frequencies 11 --max-frequency 100 --json --png " + png);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j["analysis"] == "mtf");
  REQUIRE(j["frequencies_per_mm"].size() == 11);
  CHECK(j["frequencies_per_mm"].back() == 100.0);
  REQUIRE(j["fields"].size() == 3);
  for (const auto& f : j["fields"]) {
    CHECK_THAT(f["tangential"][0].get<double>(), WithinAbs(1.0, 1e-9));  // the OTF is normalised at zero frequency
    const double strehl = f["strehl"].get<double>();
    CHECK(strehl > 0.0);
    CHECK(strehl <= 1.0);
    for (std::size_t i = 0; i < 11; ++i) CHECK(f["tangential"][i].get<double>() <= f["diffraction_limit"][i].get<double>() + 0.02);
  }
  CHECK(read_png_header(png).valid);
  CHECK(run_lensmith("mtf sasian-triplet --pupil-samples 8").exit_code == 2);
}

TEST_CASE("lensmith psf: the PSF per field with its Strehl ratio and centroid, as JSON and a picture", "[cli][psf]") {
  const ScratchFolder folder;
  const std::string png = (folder.dir / "psf.png").string();
  const auto r = run_lensmith("psf sasian-triplet --pupil-samples 32 --size 32 --json --json-grid --png " + png);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j["analysis"] == "psf");
  CHECK(j["size"] == 32);
  REQUIRE(j["fields"].size() == 3);
  for (const auto& f : j["fields"]) {
    CHECK(f["intensity"].size() == 32 * 32);
    CHECK(f["peak"].get<double>() <= 1.0);  // no PSF peaks above the aberration-free one
    CHECK(f["strehl"].get<double>() > 0.0);
  }
  CHECK(read_png_header(png).valid);
  const auto big = run_lensmith("psf sasian-triplet --pupil-samples 16 --size 512");
  CHECK(big.exit_code == 2);
  CHECK(big.err.find("--size") != std::string::npos);
  CHECK(run_lensmith("psf sasian-triplet --json-grid").exit_code == 2);
}

TEST_CASE("lensmith mtf --through-focus: the MTF at one frequency against focus, and its options need it", "[cli][mtf]") {
  const auto r = run_lensmith("mtf sasian-triplet --pupil-samples 32 --through-focus 30 --focus-range 0.2 --focus-steps 9 --json");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j["analysis"] == "through_focus_mtf");
  REQUIRE(j["focus_shifts_mm"].size() == 9);
  CHECK_THAT(j["focus_shifts_mm"][0].get<double>(), WithinAbs(-0.2, 1e-12));
  CHECK(j["fields"][0]["tangential"].size() == 9);
  CHECK(run_lensmith("mtf sasian-triplet --focus-range 0.2").exit_code == 2);
}
