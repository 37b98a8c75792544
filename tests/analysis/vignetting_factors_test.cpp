// A lens file's vignetting factors (FieldSpec::vignetting) shrink the pupil spots and fans sample, as in
// OpticStudio, but never the analyses that measure vignetting: relative illumination and the pupil shape
// sample the whole pupil and let the apertures cut it. The lens: the US 583,336 double Gauss of
// tests/data/zemax/real, whose floating apertures vignette its 24-degree field hard.
#include <catch2/catch.hpp>
#include <string>

#include "lensmith/analysis/analysis_context.h"
#include "lensmith/analysis/relative_illumination.h"
#include "lensmith/core/text_file.h"
#include "lensmith/prescription/zemax_reader.h"

using namespace lensmith;

namespace {

Prescription double_gauss() {
  const std::string path = std::string(LENSMITH_TEST_DATA_DIR) + "/zemax/real/US00583336-2-scaled.zmx";
  return read_zemax(read_file_bytes(path), path).prescription;
}

}  // namespace

TEST_CASE("relative illumination ignores vignetting factors: the same with them applied or not", "[analysis][vignetting]") {
  const Prescription lens = double_gauss();
  REQUIRE_FALSE(lens.field->vignetting.empty());
  AnalysisOptions with_factors;
  AnalysisOptions without = with_factors;
  without.use_vignetting_factors = false;
  IlluminationOptions options;
  options.field_samples = 3;
  const RelativeIllumination a = compute_relative_illumination(AnalysisContext(lens, with_factors), options);
  const RelativeIllumination b = compute_relative_illumination(AnalysisContext(lens, without), options);
  REQUIRE(a.points.size() == b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    CHECK(a.points[i].vignetting_factor == b.points[i].vignetting_factor);
    CHECK(a.points[i].projected_solid_angle_sr == b.points[i].projected_solid_angle_sr);
  }
  // The full field loses part of its beam at the apertures: what the file's factors describe.
  CHECK(a.points.back().vignetting_factor < 0.9);
}

TEST_CASE("spots sample the vignetted pupil: every full-field ray of the file's pupil passes, unlike the whole pupil's",
          "[analysis][vignetting]") {
  const Prescription lens = double_gauss();
  const AnalysisContext vignetted(lens);
  AnalysisOptions whole_options;
  whole_options.use_vignetting_factors = false;
  const AnalysisContext whole(lens, whole_options);
  const FieldPoint edge = vignetted.field_at(1.0);
  for (const PupilCoordinate p : {PupilCoordinate{0.0, 1.0}, PupilCoordinate{0.0, -1.0}}) {
    CHECK(vignetted.trace(edge, p, lens.primary_wavelength_nm()).ok());
    CHECK_FALSE(whole.trace(edge, p, lens.primary_wavelength_nm()).ok());  // cut by an aperture, or no such ray
  }
  std::optional<AnalysisContext> storage;
  CHECK(&whole_pupil(whole, storage) == &whole);
  CHECK_FALSE(whole_pupil(vignetted, storage).options().use_vignetting_factors);
}
