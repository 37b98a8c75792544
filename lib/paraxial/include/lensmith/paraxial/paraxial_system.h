// First-order (paraxial) optics of a prescription at one wavelength and object distance: the system
// matrix (Hecht, Optics, 5th ed., sec. 6.4; Marsicano 2023, eqs. 3.22-3.29), cardinal points,
// stop and pupils, f-numbers, the marginal- and chief-ray tables (Welford, Aberrations of Optical
// Systems, ch. 4) and the Lagrange invariant. Conventions: lensmith/core/conventions.h.
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "lensmith/prescription/prescription.h"

namespace lensmith {

// 2x2 paraxial matrix acting on (n u, y); see conventions.h.
struct SystemMatrix {
  double a11 = 1.0, a12 = 0.0, a21 = 0.0, a22 = 1.0;
  double determinant() const { return a11 * a22 - a12 * a21; }
  friend bool operator==(const SystemMatrix&, const SystemMatrix&) = default;
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const SystemMatrix& m) { return os << m.to_string(); }
};

// One row of a paraxial ray table: the ray at surface k (1-based).
struct ParaxialRayRow {
  int surface = 0;           // 1-based surface number
  double y_mm = 0.0;         // height at the vertex plane
  double u_after = 0.0;      // slope after refraction
  double i = 0.0;            // angle of incidence u_before + y c
  double n_after = 1.0;      // index after the surface
};

struct ParaxialRayTable {
  double object_distance_mm = kInfinity;  // object plane to surface 1 (+inf = object at infinity)
  double object_slope = 0.0;     // slope in object space
  double object_height_mm = 0.0; // height at the object plane (0 for an object at infinity)
  double y1_mm = 0.0;            // height at surface 1
  std::vector<ParaxialRayRow> rows;
  double image_height_mm = 0.0;  // height at the image plane
  std::string to_string() const;
};

struct Pupil {
  double z_mm = 0.0;         // z of the pupil (z = 0 at surface 1)
  double diameter_mm = 0.0;
  double magnification = 1.0;  // pupil diameter / stop diameter (paraxial, signed: < 0 = inverted image of the stop)
};

// Mirrors are unfolded as OpticStudio's paraxial trace does: after a reflection the index changes sign
// (n' = -n; thicknesses after an odd number of mirrors are negative), so a mirror of curvature c has the
// power -2 n c and every formula below holds as for a lens. Coordinate breaks are ignored (OpticStudio's
// default, "Paraxial: ignore coordinate breaks"): the first-order data of a folded or tilted system are those
// of the same surfaces on one axis. Toroidal and biconic surfaces are taken in one section.
struct ParaxialOptions {
  double wavelength_nm = 0.0;                 // 0 = the prescription's primary wavelength
  std::optional<double> object_distance_mm;   // empty = the prescription's (mm, +inf = infinity)
  // The section of toroidal and biconic surfaces: y (tangential, OpticStudio's paraxial section) or x. A
  // rotationally symmetric lens is the same in both.
  Section section = Section::Y;
  void validate() const;                      // throws OptionsError
};

// Everything first-order about a lens at one wavelength and object distance. All z are mm with
// z = 0 at the vertex of surface 1 (+z toward the image); focal lengths carry the sign of the
// power (a negative lens has efl_mm < 0).
class ParaxialSystem {
 public:
  // Throws ComputationError for systems without an answer (no power: afocal; a stop that cannot be
  // found because no surface has a semi-diameter), PrescriptionError via validate().
  ParaxialSystem(const Prescription& lens, const ParaxialOptions& options = {});

  double wavelength_nm() const { return wavelength_nm_; }
  double object_distance_mm() const { return object_distance_mm_; }
  const SystemMatrix& system_matrix() const { return matrix_; }
  double power_per_mm() const { return -matrix_.a12; }
  double efl_mm() const;               // 1 / power (in air on both sides: = front = rear focal length)
  double front_focal_length_mm() const;  // n_object / power
  double rear_focal_length_mm() const;   // n_image / power
  double bfl_mm() const;               // last vertex to rear focal point
  double ffl_mm() const;               // first vertex to front focal point (signed: < 0 in front)
  double z_front_focal_mm() const;
  double z_rear_focal_mm() const;
  double z_front_principal_mm() const;
  double z_rear_principal_mm() const;
  double z_front_nodal_mm() const;
  double z_rear_nodal_mm() const;
  double z_last_surface_mm() const;

  int stop_surface() const { return stop_surface_; }  // 1-based
  bool stop_was_flagged() const { return stop_flagged_; }
  // For an object-space telecentric lens the entrance pupil stands at z = 1e12 mm with the diameter
  // the NA gives there, so that every formula for a finite pupil holds; entrance_pupil_at_infinity()
  // says so, and reports print "at infinity".
  const Pupil& entrance_pupil() const { return entrance_pupil_; }
  bool entrance_pupil_at_infinity() const { return telecentric_; }
  const Pupil& exit_pupil() const { return exit_pupil_; }
  // f' / EPD, f' = n' EFL the image-space focal length (object at infinity; OpticStudio's "Image Space
  // F/#"; in air EFL / EPD). Irradiance and diffraction follow working_f_number() and image_space_na().
  double f_number() const;
  double working_f_number() const;     // 1 / (2 n' |u'|) of the marginal ray for this object distance
  double image_space_na() const;       // n' |u'| of the marginal ray (Smith's paraxial NA)
  // n' sin(arctan |u'|): the paraxial marginal ray's slope taken as an angle, as OpticStudio reports its
  // "Image Space NA" (Smith's triplet: 0.142822 against n'|u'| = 0.144296).
  double image_space_na_of_angle() const;

  const ParaxialRayTable& marginal_ray() const { return marginal_; }
  // Chief ray for the maximum field; empty when the prescription has no field.
  const std::optional<ParaxialRayTable>& chief_ray() const { return chief_; }
  // n (u_chief y_marginal - u_marginal y_chief); empty without a field.
  std::optional<double> lagrange_invariant() const;

  // Paraxial image of the object plane: distance from the last vertex to it (mm; for an object at
  // infinity this is the BFL), its z, and the lateral magnification (0 for an object at infinity).
  double image_distance_mm() const { return image_distance_mm_; }
  double z_image_mm() const;
  double magnification() const { return magnification_; }
  // Distance from the last vertex to the image plane where the prescription puts it (its last
  // thickness, or image_distance_mm() when the image sits at the paraxial focus).
  double image_plane_distance_mm() const { return image_plane_distance_mm_; }

  // Focus solve: last vertex to the paraxial image of an object at `object_distance_mm` from
  // surface 1 (+inf allowed): the lens-to-sensor distance that focuses it. Throws ComputationError
  // when the image is at infinity.
  double focus_image_distance_mm(double object_distance_mm) const;

  std::string to_string() const;  // readable summary table with units
  friend std::ostream& operator<<(std::ostream& os, const ParaxialSystem& p) { return os << p.to_string(); }

 private:
  // Implementation-defined members (the helper fills these in).
  double wavelength_nm_ = 0.0;
  double object_distance_mm_ = kInfinity;
  SystemMatrix matrix_;
  double n_object_ = 1.0;
  double n_image_ = 1.0;
  double z_last_mm_ = 0.0;
  int stop_surface_ = 0;
  bool stop_flagged_ = false;
  Pupil entrance_pupil_;
  Pupil exit_pupil_;
  double epd_mm_ = 0.0;
  ParaxialRayTable marginal_;
  std::optional<ParaxialRayTable> chief_;
  double image_distance_mm_ = 0.0;
  double magnification_ = 0.0;
  double image_plane_distance_mm_ = 0.0;
  std::vector<double> curvatures_;   // paraxial curvature per surface
  std::vector<double> thicknesses_;  // per surface
  std::vector<double> indices_;      // index after each surface at wavelength_nm_
  double z_front_focal_mm_ = 0.0;     // cardinal points, from the kernel shared with the spectral table
  double z_rear_focal_mm_ = 0.0;
  double z_front_principal_mm_ = 0.0;
  double z_rear_principal_mm_ = 0.0;
  double z_front_nodal_mm_ = 0.0;
  double z_rear_nodal_mm_ = 0.0;
  std::optional<double> stop_semi_diameter_mm_;  // the stop's clear semi-diameter, when given
  bool telecentric_ = false;                     // object-space telecentric: the entrance pupil at infinity
  bool mirrors_ = false;                         // mirrors unfolded (the listing says so)
  bool breaks_ignored_ = false;                  // tilting or decentring coordinate breaks ignored (the listing says so)
  std::string field_description_;    // the maximum field as the prescription states it, for to_string()
};

// The stop an iris opens for an image-space f-number (object at infinity, lens.aperture replaced by
// that f-number): the stop surface (1-based) and the paraxial marginal ray's height there, mm. One
// home for the camera (Camera::from_lens, which clips there) and the fits (LensFit::fit, which samples
// the beam it passes). Throws as ParaxialSystem does.
struct StopOpening {
  int surface = 0;
  double semi_diameter_mm = 0.0;
};
StopOpening stop_opened_to_f_number(const Prescription& lens, double f_number);

}  // namespace lensmith
