// A sequential lens prescription: surfaces object side first, the object-space medium, and the
// system data a designer sets (aperture, field, wavelengths, object distance). It validates itself.
// Formats: docs/lens-format.md (native JSON), Zemax .zmx, pbrt .dat, lentil lenses.json.
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "lensmith/core/diagnostic.h"
#include "lensmith/core/units.h"
#include "lensmith/prescription/material.h"
#include "lensmith/prescription/surface.h"

namespace lensmith {

// How the size of the axial beam is set.
struct ApertureSpec {
  enum class Kind {
    EntrancePupilDiameter,  // value = entrance-pupil diameter, mm
    // value = f' / EPD for an object at infinity, f' = n' EFL the image-space focal length (OpticStudio's
    // "Image Space F/#"; in air f' = EFL)
    ImageSpaceFNumber,
    FloatByStop,            // the stop's semi-diameter sets the beam; value unused
    // value = 1 / (2 n' |u'|) of the paraxial marginal ray at the prescription's object distance
    // (OpticStudio's "Paraxial Working F/#")
    ParaxialWorkingFNumber,
    // value = n sin(theta) of the ray from the axial object point to the edge of the paraxial
    // entrance pupil (finite object only; OpticStudio's "Object Space NA")
    ObjectSpaceNA,
    // value = theta in degrees, the same ray's angle to the axis (finite object; "Object Cone Angle")
    ObjectConeAngleDeg,
  };
  Kind kind = Kind::FloatByStop;
  double value = 0.0;

  friend bool operator==(const ApertureSpec&, const ApertureSpec&) = default;
  std::string to_string() const;
};

// OpticStudio's vignetting factors of one field point: they shrink and shift the pupil that real-ray
// analyses sample, so that normalised pupil coordinates (px, py) mean the ray at
// (vdx + px (1 - vcx), vdy + py (1 - vcy)), turned by van_deg about the pupil centre. CODE V's VUY, VLY,
// VUX, VLX (the pupil cut from its upper, lower, right and left edges) are vdy = (VLY - VUY) / 2,
// vcy = (VUY + VLY) / 2 and the same in x. Fields lie along +y here: x is sagittal, y tangential.
struct VignettingFactors {
  double vdx = 0.0;
  double vdy = 0.0;
  double vcx = 0.0;
  double vcy = 0.0;
  double van_deg = 0.0;
  bool is_none() const { return vdx == 0.0 && vdy == 0.0 && vcx == 0.0 && vcy == 0.0 && van_deg == 0.0; }
  friend bool operator==(const VignettingFactors&, const VignettingFactors&) = default;
};

// The field of view: a kind and the field points (the largest |value| is the maximum field).
struct FieldSpec {
  enum class Kind {
    AngleDeg,        // object-space chief-ray angle, degrees (object at infinity or finite)
    ObjectHeightMm,  // object height, mm (finite object only)
    ImageHeightMm,   // paraxial image height, mm
    // real image height, mm: where the real chief ray meets the image plane. Only ray tracing can turn
    // it into object-space field points: resolve_real_image_height_field (lensmith/trace/ray_aiming.h)
    // does, and lens loading calls it; paraxial optics refuses a lens whose field is still of this kind.
    RealImageHeightMm,
  };
  Kind kind = Kind::AngleDeg;
  std::vector<double> values;  // field points, at least one; units per kind
  // Empty, or one set per field point: the pupil real-ray analyses sample at that field (between field
  // points the factors are interpolated linearly in |field|, beyond the last one held).
  std::vector<VignettingFactors> vignetting{};
  // The factors at a field value (units of the kind): none when the field has none.
  VignettingFactors vignetting_at(double value) const;

  double max_value() const;    // largest |value|
  friend bool operator==(const FieldSpec&, const FieldSpec&) = default;
  std::string to_string() const;
};

// How rays are made from pupil coordinates (the file's "ray aiming": Zemax RAIM, CODE V's default).
enum class RayAiming {
  ParaxialEntrancePupil,  // aim at (px, py) * EP radius on the paraxial entrance-pupil plane (Zemax "off")
  // Solve for the real ray that crosses the stop surface at (px, py) * stop radius: backward from the stop point
  // by damped Newton on its stop-space direction, with continuation in pupil and field, then a forward check
  // (docs/trace.md, "Real-stop aiming"). Fails cleanly where no physical ray exists.
  RealStop,
};

struct Prescription {
  std::string name;
  std::string source;  // patent, book and page, or URL
  std::string notes;

  std::vector<Surface> surfaces;        // object side first; surface k of the docs is surfaces[k-1]
  MaterialSpec object_material;         // object-space medium (air unless immersion)
  Glass object_medium = Glass::air();   // object_material resolved

  // Distance from the object plane to the vertex of surface 1, mm; +infinity = object at infinity.
  double object_distance_mm = kInfinity;
  // When true the image plane sits at the paraxial focus of the primary wavelength and the last
  // surface's thickness_mm is not used (pbrt files and lenses whose file gives no image distance).
  bool image_at_paraxial_focus = false;

  ApertureSpec aperture;
  std::optional<FieldSpec> field;       // absent when the source gives none
  std::vector<double> wavelengths_nm{kWavelengthF_nm, kWavelengthD_nm, kWavelengthC_nm};
  std::size_t primary_wavelength_index = 1;  // into wavelengths_nm
  // The ray aiming the file asks for: real-ray analyses use it unless told otherwise (--aim).
  RayAiming ray_aiming = RayAiming::ParaxialEntrancePupil;
  // Object-space telecentric (OpticStudio's FTYP flag): the entrance pupil is at infinity, every chief
  // ray leaves the object parallel to the axis whatever the stop's position. Needs a finite object, an
  // object-space NA or cone-angle aperture and an object- or image-height field.
  bool object_space_telecentric = false;

  double primary_wavelength_nm() const { return wavelengths_nm.at(primary_wavelength_index); }
  // 0-based index of the surface flagged as stop, or empty when none is flagged.
  std::optional<std::size_t> flagged_stop_index() const;
  // z of the vertex of surface k (0-based index), mm, z = 0 at surface 1: the sum of the thicknesses before
  // it. In a coaxial system (no tilted or decentred coordinate break) that is where the vertex lies, mirrors
  // included (after a mirror thicknesses are negative); otherwise it is a position along the folded path
  // only, and surface_frames (lensmith/trace/surface_frames.h) places the surfaces.
  double vertex_z_mm(std::size_t surface_index) const;
  // Reflecting surfaces: an odd count turns the image to face back toward the object.
  int mirror_count() const;
  bool has_mirrors() const { return mirror_count() > 0; }
  // No coordinate break decentres or tilts anything: every surface is centred on one z axis.
  bool is_coaxial() const;
  // Coaxial, and every surface rotationally symmetric (no toroid or biconic with unequal sections): what
  // third-order (Seidel) theory and the rotationally symmetric analyses and fits assume.
  bool is_rotationally_symmetric() const;
  // Some surface has unequal x and y sections (a toroid, biconic or cylinder): first-order data differ per
  // section (ParaxialOptions::section), the x section's focal length giving an anamorphic's squeeze.
  bool is_anamorphic() const;
  // Why not, naming the first surface that breaks the symmetry ("surface 3 is toroidal"); empty when it is.
  std::optional<std::string> why_not_rotationally_symmetric() const;
  // Why real-stop ray aiming does not apply ("it has mirrors", or why_not_rotationally_symmetric): the
  // real-stop solver follows rays backward from the stop along one axis, so it is implemented for
  // rotationally symmetric refracting lenses only (docs/trace.md, "Ray aiming"). Empty when it applies.
  std::optional<std::string> why_no_real_ray_aiming() const;
  // z of the last vertex, mm.
  double last_vertex_z_mm() const;

  // Throws PrescriptionError naming the surface (1-based) or system field and the violated
  // constraint, e.g. "surface 3: semi_diameter_mm = -2: must be > 0". Checks: at least one surface,
  // finite curvatures and thicknesses, positive semi-diameters, at most one stop, conic and
  // asphere coefficients finite, indices > 0 at the primary wavelength, aperture value > 0 and a
  // stop semi-diameter when the aperture floats by stop, field values finite and an object-height
  // field only for a finite object, wavelengths in (100, 20000) nm, primary index in range,
  // object distance > 0.
  void validate() const;
  // What a glassmaker could not build, as warnings naming the surfaces (validate() accepts it: a
  // negative air space is a legitimate way to write some designs): a glass element of negative
  // centre thickness, and consecutive surfaces that cross within their common clear aperture (a
  // negative edge thickness: an element or two elements overlapping). Needs semi-diameters for the
  // edge check; surfaces without one are checked at the vertex only.
  Diagnostics geometry_warnings() const;

  // Resolves every MaterialSpec against `catalogue` (throws GlassError with the surface number). Mirrors
  // and coordinate breaks take the medium before them.
  void resolve_materials(const GlassCatalog& catalogue);

  // Every length multiplied by `factor` > 0 (radii, thicknesses, semi-diameters, aspheric terms,
  // finite object distance, EPD and object/image-height fields). Throws PrescriptionError.
  Prescription scaled(double factor) const;

  friend bool operator==(const Prescription&, const Prescription&) = default;
  std::string to_string() const;  // a surface table, for test failures and debugging
  friend std::ostream& operator<<(std::ostream& os, const Prescription& p) { return os << p.to_string(); }
};

// The surfaces of a lens between the coordinate breaks at its ends, as a coaxial lens of their own: a
// tilt-shift lens's elements, turned or moved as a whole by the breaks before them and put square to the
// camera's axis again by those after them. What a polynomial fit describes (docs/polyfit.md, "Tilt-shift
// lenses"): the breaks are rigid motions, applied exactly where the fit is used.
struct CoaxialCore {
  std::size_t first = 0;  // 0-based index in the whole lens of the core's surface 1
  // The core: the whole lens's surfaces from `first` to the last one that is not a coordinate break, with
  // the lens's object space (its distance grown by the leading breaks' thicknesses), stop and wavelengths;
  // the last surface's thickness grown by the trailing breaks' (the image distance along the core's axis).
  Prescription lens;
};

// The core of `lens`; the lens itself (first = 0) when no break stands at its ends. Empty when a break
// that turns or moves something lies between two surfaces that are not breaks (a fold inside the lens),
// or the lens has no surface that is not a break.
std::optional<CoaxialCore> coaxial_core(const Prescription& lens);

}  // namespace lensmith
