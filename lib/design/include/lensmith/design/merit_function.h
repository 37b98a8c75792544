// What an optimisation may change and what it measures: the variables of a lens (curvatures,
// thicknesses, conics, aspheric coefficients, model glasses) and the operands of its merit function
// (first-order data, Seidel sums, real-ray spot and wavefront, distortion, thickness and clear-aperture
// limits), each with a target or limits and a weight. The merit file is JSON: docs/optimize.md.
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "lensmith/prescription/prescription.h"

namespace lensmith {

// One number of the prescription that the optimiser may change.
struct DesignVariable {
  enum class Kind {
    Curvature,   // surface curvature c, 1/mm (the y section's for a toroid or biconic)
    Thickness,   // the distance after the surface, mm (the last surface's: the image distance)
    Conic,       // conic constant k
    Asphere,     // even-asphere coefficient of r^asphere_power, mm^(1 - asphere_power)
    GlassIndex,  // nd of the model glass after the surface (Glass::model), at 587.56 nm
    GlassAbbe,   // Vd of the same model glass
  };
  Kind kind = Kind::Curvature;
  int surface = 1;            // 1-based surface number
  int asphere_power = 4;      // Asphere: 4, 6, ..., 16
  std::optional<double> min;  // bounds in the variable's unit; empty = unbounded
  std::optional<double> max;

  // The variable's value in `lens`. A glass variable reads nd or Vd of the surface's glass, whatever kind.
  double value(const Prescription& lens) const;
  // Sets it in `lens` (a glass variable makes the surface's medium a model glass, keeping the other of nd
  // and Vd). Does not validate.
  void apply(Prescription& lens, double value) const;
  // "curvature of surface 2", "nd of the glass after surface 3".
  std::string name() const;
  std::string unit() const;  // "1/mm", "mm", "" (conic, nd, Vd), "mm^-3" (a4)
  friend bool operator==(const DesignVariable&, const DesignVariable&) = default;
};

// Something the merit function measures. Scalar operands contribute weight (value - target)^2, or, with
// limits instead of a target, weight (value - limit)^2 only while the limit is broken. The spot and
// wavefront operands are minimised: every ray contributes, so that their sum is weight x RMS^2.
struct Operand {
  enum class Kind {
    Efl,              // effective focal length, mm (paraxial, primary wavelength)
    FNumber,          // paraxial image-space f-number (ParaxialSystem::f_number)
    WorkingFNumber,   // paraxial working f-number at the lens's object distance
    Bfl,              // back focal length: last vertex to the paraxial focus, mm
    TotalTrack,       // first vertex to image plane, mm
    ImageDistance,    // last vertex to image plane minus the paraxial image distance, mm (0: in paraxial focus)
    Seidel,           // one Seidel sum, mm (term: S1 ... S5, C1, C2)
    SpotRms,          // real-ray RMS spot radius over fields and wavelengths, mm (minimised)
    WavefrontRms,     // real-ray RMS wavefront error over fields and wavelengths, waves (minimised)
    Distortion,       // real-ray distortion at one relative field, percent
    CentreThickness,  // the thickness after a surface, mm
    EdgeThickness,    // the same at a height (default: the smaller semi-diameter of the two surfaces), mm
    RayHeight,        // the largest |height| at a surface of the marginal and chief rays of the fields, mm
  };
  Kind kind = Kind::Efl;
  std::optional<double> target;
  std::optional<double> min;
  std::optional<double> max;
  double weight = 1.0;
  int surface = 0;                              // CentreThickness, EdgeThickness, RayHeight: 1-based
  std::string term;                             // Seidel: S1, S2, S3, S4, S5, C1, C2
  std::vector<double> relative_fields{0.0, 0.7, 1.0};  // SpotRms, WavefrontRms, RayHeight; Distortion: the first
  std::vector<double> wavelengths_nm;           // SpotRms, WavefrontRms: empty = the lens's
  // SpotRms, WavefrontRms: each field's and each wavelength's weight (>= 0, not all 0), one per field and per
  // wavelength; empty = equal. The operand's value is then the weighted RMS: each (field, wavelength) pair's
  // mean square weighted by the product of its two weights (OpticStudio's field and wavelength weights).
  std::vector<double> field_weights;
  std::vector<double> wavelength_weights;
  int rings = 4;                                // SpotRms: hexapolar rings (1 + 3 rings (rings + 1) rays)
  int grid = 12;                                // WavefrontRms: pupil samples across
  bool centroid_reference = true;               // SpotRms: about the polychromatic centroid (else the chief ray)
  std::optional<double> height_mm;              // EdgeThickness: where, mm

  // True for the operands whose contribution is a vector of per-ray residuals (SpotRms, WavefrontRms).
  bool is_minimised() const { return kind == Kind::SpotRms || kind == Kind::WavefrontRms; }
  // "EFL", "spot RMS (3 fields, 3 wavelengths)", "edge thickness after surface 4".
  std::string label() const;
  std::string unit() const;
  // "= 100", ">= 1", "<= 120", "1 to 2", "min" (minimised).
  std::string goal() const;
  friend bool operator==(const Operand&, const Operand&) = default;
};

// A number of the prescription set from the others instead of varied: a surface's curvature solved so that
// the lens's EFL (paraxial, primary wavelength) is exactly the target, as OpticStudio's marginal-ray-angle
// and CODE V's UMC solves hold a focal length. It removes the focal length from the merit function, so the
// optimiser moves along lenses of that focal length instead of down a narrow valley about them.
struct EflSolve {
  int surface = 1;      // 1-based; its curvature is solved (the system power is affine in one surface's curvature)
  double efl_mm = 0.0;  // the EFL to hold, mm (nonzero)
  // Sets the curvature. Throws ComputationError when this surface cannot change the power (no index change
  // across it, or its power does not reach the system's: a surface at a focal point).
  void apply(Prescription& lens) const;
  friend bool operator==(const EflSolve&, const EflSolve&) = default;
};

struct MeritFunction {
  std::vector<DesignVariable> variables;
  std::vector<Operand> operands;
  // What relative field 1 means, object-space degrees, for lenses whose file has no field (else the lens's).
  std::optional<double> field_angle_deg;
  std::optional<EflSolve> efl_solve;  // applied after the variables, before the operands are measured

  // Throws OptionsError naming the variable or operand and what is wrong with it for this lens (a surface
  // number out of range, a thickness of the last surface of a lens whose image sits at the paraxial focus,
  // the same variable twice, a Seidel term of a lens without rotational symmetry, no variables, a solved
  // curvature that is also a variable, ...).
  void validate(const Prescription& lens) const;
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const MeritFunction& m) { return os << m.to_string(); }
};

// Reads a merit file (docs/optimize.md). Throws FileError with file:line:column and what was
// expected, IoError when the file cannot be read.
MeritFunction read_merit_function(const std::string& path);
MeritFunction parse_merit_function(std::string_view text, const std::string& file_name);

}  // namespace lensmith
