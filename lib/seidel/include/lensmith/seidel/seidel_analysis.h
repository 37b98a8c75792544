// Third-order (Seidel) aberrations of a prescription at one wavelength and object distance, from
// the paraxial marginal and chief rays: Welford's sums S_I..S_V and the primary colour sums C_I,
// C_II per surface (W. T. Welford, Aberrations of Optical Systems, 1986, ch. 8, eqs. 8.23-8.28 and
// 8.46; the conic/aspheric terms of sec. 8.5), their wavefront, transverse and longitudinal forms,
// and Petzval and field curvatures. Signs: a positive, undercorrected singlet has S_I > 0
// (conventions.h). Formulas in docs/seidel.md.
#pragma once

#include <array>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "lensmith/paraxial/paraxial_system.h"
#include "lensmith/prescription/prescription.h"

namespace lensmith {

// The five Seidel sums and the two primary chromatic sums, mm.
struct SeidelSums {
  double S1 = 0.0;  // spherical aberration
  double S2 = 0.0;  // coma
  double S3 = 0.0;  // astigmatism
  double S4 = 0.0;  // Petzval curvature
  double S5 = 0.0;  // distortion
  double C1 = 0.0;  // axial (longitudinal) colour, from dn = n(short) - n(long) (SeidelAnalysis::colour_wavelengths_nm)
  double C2 = 0.0;  // lateral (transverse) colour, the same dn

  SeidelSums& operator+=(const SeidelSums& o);
  friend SeidelSums operator+(SeidelSums a, const SeidelSums& b) { return a += b; }
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const SeidelSums& s) { return os << s.to_string(); }
};

// Wavefront aberration coefficients W_klm of W(h, rho, phi) = sum W_klm h^k rho^l cos^m(phi),
// h and rho normalised to the maximum field and the pupil edge (Welford eq. 8.30 ff.):
// W040 = S_I/8, W131 = S_II/2, W222 = S_III/2, W220 = (S_III + S_IV)/4, W311 = S_V/2,
// W020 = C_I/2, W111 = C_II (mm of optical path; divide by the wavelength for waves).
struct WavefrontCoefficients {
  double W040 = 0.0, W131 = 0.0, W222 = 0.0, W220 = 0.0, W311 = 0.0, W020 = 0.0, W111 = 0.0;
  WavefrontCoefficients in_waves(double wavelength_nm) const;
  std::string to_string() const;
};

// Third-order aberrations as ray errors on the paraxial image plane at full aperture and field, mm
// (Smith's and CODE V's transverse forms; u' = image-space marginal slope, n' its index):
// TSA = S_I/(2n'u'), TCO = 3 S_II/(2n'u') (tangential coma; sagittal coma is a third of it),
// TAS = (3 S_III + S_IV)/(2n'u'), SAS = (S_III + S_IV)/(2n'u'), PTB = S_IV/(2n'u'),
// DST = S_V/(2n'u'), TAX = C_I/(n'u') (transverse axial colour), TLAT = C_II/(n'u').
struct TransverseAberrations {
  double TSA = 0.0, TCO = 0.0, TAS = 0.0, SAS = 0.0, PTB = 0.0, DST = 0.0, TAX = 0.0, TLAT = 0.0;
  std::string to_string() const;
};

// Longitudinal forms: the focus shift along the axis, mm, = -transverse / u', so that a positive value
// is a focus behind (at +z of) the paraxial image: LSA (marginal focus; < 0 for an undercorrected
// lens), LTAS and LSAS (tangential and sagittal foci at full field), LPTZ (Petzval surface at full
// field) and LAX (axial colour: the F focus relative to the C focus).
struct LongitudinalAberrations {
  double LSA = 0.0, LTAS = 0.0, LSAS = 0.0, LPTZ = 0.0, LAX = 0.0;
  std::string to_string() const;
};

// Curvatures of the third-order image surfaces, 1/mm, as ray-optics and Sasian print them (positive
// when the surface curves toward the lens, i.e. its centre of curvature lies at -z, as the Petzval
// surface of a positive singlet does): TCV = (3 S_III + S_IV)/H^2, SCV = (S_III + S_IV)/H^2,
// PCV = S_IV/H^2, with H the Lagrange invariant.
struct FieldCurvatures {
  double tangential_per_mm = 0.0;
  double sagittal_per_mm = 0.0;
  double petzval_per_mm = 0.0;
  double petzval_radius_mm() const;  // -1 / petzval_per_mm (Smith's sign: < 0 for an inward-curving field)
  std::string to_string() const;
};

struct SeidelOptions {
  double wavelength_nm = 0.0;                  // 0 = the prescription's primary wavelength
  std::optional<double> object_distance_mm;    // empty = the prescription's
  std::optional<double> entrance_pupil_diameter_mm;  // override the aperture (mm)
  std::optional<double> f_number;              // override the aperture (image-space F/#)
  std::optional<double> field_angle_deg;       // override the maximum field (object-space angle)
  std::optional<double> object_height_mm;      // override the maximum field (finite object)
  // The short and long wavelengths (nm) whose index difference dn the colour sums C_I and C_II use.
  // Empty: the lens's own shortest and longest wavelengths, as CODE V computes its first-order colour
  // (F and C, hence n_F - n_C, for a lens at F, d, C or with fewer than two wavelengths).
  std::optional<std::array<double, 2>> colour_wavelengths_nm;
  void validate() const;                       // throws OptionsError naming the field
};

class SeidelAnalysis {
 public:
  // Throws ComputationError when the lens has no field and none is given (the chief ray is needed),
  // and what ParaxialSystem throws.
  SeidelAnalysis(const Prescription& lens, const SeidelOptions& options = {});

  double wavelength_nm() const { return paraxial_.wavelength_nm(); }
  const ParaxialSystem& paraxial() const { return paraxial_; }
  // Per surface, in surface order (surface k is index k-1).
  const std::vector<SeidelSums>& surfaces() const { return surfaces_; }
  // Aspheric (conic + even-asphere) part of each surface's contribution, included in surfaces().
  const std::vector<SeidelSums>& aspheric_parts() const { return aspheric_; }
  const SeidelSums& sums() const { return sums_; }
  double lagrange_invariant() const { return lagrange_; }
  double image_slope() const { return image_slope_; }   // u' of the marginal ray in image space
  double image_index() const { return image_index_; }   // n' in image space
  // The short and long wavelengths (nm) of the colour sums' dn.
  const std::array<double, 2>& colour_wavelengths_nm() const { return colour_wavelengths_nm_; }

  WavefrontCoefficients wavefront() const;
  TransverseAberrations transverse() const;
  LongitudinalAberrations longitudinal() const;
  FieldCurvatures field_curvatures() const;

  // A listing like CODE V's third-order output: per-surface S_I..S_V, C_I, C_II, the sums, then the
  // wavefront, transverse and longitudinal forms and the field curvatures.
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const SeidelAnalysis& s) { return os << s.to_string(); }

 private:
  ParaxialSystem paraxial_;
  std::vector<SeidelSums> surfaces_;
  std::vector<SeidelSums> aspheric_;
  SeidelSums sums_;
  double lagrange_ = 0.0;
  FieldCurvatures curvatures_;  // from the sums, or (on the axis, H = 0) from a nominal field
  double image_slope_ = 0.0;
  double image_index_ = 1.0;
  std::array<double, 2> colour_wavelengths_nm_{kWavelengthF_nm, kWavelengthC_nm};
};

}  // namespace lensmith
