// Real OpticStudio files from another project's test suite (tests/data/zemax/real/README.md): each reads,
// and the specification its file or patent states comes out of lensmith's own first-order and real-ray
// computations. Which features each exercises: FTYP 3 (real image heights), the telecentric flag, OBNA,
// RAIM, FLAP, vignetting factors, a moulding glass.
#include <catch2/catch.hpp>
#include <cmath>
#include <string>

#include "lensmith/core/text_file.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "lensmith/prescription/zemax_reader.h"
#include "lensmith/trace/ray_aiming.h"

using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using namespace lensmith;

namespace {

LensReadResult read_real(const std::string& name) {
  const std::string path = std::string(LENSMITH_TEST_DATA_DIR) + "/zemax/real/" + name;
  return read_zemax(read_file_bytes(path), path);
}

// Where the real chief ray of the prescription's field point `index` meets the image plane (|y|, mm).
double chief_ray_image_height(const Prescription& lens, std::size_t index) {
  TracerOptions free;
  free.clip_apertures = false;
  const SequentialTracer tracer(lens, free);
  AimOptions aim;
  aim.aiming = lens.ray_aiming;
  const RayAimer aimer(tracer, aim);
  const double relative = lens.field->values[index] / lens.field->max_value();
  const AimedRay chief = aimer.make_ray(aimer.field_at(relative), {0.0, 0.0}, lens.primary_wavelength_nm());
  REQUIRE(chief.ok());
  const TraceResult r = tracer.trace_forward(chief.ray);
  REQUIRE(r.ok());
  return std::abs(r.ray.position_mm.y());
}

// The real chief rays of resolved real-image-height fields land on those heights to the solve's 1e-9 mm
// (relative above 1 mm); 1e-8 allows the re-trace's own rounding.
constexpr double kRealHeight_mm = 1e-8;

}  // namespace

TEST_CASE("US 5,831,776 lithography lens: telecentric, NA 0.15, a 1/4 reduction, its real image heights reached",
          "[trace][real-files]") {
  const Prescription read = read_real("US05831776-1.zmx").prescription;
  CHECK(read.object_space_telecentric);
  CHECK(read.aperture == ApertureSpec{ApertureSpec::Kind::ObjectSpaceNA, 0.15});
  REQUIRE(read.field->kind == FieldSpec::Kind::RealImageHeightMm);
  const Prescription lens = resolve_real_image_height_field(read);
  const ParaxialSystem p(lens);
  CHECK(p.entrance_pupil_at_infinity());
  // The patent's reduction ratio is 1/4; the model's paraxial magnification is -0.250031.
  CHECK_THAT(p.magnification(), WithinAbs(-0.25, 1e-4));
  // Object-space NA 0.15 at 1/4 gives 0.6 in image space (paraxial slopes: n' u' = 4 tan(asin 0.15)).
  CHECK_THAT(p.image_space_na(), WithinRel(4.0 * std::tan(std::asin(0.15)), 1e-3));
  CHECK_THAT(std::abs(p.chief_ray()->object_slope), WithinAbs(0.0, 1e-10));  // telecentric: parallel chief ray
  for (std::size_t i = 1; i < lens.field->values.size(); ++i) {
    CHECK_THAT(chief_ray_image_height(lens, i), WithinAbs(read.field->values[i], kRealHeight_mm));
  }
}

TEST_CASE("US 583,336 double Gauss: F/4.5, real ray aiming, floating apertures and vignetting factors",
          "[trace][real-files]") {
  const Prescription lens = read_real("US00583336-2-scaled.zmx").prescription;
  CHECK(lens.ray_aiming == RayAiming::RealStop);
  CHECK(lens.surfaces[1].clips_rays);   // FLAP on SURF 2
  CHECK_FALSE(lens.surfaces[0].clips_rays);  // DIAM only on SURF 1
  REQUIRE(lens.field->vignetting.size() == 3);
  CHECK(lens.field->vignetting[2].vcy > 0.3);
  const ParaxialSystem p(lens);
  CHECK_THAT(p.f_number(), WithinRel(4.5, 1e-12));
  // OpticStudio's real ray aiming fills the stop to where the real axial ray through the paraxial pupil's edge
  // crosses it: its automatic stop semi-diameter, DIAM 4.215000499256 on SURF 7, is that height.
  {
    const SequentialTracer free_tracer(lens);
    AimOptions real;
    real.aiming = RayAiming::RealStop;
    CHECK_THAT(RayAimer(free_tracer, real).stop_radius_mm(), WithinAbs(4.215000499256, 1e-6));
  }
  // With its vignetting factors the full-field rim rays pass every clear aperture, as in OpticStudio.
  const SequentialTracer tracer(lens);
  AimOptions aim;
  aim.aiming = lens.ray_aiming;
  const RayAimer aimer(tracer, aim);
  for (const PupilCoordinate pupil : {PupilCoordinate{0.0, 1.0}, PupilCoordinate{0.0, -1.0}, PupilCoordinate{1.0, 0.0}}) {
    INFO("pupil " << pupil.px << ", " << pupil.py);
    const AimedRay ray = aimer.make_ray(aimer.field_at(1.0), pupil, lens.primary_wavelength_nm());
    REQUIRE(ray.ok());
    CHECK(tracer.trace_forward(ray.ray).ok());
  }
}

TEST_CASE("US 8,427,765 camera lens: F/2.1, real image heights 8 and 13.6 mm, a moulding glass", "[trace][real-files]") {
  const LensReadResult r = read_real("US08427765-1.zmx");
  bool moulded = false;
  for (const Diagnostic& d : r.diagnostics) moulded = moulded || d.message.find("L-TIM28_MOLD") != std::string::npos;
  CHECK(moulded);
  const Prescription lens = resolve_real_image_height_field(r.prescription);
  CHECK_THAT(ParaxialSystem(lens).f_number(), WithinRel(2.1, 1e-12));
  CHECK_THAT(chief_ray_image_height(lens, 1), WithinAbs(8.0, kRealHeight_mm));
  CHECK_THAT(chief_ray_image_height(lens, 2), WithinAbs(13.6, kRealHeight_mm));
}
