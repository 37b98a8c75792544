// A surface's explicit aperture in JSON, as the native lens format writes it (docs/lens-format.md,
// "Apertures") and as fit files carry the apertures they clip at (docs/polyfit.md):
// {"shape": "circular", "radius_mm": 12, "min_radius_mm": 3} or {"shape": "rectangular"|"elliptical",
// "half_x_mm", "half_y_mm"}, with "obscuration" and the decentres "decenter_x_mm", "decenter_y_mm".
#pragma once

#include <string>

#include "lensmith/core/located_json.h"
#include "lensmith/prescription/surface.h"

namespace lensmith {

// Reads the object at `pointer` (`path` in messages); strict: unknown keys and impossible shapes are
// errors with file:line:col.
SurfaceAperture read_surface_aperture(const LocatedJson& doc, const std::string& pointer, const std::string& path);

// The object read_surface_aperture reads back (nlohmann::json or ordered_json).
template <class Json>
Json surface_aperture_json(const SurfaceAperture& a) {
  Json ap;
  if (a.shape == SurfaceAperture::Shape::Circular) {
    ap["shape"] = "circular";
    ap["radius_mm"] = a.half_x_mm;
    if (a.min_radius_mm > 0.0) ap["min_radius_mm"] = a.min_radius_mm;
  } else {
    ap["shape"] = a.shape == SurfaceAperture::Shape::Rectangular ? "rectangular" : "elliptical";
    ap["half_x_mm"] = a.half_x_mm;
    ap["half_y_mm"] = a.half_y_mm;
  }
  if (a.obscuration) ap["obscuration"] = true;
  if (a.decenter_x_mm != 0.0) ap["decenter_x_mm"] = a.decenter_x_mm;
  if (a.decenter_y_mm != 0.0) ap["decenter_y_mm"] = a.decenter_y_mm;
  return ap;
}

}  // namespace lensmith
