#include "lensmith/camera/aperture.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>

#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/units.h"

namespace lensmith {

namespace {

// Corner k of a regular polygon inscribed in the unit circle, angle measured from +x.
double corner_angle(int k, int blades, double rotation_deg) {
  return kPi / 2.0 + rad_from_deg(rotation_deg) + 2.0 * kPi * k / blades;
}

double triangle_area(const PupilPoint& a, const PupilPoint& b, const PupilPoint& c) {
  return 0.5 * std::abs((b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y));
}

}  // namespace

Aperture Aperture::circular() {
  Aperture a;
  a.kind_ = Kind::Circular;
  a.effective_area_ = kPi;
  return a;
}

Aperture Aperture::blades(int blades, double rotation_deg) {
  if (blades < 3 || blades > 64) {
    throw OptionsError("aperture blades must be between 3 and 64 (got " + std::to_string(blades) + "); leave it out for a circular iris");
  }
  if (!std::isfinite(rotation_deg)) throw OptionsError("blade rotation must be a finite angle in degrees");
  Aperture a;
  a.kind_ = Kind::Blades;
  a.blades_ = blades;
  a.rotation_deg_ = rotation_deg;
  a.effective_area_ = 0.5 * blades * std::sin(2.0 * kPi / blades);
  return a;
}

Aperture Aperture::mask(int width, int height, std::vector<float> transmission) {
  if (width < 2 || height < 2 || transmission.size() != static_cast<std::size_t>(width) * height) {
    throw OptionsError("aperture mask must be at least 2 x 2 samples with one value per sample");
  }
  double sum = 0.0;
  for (float t : transmission) {
    if (!(std::isfinite(t) && t >= 0.0f)) throw OptionsError("aperture mask values must be finite and >= 0");
    sum += t;
  }
  if (!(sum > 0.0)) throw OptionsError("aperture mask is black everywhere: no light would pass");
  Aperture a;
  a.kind_ = Kind::Mask;
  a.mask_width_ = width;
  a.mask_height_ = height;
  a.mask_ = std::move(transmission);
  a.effective_area_ = 4.0 * sum / static_cast<double>(a.mask_.size());
  return a;
}

double Aperture::edge_radius(double theta_rad) const {
  if (kind_ == Kind::Circular) return 1.0;
  if (kind_ == Kind::Blades) {
    // Distance to the polygon edge: apothem / cos(angle from the edge's normal).
    const double sector = 2.0 * kPi / blades_;
    const double start = corner_angle(0, blades_, rotation_deg_);
    double local = std::fmod(theta_rad - start, sector);
    if (local < 0.0) local += sector;
    return std::cos(0.5 * sector) / std::cos(local - 0.5 * sector);
  }
  throw ComputationError("a mask aperture has no single edge radius");
}

std::vector<PupilPoint> Aperture::outline(int min_vertices) const {
  if (kind_ == Kind::Mask) throw ComputationError("a mask aperture has no polygon outline");
  std::vector<PupilPoint> out;
  const int per_edge = kind_ == Kind::Blades ? std::max(1, (min_vertices + blades_ - 1) / blades_) : 1;
  const int n = kind_ == Kind::Blades ? per_edge * blades_ : std::max(3, min_vertices);
  out.reserve(static_cast<std::size_t>(n));
  const double start = kind_ == Kind::Blades ? corner_angle(0, blades_, rotation_deg_) : kPi / 2.0;
  for (int k = 0; k < n; ++k) {
    const double theta = start + 2.0 * kPi * k / n;
    const double r = edge_radius(theta);
    out.push_back({r * std::cos(theta), r * std::sin(theta)});
  }
  // Blade outlines: points placed by angle lie on the straight edges, corners included exactly.
  return out;
}

double Aperture::transmission(const PupilPoint& p) const {
  if (kind_ == Kind::Mask) {
    if (p.x < -1.0 || p.x > 1.0 || p.y < -1.0 || p.y > 1.0) return 0.0;
    const int col = std::min(mask_width_ - 1, static_cast<int>((p.x + 1.0) * 0.5 * mask_width_));
    const int row = std::min(mask_height_ - 1, static_cast<int>((1.0 - p.y) * 0.5 * mask_height_));
    return mask_[static_cast<std::size_t>(row) * mask_width_ + col];
  }
  const double r = std::hypot(p.x, p.y);
  if (r == 0.0) return 1.0;
  return r <= edge_radius(std::atan2(p.y, p.x)) ? 1.0 : 0.0;
}

double Aperture::effective_area() const { return effective_area_; }

PupilMesh Aperture::mesh(int rings, int sectors) const {
  if (rings < 1 || sectors < 3) throw OptionsError("a pupil mesh needs at least 1 ring and 3 sectors");
  PupilMesh m;
  if (kind_ == Kind::Mask) {
    // Cartesian grid of rings x rings cells; each cell's weight is its mean transmission (sampled
    // 4 x 4 inside the cell), split between its two triangles.
    const int n = rings;
    m.rings = n;
    for (int j = 0; j <= n; ++j) {
      for (int i = 0; i <= n; ++i) m.points.push_back({-1.0 + 2.0 * i / n, 1.0 - 2.0 * j / n});
    }
    double total = 0.0;
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        double t = 0.0;
        for (int sy = 0; sy < 4; ++sy) {
          for (int sx = 0; sx < 4; ++sx) {
            t += transmission({-1.0 + 2.0 * (i + (sx + 0.5) / 4.0) / n, 1.0 - 2.0 * (j + (sy + 0.5) / 4.0) / n});
          }
        }
        if (t <= 0.0) continue;
        const int p00 = j * (n + 1) + i, p10 = p00 + 1, p01 = p00 + n + 1, p11 = p01 + 1;
        m.triangles.push_back({p00, p10, p11, t / 32.0});
        m.triangles.push_back({p00, p11, p01, t / 32.0});
        total += t / 16.0;
      }
    }
    for (auto& tri : m.triangles) tri.weight /= total;
    return m;
  }
  // Polar mesh: centre, then `rings` rings scaled to the edge, vertices placed on the outline.
  const std::vector<PupilPoint> edge = outline(sectors);
  const int s = static_cast<int>(edge.size());
  m.rings = rings;
  m.sectors = s;
  m.points.push_back({0.0, 0.0});
  for (int k = 1; k <= rings; ++k) {
    const double f = static_cast<double>(k) / rings;
    for (const PupilPoint& e : edge) m.points.push_back({f * e.x, f * e.y});
  }
  auto index = [s](int ring, int j) { return 1 + (ring - 1) * s + (j % s); };
  double total = 0.0;
  for (int j = 0; j < s; ++j) {
    m.triangles.push_back({0, index(1, j), index(1, j + 1), 0.0});
    for (int k = 1; k < rings; ++k) {
      m.triangles.push_back({index(k, j), index(k + 1, j), index(k + 1, j + 1), 0.0});
      m.triangles.push_back({index(k, j), index(k + 1, j + 1), index(k, j + 1), 0.0});
    }
  }
  for (auto& tri : m.triangles) {
    tri.weight = triangle_area(m.points[tri.a], m.points[tri.b], m.points[tri.c]);
    total += tri.weight;
  }
  for (auto& tri : m.triangles) tri.weight /= total;
  return m;
}

std::string PupilMesh::to_string() const {
  std::ostringstream os;
  os << "PupilMesh(" << points.size() << " points, " << triangles.size() << " triangles, " << rings << " rings, "
     << sectors << " sectors)";
  return os.str();
}

std::string Aperture::to_string() const {
  switch (kind_) {
    case Kind::Circular: return "circular";
    case Kind::Blades: return std::to_string(blades_) + " blades at " + format_number(rotation_deg_) + " deg";
    case Kind::Mask: return "mask " + std::to_string(mask_width_) + " x " + std::to_string(mask_height_);
  }
  return "aperture";
}

double disc_clearance(const PupilPoint& p, std::span<const PupilDisc> discs, double radius_scale) {
  double c = 1.0;
  for (const PupilDisc& d : discs) {
    const double dx = p.x - d.x, dy = p.y - d.y;
    c = std::min(c, 1.0 - std::sqrt(dx * dx + dy * dy) / (radius_scale * d.radius));
  }
  return c;
}

double pupil_polygon_area(const std::vector<PupilPoint>& v) {
  const std::size_t n = v.size();
  if (n == 0) return 0.0;
  double twice = 0.0;
  // Edge (i - 1, i) for every i, the closing edge first: no modulo in the loop (the renderer
  // measures every vignetted footprint's passing share with it).
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) twice += v[j].x * v[i].y - v[i].x * v[j].y;
  return 0.5 * std::abs(twice);
}

void clip_pupil_polygon(const std::vector<PupilPoint>& convex, std::span<const PupilDisc> discs, std::vector<PupilPoint>& out,
                        std::vector<PupilPoint>& work) {
  constexpr double kArcStepRad = 0.1;  // a chord 0.1 rad long departs from its arc by 1/800 of the radius
  out = convex;
  for (const PupilDisc& d : discs) {
    work.clear();
    const std::size_t n = out.size();
    if (n < 3) break;
    const double r2 = d.radius * d.radius;
    auto inside = [&d, r2](const PupilPoint& q) { return (q.x - d.x) * (q.x - d.x) + (q.y - d.y) * (q.y - d.y) <= r2; };
    // Where the segment a -> b crosses the circle (the root in [0, 1] of |a + t (b - a) - c| = R).
    auto crossing = [&d](const PupilPoint& a, const PupilPoint& b, bool entering) {
      const double ex = b.x - a.x, ey = b.y - a.y, fx = a.x - d.x, fy = a.y - d.y;
      const double qa = ex * ex + ey * ey, qb = 2.0 * (fx * ex + fy * ey), qc = fx * fx + fy * fy - d.radius * d.radius;
      const double root = std::sqrt(std::max(0.0, qb * qb - 4.0 * qa * qc));
      const double t = std::clamp(entering ? (-qb - root) / (2.0 * qa) : (-qb + root) / (2.0 * qa), 0.0, 1.0);
      return PupilPoint{a.x + t * ex, a.y + t * ey};
    };
    // Whether the segment a -> b comes within the circle (touching counts where `touch`): its point
    // nearest the centre.
    auto meets = [&d, r2](const PupilPoint& a, const PupilPoint& b, bool touch) {
      const double ex = b.x - a.x, ey = b.y - a.y;
      const double t = std::clamp(((d.x - a.x) * ex + (d.y - a.y) * ey) / (ex * ex + ey * ey), 0.0, 1.0);
      const double gx = a.x + t * ex - d.x, gy = a.y + t * ey - d.y;
      return touch ? gx * gx + gy * gy <= r2 : gx * gx + gy * gy < r2;
    };
    // The exit point of the arc being drawn, while outside.
    std::optional<PupilPoint> exit;
    double orientation = 0.0;
    for (std::size_t i = 0; i < n; ++i) orientation += out[i].x * out[(i + 1) % n].y - out[(i + 1) % n].x * out[i].y;
    auto arc = [&](const PupilPoint& from, const PupilPoint& to) {
      // Along the circle from `from` to `to` in the polygon's winding.
      const double a0 = std::atan2(from.y - d.y, from.x - d.x);
      double sweep = std::atan2(to.y - d.y, to.x - d.x) - a0;
      if (orientation > 0.0) {
        while (sweep < 0.0) sweep += 2.0 * kPi;
      } else {
        while (sweep > 0.0) sweep -= 2.0 * kPi;
      }
      const int steps = static_cast<int>(std::ceil(std::abs(sweep) / kArcStepRad));
      // Rotate the radius vector step by step (no trigonometry per point).
      const double c = std::cos(sweep / steps), sn = std::sin(sweep / steps);
      double vx = from.x - d.x, vy = from.y - d.y;
      for (int k = 1; k < steps; ++k) {
        const double nx = c * vx - sn * vy;
        vy = sn * vx + c * vy;
        vx = nx;
        work.push_back({d.x + vx, d.y + vy});
      }
    };
    // Start at a vertex inside, if any; a polygon wholly outside the disc may still contain it.
    std::size_t start = n;
    for (std::size_t i = 0; i < n; ++i) {
      if (inside(out[i])) {
        start = i;
        break;
      }
    }
    if (start == n) {
      bool any_crossing = false;
      for (std::size_t i = 0; i < n && !any_crossing; ++i) {
        any_crossing = meets(out[i], out[(i + 1) % n], true);
      }
      if (!any_crossing) {
        // Disjoint, or the disc lies inside the polygon: then the disc itself is what passes.
        const PupilPoint centre{d.x, d.y};
        bool contains = true;
        for (std::size_t i = 0; i < n; ++i) {
          const PupilPoint& a = out[i];
          const PupilPoint& b = out[(i + 1) % n];
          contains = contains && ((b.x - a.x) * (centre.y - a.y) - (b.y - a.y) * (centre.x - a.x)) * orientation >= 0.0;
        }
        if (contains) {
          const int steps = static_cast<int>(std::ceil(2.0 * kPi / kArcStepRad));
          for (int k = 0; k < steps; ++k) {
            const double a = 2.0 * kPi * k / steps * (orientation > 0.0 ? 1.0 : -1.0);
            work.push_back({d.x + d.radius * std::cos(a), d.y + d.radius * std::sin(a)});
          }
        }
        out.swap(work);
        continue;
      }
      // Edges cross the disc although no vertex lies in it: walk from vertex 0, outside.
      start = 0;
    }
    bool was_inside = inside(out[start]);
    std::optional<PupilPoint> first_exit;  // when the walk starts outside
    for (std::size_t step = 0; step <= n; ++step) {
      const PupilPoint& a = out[(start + step) % n];
      if (step == n) break;
      const PupilPoint& b = out[(start + step + 1) % n];
      const bool b_inside = inside(b);
      if (was_inside) {
        work.push_back(a);
        if (!b_inside) exit = crossing(a, b, false);
      } else if (b_inside) {
        const PupilPoint entry = crossing(a, b, true);
        if (exit) {
          work.push_back(*exit);
          arc(*exit, entry);
        }
        work.push_back(entry);
        exit.reset();
      } else {
        // Both outside: the edge may still pass through the disc.
        if (meets(a, b, false)) {
          const PupilPoint entry = crossing(a, b, true);
          if (exit) {
            work.push_back(*exit);
            arc(*exit, entry);
          } else if (!first_exit) {
            first_exit = entry;  // nothing before it: the arc into it is closed at the end
          }
          work.push_back(entry);
          exit = crossing(a, b, false);
        }
      }
      was_inside = b_inside;
    }
    // Close the arc from the last exit to the walk's first point on the circle.
    if (exit && !work.empty()) {
      work.push_back(*exit);
      arc(*exit, first_exit ? *first_exit : work.front());
    }
    out.swap(work);
  }
}

}  // namespace lensmith
