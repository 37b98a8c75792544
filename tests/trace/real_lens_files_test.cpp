// Real OpticStudio files from another project's test suite (tests/data/zemax/real/README.md): each reads,
// and the specification its file or patent states comes out of lensmith's own first-order and real-ray
// computations. Which features each exercises: FTYP 3 (real image heights), the telecentric flag, OBNA,
// RAIM, FLAP, vignetting factors, a moulding glass.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Dense>

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

// ---- Mirror systems (issue 18) ---------------------------------------------------------------------------

TEST_CASE("Handbook of Optics' classical Cassegrain: the two-mirror focal length, and a stigmatic axial image",
          "[trace][real-files][mirror]") {
  const Prescription lens = read_real("HoO-V2C18Ex03.zmx").prescription;
  REQUIRE(lens.surfaces.size() == 3);  // a dummy surface, the primary, the secondary
  CHECK(lens.surfaces[1].mirror);
  CHECK(lens.surfaces[2].mirror);
  // Two mirrors of powers -2 c (air to reversed air, n' = -1) a distance d apart (Schroeder, Astronomical
  // Optics, 6.1): P = P1 + P2 - d P1 P2, back focal distance (1 - d P1) / P.
  const double p1 = -2.0 * lens.surfaces[1].curvature_per_mm;
  const double p2 = 2.0 * lens.surfaces[2].curvature_per_mm;
  const double d = -lens.surfaces[1].thickness_mm;
  const double power = p1 + p2 - d * p1 * p2;
  const ParaxialSystem p(lens);
  CHECK_THAT(p.efl_mm(), WithinRel(1.0 / power, 1e-12));
  CHECK_THAT(p.image_distance_mm(), WithinRel((1.0 - d * p1) / power, 1e-12));
  // The file puts its image at that focus (24.035 mm from the secondary, as printed).
  CHECK_THAT(lens.surfaces[2].thickness_mm, WithinAbs(p.image_distance_mm(), 5e-4));
  // A classical Cassegrain: paraboloidal primary, and the secondary's conic -((m + 1) / (m - 1))^2 with m the
  // secondary's magnification EFL / f1 makes the axial image free of aberration (Schroeder 6.2). The file's
  // conic is that to its 4 printed digits.
  const double m = p.efl_mm() * p1;
  CHECK_THAT(lens.surfaces[2].conic, WithinAbs(-std::pow((m + 1.0) / (m - 1.0), 2.0), 1e-3));
  // Real rays over the F/4 beam meet within 0.1 um of the axis (the conic's 4th digit), where a spherical
  // secondary leaves tens of micrometres.
  auto worst_axial_miss = [](const Prescription& l) {
    const SequentialTracer tracer(l);
    const RayAimer aimer(tracer);
    double worst = 0.0;
    for (double py : {-1.0, -0.6, 0.3, 0.8, 1.0}) {
      const AimedRay a = aimer.make_ray(aimer.field_at(0.0), {0.0, py}, l.primary_wavelength_nm());
      REQUIRE(a.ok());
      const TraceResult r = tracer.trace_forward(a.ray);
      REQUIRE(r.ok());
      worst = std::max(worst, std::hypot(r.ray.position_mm.x(), r.ray.position_mm.y()));
    }
    return worst;
  };
  CHECK(worst_axial_miss(lens) < 1e-4);
  Prescription spherical = lens;
  spherical.surfaces[2].conic = 0.0;
  CHECK(worst_axial_miss(spherical) > 1e-2);
}

TEST_CASE("An off-axis paraboloid (Edmund 37-992): parent focal length 95.3 mm, a perfect focus 190.6 mm from the mirror",
          "[trace][real-files][mirror][coordinate-break]") {
  const LensReadResult read = read_real("zmax_37992.zmx");
  const Prescription& lens = read.prescription;
  // The decentring break, the mirror, and the image plane's surface tilt (SCBD) read as a second break.
  REQUIRE(lens.surfaces.size() == 4);
  CHECK(lens.surfaces[1].is_coordinate_break());
  CHECK(lens.surfaces[1].coordinate_break.decenter_y_mm == -190.6);
  CHECK(lens.surfaces[2].mirror);
  CHECK(lens.surfaces[3].is_coordinate_break());
  CHECK(lens.surfaces[3].coordinate_break.tilt_x_deg == 90.0);
  // First order ignores the breaks (OpticStudio's default): the parent paraboloid's focal length R / 2.
  CHECK_THAT(ParaxialSystem(lens).efl_mm(), WithinRel(95.3, 1e-12));
  // Its name says "90 DEG ... 190.6": the beam, 190.6 mm off the parent's axis, turns through 90 degrees to a
  // focus its reflected focal length away, and a paraboloid's focus is perfect over the whole 50.8-mm beam.
  const SequentialTracer tracer(lens);
  for (double x : {-20.0, 0.0, 15.0}) {
    for (double y : {-22.0, 0.0, 10.0, 25.0}) {
      if (std::hypot(x, y) > 25.4) continue;
      Ray ray;
      ray.position_mm = Eigen::Vector3d(x, y, 0.0);
      ray.direction = Eigen::Vector3d::UnitZ();
      ray.wavelength_nm = lens.primary_wavelength_nm();
      std::vector<SurfaceHit> path;
      const TraceResult r = tracer.trace_forward(ray, &path);
      REQUIRE(r.ok());
      CHECK_THAT(r.ray.position_mm.x(), WithinAbs(0.0, 1e-9));
      CHECK_THAT(r.ray.position_mm.y(), WithinAbs(0.0, 1e-9));
      if (x == 0.0 && y == 0.0) {
        // The central ray: reflected at a right angle, 190.6 mm to the focus (the optical path after the
        // mirror, in air).
        REQUIRE(path.size() == 4);
        CHECK_THAT(r.optical_path_mm - path[2].optical_path_mm, WithinAbs(190.6, 1e-9));
        CHECK_THAT(path[2].direction_after.y(), WithinAbs(-1.0, 1e-12));
      }
    }
  }
}

TEST_CASE("Mirror systems with tilts and a toroid read, trace, and say where third-order theory stops",
          "[trace][real-files][mirror][coordinate-break][toroid]") {
  // Handbook of Optics' tilted two-mirror telescope: the designer decentred the image onto the chief ray, so
  // the axial chief ray lands at the image's origin; the toroidal secondary makes Seidel sums inapplicable.
  const Prescription tilted = read_real("HoO-V2C18Ex46.zmx").prescription;
  CHECK(tilted.surfaces[6].kind == SurfaceKind::Toroidal);
  CHECK(tilted.surfaces[6].mirror);
  CHECK_FALSE(tilted.is_rotationally_symmetric());
  const SequentialTracer tracer(tilted);
  const RayAimer aimer(tracer);
  const AimedRay chief = aimer.make_ray(aimer.field_at(0.0), {0.0, 0.0}, tilted.primary_wavelength_nm());
  REQUIRE(chief.ok());
  const TraceResult r = tracer.trace_forward(chief.ray);
  REQUIRE(r.ok());
  CHECK(std::hypot(r.ray.position_mm.x(), r.ray.position_mm.y()) < 1e-3);
  // US 8,011,793 example 1: a four-mirror objective of focal length 500 mm (the patent's), F/3.5.
  const Prescription patent = read_real("US08011793-1.zmx").prescription;
  const ParaxialSystem p(patent);
  CHECK_THAT(p.efl_mm(), WithinRel(500.0, 1e-5));
  CHECK_THAT(p.f_number(), WithinRel(3.5, 1e-12));
  CHECK(patent.ray_aiming == RayAiming::ParaxialEntrancePupil);  // real aiming is for symmetric refracting lenses
  // The Handbook's catadioptric F/1.25 objective (correctors, two mirrors, a relay doublet): its 1.5-degree field
  // is imaged within 1 um RMS.
  const Prescription catadioptric = read_real("HoO-V2C18Ex27.zmx").prescription;
  CHECK_THAT(ParaxialSystem(catadioptric).f_number(), WithinRel(1.25, 1e-12));
  const SequentialTracer cat(catadioptric);
  const RayAimer cat_aimer(cat);
  const AimedRay edge = cat_aimer.make_ray(cat_aimer.field_at(1.0), {0.0, 1.0}, catadioptric.primary_wavelength_nm());
  REQUIRE(edge.ok());
  CHECK(cat.trace_forward(edge.ray).ok());
}
