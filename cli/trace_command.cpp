// `lensmith trace`: one real ray through the lens, surface by surface, as a table or one JSON object
// (schema in docs/cli.md). A ray that dies is an answer (its status), not an error: exit status 0.
#include <cstdio>
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "lensmith/analysis/ray_trace_listing.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/json_text.h"

namespace lensmith::cli {

namespace {

using ojson = nlohmann::ordered_json;

// PX,PY as two numbers; false when the text is not that.
bool read_pupil(const std::string& text, PupilCoordinate& pupil) {
  char tail = 0;
  return std::sscanf(text.c_str(), "%lf,%lf%c", &pupil.px, &pupil.py, &tail) == 2;
}

ojson point_json(int surface, const Eigen::Vector3d& p, const Eigen::Vector3d& d) {
  return {{"surface", surface}, {"x_mm", p.x()}, {"y_mm", p.y()}, {"z_mm", p.z()}, {"l", d.x()}, {"m", d.y()}, {"n", d.z()}};
}

ojson field_json(const FieldPoint& f) {
  switch (f.kind) {
    case FieldPoint::Kind::AngleDeg: return {{"kind", "angle_deg"}, {"x", f.x}, {"y", f.y}};
    case FieldPoint::Kind::ObjectHeightMm: return {{"kind", "object_height_mm"}, {"x", f.x}, {"y", f.y}};
    case FieldPoint::Kind::ObjectPoint:
      return {{"kind", "object_point_mm"}, {"x", f.point_mm.x()}, {"y", f.point_mm.y()}, {"z", f.point_mm.z()}};
  }
  return nullptr;
}

ojson listing_json(const RayTraceListing& r, const std::string& aim) {
  ojson o;
  o["lens"] = r.lens_name;
  o["wavelength_nm"] = r.wavelength_nm;
  o["field"] = field_json(r.field);
  o["pupil"] = {{"px", r.pupil.px}, {"py", r.pupil.py}};
  o["aim"] = aim;
  o["image_plane_z_mm"] = r.image_plane_z_mm;
  o["status"] = std::string(to_string(r.status));
  o["surface"] = r.surface > 0 ? ojson(r.surface) : ojson(nullptr);
  const Eigen::Vector3d& p0 = r.object_ray.position_mm;
  const Eigen::Vector3d& d0 = r.object_ray.direction;
  o["start"] = {{"x_mm", p0.x()}, {"y_mm", p0.y()}, {"z_mm", p0.z()}, {"l", d0.x()}, {"m", d0.y()}, {"n", d0.z()}};
  ojson points = ojson::array();
  for (const SurfaceHit& h : r.hits) points.push_back(point_json(h.surface, h.point_mm, h.direction_after));
  o["points"] = points;
  if (r.folded) {
    ojson local = ojson::array();
    for (const SurfaceHit& h : r.local_hits) local.push_back(point_json(h.surface, h.point_mm, h.direction_after));
    o["points_local"] = local;
  }
  if (r.image) {
    o["image"] = {{"x_mm", r.image->x_mm}, {"y_mm", r.image->y_mm}, {"z_mm", r.image->z_mm},
                  {"l", r.image_direction.x()}, {"m", r.image_direction.y()}, {"n", r.image_direction.z()}};
  } else {
    o["image"] = nullptr;
  }
  return o;
}

}  // namespace

std::string check_pupil_text(const std::string& text) {
  PupilCoordinate p;
  if (!read_pupil(text, p)) return text + ": expected PX,PY, two numbers separated by a comma (e.g. 0,0.7)";
  if (!(p.px * p.px + p.py * p.py <= 1.0)) return text + ": must lie in the unit disc (px^2 + py^2 <= 1)";
  return {};
}

int run_trace(const TraceCommandOptions& options, const GlobalOptions& global) {
  const Prescription lens = load_lens(options.lens, global);
  RayTraceOptions trace;
  if (const std::string problem = check_pupil_text(options.pupil); !problem.empty()) throw UsageError("--pupil " + problem);
  (void)read_pupil(options.pupil, trace.pupil);
  trace.wavelength_nm = options.wavelength_nm;
  if (options.field_angle_deg) trace.field = FieldPoint::angle_deg(*options.field_angle_deg);
  if (options.object_height_mm) trace.field = FieldPoint::object_height_mm(*options.object_height_mm);
  if (options.relative_field) {
    RealRayCommandOptions common;
    common.relative_fields = {*options.relative_field};
    common.image = options.image;
    common.aim = options.aim;
    trace.field = AnalysisContext(lens, make_analysis_options(common)).field_at(*options.relative_field);
  }
  RealRayCommandOptions words;
  words.image = options.image;
  words.aim = options.aim;
  const AnalysisOptions analysis = make_analysis_options(words);
  trace.aiming = analysis.aiming;
  trace.image_plane = analysis.image_plane;
  const RayTraceListing listing = trace_ray_listing(lens, trace);
  if (options.json) {
    const RayAiming used = trace.aiming.value_or(lens.ray_aiming);
    std::cout << json_text(listing_json(listing, used == RayAiming::RealStop ? "real" : "paraxial"), 2) << "\n";
  } else {
    std::cout << listing.to_string();
  }
  return kExitOk;
}

}  // namespace lensmith::cli
