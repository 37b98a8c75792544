// Private to lib/paraxial: the wavelength-dependent first-order kernel that ParaxialSystem and
// ParaxialSpectralTable share. Pure functions on flat arrays, no allocation, so the spectral table
// can run it 64 times per lens. Formulas: Hecht, Optics, 5th ed., sec. 6.4 (system matrix);
// Welford, Aberrations of Optical Systems, ch. 4 (cardinal points, pupils). Signs: conventions.h.
#pragma once

#include <cstddef>
#include <span>
#include <vector>
#include <string>

#include "lensmith/paraxial/paraxial_system.h"

#include "lensmith/prescription/prescription.h"

namespace lensmith::paraxial_detail {

// |power| below this fraction of the sum of the surface powers |P_k| means "afocal": the focal
// length would exceed the longest surface focal length by more than 10^10, which no lens has and
// which rounding alone produces for a telescope whose powers cancel.
inline constexpr double kAfocalRelativePower = 1.0e-10;

// +1 or -1 per surface: the sign of the index after it in the unfolded system (-1 after an odd number of
// mirrors, counting the surface itself).
std::vector<double> reflection_signs(const Prescription& lens);

// |n' u'| of the axial ray below this fraction of its two terms means "image at infinity" (the
// object sits in the front focal plane); the same relative test is used for pupils at infinity.
inline constexpr double kAtInfinityRelative = 1.0e-12;

// Matrices of a lens at one wavelength (conventions.h: state (n u, y)).
struct KernelMatrices {
  SystemMatrix system;  // just before vertex 1 -> just after the last vertex
  SystemMatrix front;   // just before vertex 1 -> just before the stop vertex (stop refraction excluded)
  SystemMatrix rear;    // just after the stop refraction -> just after the last vertex
  double sum_abs_surface_power_per_mm = 0.0;  // sum |P_k|, the scale for the afocal test
};

// curvatures, thicknesses and indices (the index after each surface) have one entry per surface;
// stop_index is 0-based. Only the first size-1 thicknesses are used (the last is the image gap).
KernelMatrices compose_matrices(std::span<const double> curvatures_per_mm, std::span<const double> thicknesses_mm,
                                std::span<const double> indices_after, double n_object, std::size_t stop_index);

// Cardinal points from the system matrix; z in mm from vertex 1. Throws ComputationError when the
// system is afocal (see kAfocalRelativePower).
struct CardinalPoints {
  double power_per_mm = 0.0;
  double z_front_focal_mm = 0.0;
  double z_rear_focal_mm = 0.0;
  double z_front_principal_mm = 0.0;
  double z_rear_principal_mm = 0.0;
  double z_front_nodal_mm = 0.0;
  double z_rear_nodal_mm = 0.0;
};
CardinalPoints cardinal_points(const KernelMatrices& m, double n_object, double n_image, double z_last_mm);

// Pupils as images of the stop: z (mm from vertex 1) and magnification (pupil size / stop size).
// A pupil at infinity (telecentric side) has z = +-infinity and magnification +-infinity.
struct PupilImages {
  double z_entrance_mm = 0.0;
  double entrance_magnification = 1.0;
  double z_exit_mm = 0.0;
  double exit_magnification = 1.0;
};
PupilImages pupil_images(const KernelMatrices& m, double n_object, double n_image, double z_last_mm);

// Paraxial image of the object plane at object_distance_mm before vertex 1 (+inf allowed).
struct ImageConjugate {
  double image_distance_mm = 0.0;  // last vertex to the image (the BFL for an object at infinity)
  double magnification = 0.0;      // n u / (n' u') of the axial ray; 0 for an object at infinity
};
// Throws ComputationError when the image lies at infinity (object in the front focal plane).
ImageConjugate image_conjugate(const SystemMatrix& system, double n_object, double n_image,
                               double object_distance_mm);

// Listing formatters shared by ParaxialSystem and ParaxialSpectralTable: fixed decimals, with
// infinities spelled out and a value that rounds to zero printed as 0, not -0.
std::string format_fixed(double value, int decimals);
// `text` right-aligned in `width` characters.
std::string right_aligned(const std::string& text, std::size_t width);

}  // namespace lensmith::paraxial_detail
