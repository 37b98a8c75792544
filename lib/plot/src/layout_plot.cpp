// The lens layout picture (layout_plot.h).
#include "lensmith/plot/layout_plot.h"

#include "lensmith/core/units.h"

#include <algorithm>
#include <cmath>

#include "figure_parts.h"
#include "lensmith/plot/plot_axes.h"

namespace lensmith::plot {

using namespace detail;

namespace {

constexpr Rgb kGlass{0.82f, 0.89f, 0.97f};
constexpr Rgb kSurface{0.12f, 0.16f, 0.30f};
constexpr Rgb kDummy{0.6f, 0.6f, 0.6f};
constexpr double kWidthPx = 1100.0;
constexpr double kMaxSectionHeightPx = 720.0;
constexpr double kMarginPx = 50.0;

std::vector<Point2> to_pixels(const std::vector<LayoutPoint>& points, const LayoutFrame& f) {
  std::vector<Point2> out;
  for (const LayoutPoint& p : points) out.push_back(f.to_pixel(p.z_mm, p.y_mm));
  return out;
}

}  // namespace

Rgb field_colour(std::size_t field_index) {
  static constexpr Rgb kColours[] = {{0.08f, 0.25f, 0.88f}, {0.0f, 0.58f, 0.12f}, {0.85f, 0.08f, 0.08f}, {0.90f, 0.50f, 0.0f},
                                     {0.55f, 0.20f, 0.75f}, {0.0f, 0.60f, 0.65f}, {0.75f, 0.10f, 0.55f}, {0.45f, 0.35f, 0.10f}};
  return kColours[field_index % std::size(kColours)];
}

Canvas plot_lens_layout(const LensLayout& layout, const PlotOptions& o, LayoutFrame* frame_out) {
  // The section's extent: every surface, the image plane, and every drawn ray.
  // A coaxial lens is drawn symmetric about its axis; a folded or tilted one over what it occupies.
  double z_lo = kInfinity, z_hi = -kInfinity, y_lo = kInfinity, y_hi = -kInfinity;
  auto include = [&](const LayoutPoint& p) {
    z_lo = std::min(z_lo, p.z_mm);
    z_hi = std::max(z_hi, p.z_mm);
    y_lo = std::min(y_lo, p.y_mm);
    y_hi = std::max(y_hi, p.y_mm);
  };
  for (const LayoutPoint& p : layout.image_plane_ends) include(p);
  for (const LayoutSurface& s : layout.surfaces) {
    for (const LayoutPoint& p : s.profile) include(p);
  }
  for (const LayoutRay& r : layout.rays) {
    for (const LayoutPoint& p : r.path) include(p);
  }
  const double reach = std::max(std::abs(y_lo), std::abs(y_hi));
  if (y_lo < 0.0 && y_hi > 0.0 && std::min(-y_lo, y_hi) > 0.5 * reach) {
    y_lo = -reach;  // about the axis
    y_hi = reach;
  }
  const double stop_bar_mm = 0.12 * 0.5 * std::max(y_hi - y_lo, 1e-3);
  y_hi += stop_bar_mm;
  y_lo -= stop_bar_mm;
  const double z_span = std::max(z_hi - z_lo, 1e-3), y_span = std::max(y_hi - y_lo, 1e-3);
  const double scale = std::min((kWidthPx - 2.0 * kMarginPx) / z_span, kMaxSectionHeightPx / y_span);
  const double legend_y = header_height(o) + 0.6 * o.font_px;
  const double top = legend_y + 1.6 * o.font_px + 16.0;
  const double section_px = y_span * scale;
  const double bottom_px = 40.0 + 2.0 * o.font_px;  // the scale bar
  Canvas canvas = make_canvas(static_cast<int>(kWidthPx), static_cast<int>(std::ceil(top + section_px + bottom_px)), o);
  LayoutFrame frame;
  frame.px_per_mm = scale;
  frame.z_min_mm = z_lo;
  frame.left_px = 0.5 * (kWidthPx - z_span * scale);
  frame.axis_y_px = top + y_hi * scale;  // y = 0
  if (frame_out) *frame_out = frame;

  std::string details = "meridional section, equal scales; " + std::to_string(layout.rays.size() / std::max<std::size_t>(1, layout.relative_fields.size())) +
                        " rays per field from the pupil's edge to edge at " + wavelength_label(layout.wavelength_nm) +
                        ", real rays (exact tracer), each ending where it is stopped";
  if (layout.stop_surface) details += "; stop: surface " + std::to_string(*layout.stop_surface) + " (bars)";
  details += "; total track " + fixed(layout.total_track_mm, 2) + " mm";
  header(canvas, "Lens layout", layout.lens_name, details, o);

  // The axis, dashed, under everything.
  canvas.line(frame.to_pixel(z_lo, 0.0), frame.to_pixel(z_hi, 0.0), LineStyle{kDummy, 1.0, 10.0, 4.0});
  for (const LayoutElement& e : layout.elements) {
    const std::vector<Point2> outline = to_pixels(e.outline, frame);
    canvas.fill_polygon(outline, kGlass);
  }
  for (const LayoutElement& e : layout.elements) {
    std::vector<Point2> outline = to_pixels(e.outline, frame);
    outline.push_back(outline.front());
    canvas.polyline(outline, LineStyle{kSurface, 1.6});
  }
  for (const LayoutSurface& s : layout.surfaces) {
    const bool in_element =
        !s.mirror && (s.glass_after || (s.surface > 1 && layout.surfaces[static_cast<std::size_t>(s.surface - 2)].glass_after));
    if (in_element) continue;  // drawn with its element
    // An air-to-air surface (a dummy, or the stop's plane): a thin grey line; the stop gets bars below.
    if (s.mirror && s.profile.size() >= 2) {
      canvas.polyline(to_pixels(s.profile, frame), LineStyle{kSurface, 2.4});  // a mirror: solid
    } else if (!s.is_stop && s.profile.size() >= 2) {
      canvas.polyline(to_pixels(s.profile, frame), LineStyle{kDummy, 1.0, 4.0, 3.0});
    }
  }
  if (layout.stop_surface) {
    const LayoutSurface& s = layout.surfaces[static_cast<std::size_t>(*layout.stop_surface - 1)];
    // Bars outward from both ends of the stop's section, along it (a tilted stop's bars tilt with it).
    if (s.profile.size() >= 2) {
      for (const auto& [end, before] : {std::pair{s.profile.back(), s.profile[s.profile.size() - 2]}, std::pair{s.profile.front(), s.profile[1]}}) {
        const double dz = end.z_mm - before.z_mm, dy = end.y_mm - before.y_mm, length = std::hypot(dz, dy);
        if (!(length > 0.0)) continue;
        canvas.line(frame.to_pixel(end.z_mm, end.y_mm),
                    frame.to_pixel(end.z_mm + stop_bar_mm * dz / length, end.y_mm + stop_bar_mm * dy / length), LineStyle{kBlack, 3.5});
      }
    }
  }
  canvas.line(frame.to_pixel(layout.image_plane_ends[0].z_mm, layout.image_plane_ends[0].y_mm),
              frame.to_pixel(layout.image_plane_ends[1].z_mm, layout.image_plane_ends[1].y_mm), LineStyle{kBlack, 2.5});

  // Rays: the fields in order, outermost last so it stays on top; a dot where a ray was stopped.
  std::vector<LegendEntry> legend;
  for (std::size_t f = 0; f < layout.relative_fields.size(); ++f) {
    legend.push_back({"field " + (f < layout.field_labels.size() ? layout.field_labels[f] : fixed(layout.relative_fields[f], 2)),
                      LineStyle{field_colour(f), 2.0}});
  }
  for (const LayoutRay& r : layout.rays) {
    const auto it = std::find(layout.relative_fields.begin(), layout.relative_fields.end(), r.relative_field);
    const Rgb colour = field_colour(static_cast<std::size_t>(it - layout.relative_fields.begin()));
    const std::vector<Point2> path = to_pixels(r.path, frame);
    canvas.polyline(path, LineStyle{colour, 1.1});
    if (r.status != RayStatus::Ok && !path.empty()) canvas.fill_disc(path.back(), 2.5, colour);
  }
  legend.push_back({"ray stopped", LineStyle{kText, 2.0}, true});
  legend_row(canvas, {20.0, legend_y}, legend, o);

  // Scale bar: a nice length near a fifth of the section.
  const std::vector<double> ticks = nice_ticks(0.0, z_span, 5);
  const double bar_mm = ticks.size() > 1 ? ticks[1] - ticks[0] : z_span;
  const double bx = frame.left_px, by = canvas.height() - 22.0 - 0.5 * o.font_px;
  canvas.line({bx, by}, {bx + bar_mm * scale, by}, LineStyle{kText, 2.5});
  canvas.line({bx, by - 5.0}, {bx, by + 5.0}, LineStyle{kText, 1.5});
  canvas.line({bx + bar_mm * scale, by - 5.0}, {bx + bar_mm * scale, by + 5.0}, LineStyle{kText, 1.5});
  canvas.text({bx + bar_mm * scale + 10.0, by}, tick_label(bar_mm, bar_mm) + " mm", o.font_px * 0.9, kText, HAlign::Left, VAlign::Middle);
  return canvas;
}

}  // namespace lensmith::plot
