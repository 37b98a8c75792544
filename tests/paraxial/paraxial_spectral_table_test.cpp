// ParaxialSpectralTable: first-order data sampled over 380-780 nm must agree with ParaxialSystem
// at every sample, interpolate smoothly in between, and follow the glass dispersion.
#include "lensmith/paraxial/paraxial_spectral_table.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "lensmith/core/errors.h"
#include "lensmith/glass/glass_catalog.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "reference_lenses.h"

using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using namespace lensmith;
using lensmith::testing::make_surface;
using lensmith::testing::sasian_triplet;

namespace {

// The table and ParaxialSystem run the same kernel: only rounding may separate them.
constexpr double kSameKernel = 1e-12;
// Linear interpolation over 6.35 nm steps of a smooth dispersion curve: the error is h^2/8 times
// the curvature of EFL(lambda), about 1e-7 relative for these glasses; allow 100 times that.
constexpr double kInterpolation = 1e-5;

// Biconvex singlet in air, first surface as stop.
Prescription singlet(const MaterialSpec& glass) {
  Prescription p;
  p.surfaces = {make_surface(60.0, 6.0, glass, 12.0), make_surface(-80.0, 55.0, MaterialSpec::air(), 12.0)};
  p.surfaces[0].is_stop = true;
  p.aperture = ApertureSpec{ApertureSpec::Kind::FloatByStop, 0.0};
  return p;
}

void check_same(const ParaxialSample& s, const ParaxialSystem& p) {
  CHECK_THAT(s.efl_mm, WithinRel(p.efl_mm(), kSameKernel));
  CHECK_THAT(s.bfl_mm, WithinRel(p.bfl_mm(), kSameKernel));
  CHECK_THAT(s.ffl_mm, WithinRel(p.ffl_mm(), kSameKernel));
  CHECK_THAT(s.z_front_principal_mm, WithinAbs(p.z_front_principal_mm(), kSameKernel * p.efl_mm()));
  CHECK_THAT(s.z_rear_principal_mm, WithinAbs(p.z_rear_principal_mm(), kSameKernel * p.efl_mm()));
  CHECK_THAT(s.z_entrance_pupil_mm, WithinAbs(p.entrance_pupil().z_mm, kSameKernel * p.efl_mm()));
  CHECK_THAT(s.entrance_pupil_diameter_mm, WithinRel(p.entrance_pupil().diameter_mm, kSameKernel));
  CHECK_THAT(s.z_exit_pupil_mm, WithinAbs(p.exit_pupil().z_mm, kSameKernel * p.efl_mm()));
  CHECK_THAT(s.exit_pupil_diameter_mm, WithinRel(p.exit_pupil().diameter_mm, kSameKernel));
  CHECK_THAT(s.image_distance_mm, WithinRel(p.image_distance_mm(), kSameKernel));
  CHECK_THAT(s.magnification, WithinAbs(p.magnification(), kSameKernel));
}

}  // namespace

TEST_CASE("spectral table: 64 evenly spaced samples from 380 to 780 nm by default", "[paraxial][spectral]") {
  const ParaxialSpectralTable table(sasian_triplet());
  const auto& samples = table.samples();
  REQUIRE(samples.size() == 64);
  CHECK(samples.front().wavelength_nm == 380.0);
  CHECK(samples.back().wavelength_nm == 780.0);
  for (std::size_t k = 1; k < samples.size(); ++k) {
    INFO("sample " << k);
    CHECK_THAT(samples[k].wavelength_nm - samples[k - 1].wavelength_nm, WithinRel(400.0 / 63.0, 1e-12));
  }
}

TEST_CASE("spectral table: every sample equals a ParaxialSystem at its wavelength", "[paraxial][spectral]") {
  for (const double object_distance : {kInfinity, 400.0}) {
    SpectralTableOptions options;
    options.object_distance_mm = object_distance;
    const Prescription lens = sasian_triplet();
    const ParaxialSpectralTable table(lens, options);
    for (const std::size_t k : {std::size_t{0}, std::size_t{20}, std::size_t{63}}) {
      const ParaxialSample& s = table.samples()[k];
      INFO("object distance " << object_distance << " mm, " << s.wavelength_nm << " nm");
      ParaxialOptions system_options;
      system_options.wavelength_nm = s.wavelength_nm;
      system_options.object_distance_mm = object_distance;
      check_same(s, ParaxialSystem(lens, system_options));
    }
  }
  // A floating stop: the EPD follows the stop's image at each wavelength.
  const Prescription lens = singlet(MaterialSpec::model(1.5168, 64.17));
  const ParaxialSpectralTable table(lens);
  const ParaxialSample& s = table.samples()[5];
  check_same(s, ParaxialSystem(lens, ParaxialOptions{s.wavelength_nm, {}}));
}

TEST_CASE("spectral table: at(587.5618) interpolates to the primary-wavelength values", "[paraxial][spectral]") {
  const Prescription lens = sasian_triplet();
  const ParaxialSpectralTable table(lens);
  const ParaxialSystem primary(lens);
  const ParaxialSample s = table.at(kWavelengthD_nm);
  CHECK(s.wavelength_nm == kWavelengthD_nm);
  CHECK_THAT(s.efl_mm, WithinRel(primary.efl_mm(), kInterpolation));
  CHECK_THAT(s.bfl_mm, WithinRel(primary.bfl_mm(), kInterpolation));
  CHECK_THAT(s.ffl_mm, WithinRel(primary.ffl_mm(), kInterpolation));
  CHECK_THAT(s.z_entrance_pupil_mm, WithinRel(primary.entrance_pupil().z_mm, kInterpolation));
  CHECK_THAT(s.z_exit_pupil_mm, WithinRel(primary.exit_pupil().z_mm, kInterpolation));
  CHECK_THAT(s.entrance_pupil_diameter_mm, WithinRel(12.5, kSameKernel));  // EPD spec: fixed
  CHECK_THAT(s.image_distance_mm, WithinRel(primary.image_distance_mm(), kInterpolation));
  CHECK_FALSE(s.extrapolated);
}

TEST_CASE("spectral table: at() clamps outside the range and hits samples exactly", "[paraxial][spectral]") {
  const ParaxialSpectralTable table(sasian_triplet());
  const auto& samples = table.samples();
  CHECK(table.at(300.0).efl_mm == samples.front().efl_mm);
  CHECK(table.at(900.0).efl_mm == samples.back().efl_mm);
  CHECK_THAT(table.at(samples[10].wavelength_nm).efl_mm, WithinRel(samples[10].efl_mm, 1e-14));
  const double midpoint = 0.5 * (samples[10].wavelength_nm + samples[11].wavelength_nm);
  CHECK_THAT(table.at(midpoint).bfl_mm, WithinRel(0.5 * (samples[10].bfl_mm + samples[11].bfl_mm), 1e-14));
}

TEST_CASE("spectral table: EFL follows the dispersion of the glass and is flat for a constant index",
          "[paraxial][spectral]") {
  // A positive crown singlet: higher index in the blue gives more power, a shorter focal length.
  const ParaxialSpectralTable dispersive(singlet(MaterialSpec::model(1.5168, 64.17)));
  const auto& d = dispersive.samples();
  CHECK(d.front().efl_mm < d.back().efl_mm);
  for (std::size_t k = 1; k < d.size(); ++k) {
    INFO(d[k].wavelength_nm << " nm");
    CHECK(d[k].efl_mm > d[k - 1].efl_mm);
  }
  // Longitudinal colour of a thin-ish singlet: delta f / f ~ (nF - nC)/(nd - 1) = 1/Vd between F and C.
  const double f_blue = dispersive.at(kWavelengthF_nm).efl_mm, f_red = dispersive.at(kWavelengthC_nm).efl_mm;
  const double f_d = dispersive.at(kWavelengthD_nm).efl_mm;
  CHECK_THAT((f_red - f_blue) / f_d, WithinRel(1.0 / 64.17, 0.05));  // 5 %: thickness and interpolation

  const ParaxialSpectralTable constant(singlet(MaterialSpec::model(1.5168, {})));
  for (const ParaxialSample& s : constant.samples()) {
    INFO(s.wavelength_nm << " nm");
    CHECK(s.efl_mm == constant.samples().front().efl_mm);
    CHECK(s.bfl_mm == constant.samples().front().bfl_mm);
  }
}

TEST_CASE("spectral table: samples where a glass is extrapolated beyond its range are flagged",
          "[paraxial][spectral]") {
  // Schott N-BK7 Sellmeier coefficients (refractiveindex.info formula 2), range cut to 400-700 nm.
  const Glass narrow = Glass::from_formula(
      "BK7-NARROW", "TEST", Glass::Formula::Sellmeier2,
      {0.0, 1.03961212, 0.00600069867, 0.231792344, 0.0200179144, 1.01046945, 103.560653}, {400.0, 700.0}, 1.5168,
      64.17);
  Prescription lens = singlet(MaterialSpec::model(1.5168, 64.17));
  lens.surfaces[0].medium = narrow;
  const ParaxialSpectralTable table(lens);
  for (const ParaxialSample& s : table.samples()) {
    INFO(s.wavelength_nm << " nm");
    CHECK(s.extrapolated == !(s.wavelength_nm >= 400.0 && s.wavelength_nm <= 700.0));
  }
  CHECK(table.at(390.0).extrapolated);
  CHECK_FALSE(table.at(550.0).extrapolated);
  CHECK(table.to_string().find('*') != std::string::npos);
}

TEST_CASE("spectral table options validate themselves and name the field", "[paraxial][spectral][errors]") {
  SpectralTableOptions options;
  options.samples = 1;
  CHECK_THROWS_WITH(options.validate(), Catch::Contains("samples"));
  options = {};
  options.max_wavelength_nm = 300.0;
  CHECK_THROWS_WITH(options.validate(), Catch::Contains("max_wavelength_nm"));
  options = {};
  options.min_wavelength_nm = 50.0;
  CHECK_THROWS_AS(ParaxialSpectralTable(sasian_triplet(), options), OptionsError);
  CHECK_NOTHROW(SpectralTableOptions{}.validate());
}
