// The lens layout: the meridional (y-z) cross-section designers look at first. Each surface as its
// sag curve z(y) across its clear semi-diameter, the glass elements between them, the stop, the image
// plane, and a few real ray bundles traced by the exact tracer (Kingslake, Lens Design Fundamentals,
// ch. 1 draws lenses this way; OpticStudio's "Cross-Section" layout). Plain data for lensmith/plot.
#pragma once

#include <array>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "lensmith/analysis/analysis_context.h"

namespace lensmith {

struct LayoutOptions {
  // Pupil points per bundle, evenly from py = -1 to +1 along the tangential direction (px = 0), 1-101.
  int rays_per_field = 5;
  void validate() const;  // throws OptionsError naming the field
};

// A point of the section: z along the axis, y up (global frame of `lensmith info --json`), mm.
struct LayoutPoint {
  double z_mm = 0.0;
  double y_mm = 0.0;
};

struct LayoutSurface {
  int surface = 0;                      // 1-based
  double vertex_z_mm = 0.0;
  // Drawn half-height, mm: the clear semi-diameter, or (without one) the largest height of a drawn
  // ray there, or the paraxial |y marginal| + |y chief|; never beyond where the sag is defined.
  double semi_diameter_mm = 0.0;
  bool semi_diameter_given = false;     // false: estimated from the rays as above
  bool is_stop = false;
  bool glass_after = false;             // the medium after this surface is not air
  bool mirror = false;                  // reflects (drawn as a solid line)
  std::vector<LayoutPoint> profile;     // the sag curve from -semi_diameter to +semi_diameter
  double edge_z_mm() const;             // z of the profile's ends (vertex + sag at the semi-diameter)
};

// A glass element: the surfaces that bound one glass (a cemented doublet is two elements sharing a surface).
struct LayoutElement {
  int front_surface = 0;  // 1-based
  int back_surface = 0;
  std::string glass;
  // Closed outline: the front profile, the flat edge at the larger semi-diameter, the back profile.
  std::vector<LayoutPoint> outline;
};

struct LayoutRay {
  double relative_field = 0.0;
  double pupil_py = 0.0;
  RayStatus status = RayStatus::Ok;
  int surface = 0;                   // where it died; 0 when it reached the image plane
  std::vector<LayoutPoint> path;     // object-space start, every surface reached, the image plane (when ok)
};

struct LensLayout {
  std::string lens_name;
  double wavelength_nm = 0.0;        // the reference (primary) wavelength the rays are traced at
  std::vector<double> relative_fields;
  std::vector<std::string> field_labels;  // per relative field, "14.00 deg"
  std::vector<LayoutSurface> surfaces;
  std::vector<LayoutElement> elements;
  std::optional<int> stop_surface;   // 1-based, the paraxial stop
  double image_plane_z_mm = 0.0;
  double image_half_height_mm = 0.0;  // the image plane is drawn from -this to +this
  // The drawn image plane's two ends in the global section (on the line z = image_plane_z_mm of a coaxial
  // lens; where the plane lies in a folded or tilted system).
  std::array<LayoutPoint, 2> image_plane_ends{};
  double total_track_mm = 0.0;        // first vertex to the image plane
  std::vector<LayoutRay> rays;        // per field, rays_per_field rays from py = -1 to +1
  std::string to_string() const;      // elements, stop, total track: a short text summary
  friend std::ostream& operator<<(std::ostream& os, const LensLayout& l) { return os << l.to_string(); }
};

// The section of `context`'s lens with a bundle per relative field of the context, traced at its
// reference wavelength with its aiming. Dead rays end where they died. Throws OptionsError.
LensLayout compute_lens_layout(const AnalysisContext& context, const LayoutOptions& options = {});

}  // namespace lensmith
