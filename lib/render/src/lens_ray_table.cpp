// Lens rays as lines in the pinhole image, tabulated over the film (lens_ray_table.h).
#include "lens_ray_table.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "lensmith/camera/lens_camera.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"

namespace lensmith {

namespace {

// Direction tangents of a line through the pinhole as a function of inverse depth: tan(w) = a + w b.
struct TangentLine {
  double a_x = 0.0, a_y = 0.0, b_x = 0.0, b_y = 0.0;
};

PixelRay pixel_ray(const TangentLine& line, const PinholeFrame& frame, double weight) {
  const double f = frame.focal_length_px();
  PixelRay r;
  r.inf_x = static_cast<float>(0.5 * frame.width_px() + line.a_x * f);
  r.inf_y = static_cast<float>(0.5 * frame.height_px() - line.a_y * f);
  r.k_x = static_cast<float>(line.b_x * f);
  r.k_y = static_cast<float>(-line.b_y * f);
  r.weight = static_cast<float>(weight);
  return r;
}

}  // namespace

struct LensRayTable::Source {
  virtual ~Source() = default;
  // The ray of `sample` from film point (x, y) (mm, lens frame), weight 0 where the lens stops it.
  virtual PixelRay ray(double film_x_mm, double film_y_mm, const LensSample& sample, double wavelength_nm) const = 0;
};

namespace {

// exact and poly: LensCamera's backward trace. A point X = O + t D of the ray (mm, camera frame)
// has tangents X_xy / X_z; with w = 1 / X_z they are D_xy / D_z + w (O_xy - O_z D_xy / D_z).
class CameraSource final : public LensRayTable::Source {
 public:
  CameraSource(const RayModel& model, const std::vector<double>& wavelengths_nm, bool vignetting)
      : camera_(model.kind() == RayModelKind::Poly ? LensCamera(model.camera(), model.fit(), wavelengths_nm)
                                                   : LensCamera(model.camera(), wavelengths_nm)),
        vignetting_(vignetting) {}
  PixelRay ray(double fx, double fy, const LensSample& s, double wavelength_nm) const override {
    const CameraRaySample r = camera_.sample_ray(fx, fy, s.u, s.v, wavelength_nm);
    if (!r.ok()) return {};
    const Eigen::Vector3d o = r.ray.origin_m * 1000.0, &d = r.ray.direction;
    if (!(d.z() > 0.0)) return {};
    TangentLine line;
    line.a_x = d.x() / d.z();
    line.a_y = d.y() / d.z();
    line.b_x = o.x() - o.z() * line.a_x;
    line.b_y = o.y() - o.z() * line.a_y;
    return pixel_ray(line, camera_.camera().frame(), vignetting_ ? r.ray.weight : 1.0);
  }

 private:
  LensCamera camera_;
  bool vignetting_;
};

// Iterations of InverseSource::solve.
constexpr int kSolveIterations = 16;

// thin, paraxial, seidel: the forward map inverted at two depths.
class InverseSource final : public LensRayTable::Source {
 public:
  InverseSource(const RayModel& model, const Aperture& aperture, const std::vector<double>& wavelengths_nm, bool vignetting,
                const render_detail::IlluminationTable* illumination)
      : model_(model), aperture_(aperture), vignetting_(vignetting), illumination_(illumination) {
    const Camera& camera = model.camera();
    // The focus plane, where the model's rays of one film point meet (so in-focus detail stays as
    // sharp as the model makes it), and infinity; a camera focused at infinity: 10 m instead.
    w_near_ = inverse_per_mm(camera.focus_distance_mm());
    if (!(w_near_ > 0.0)) w_near_ = inverse_depth_per_mm(10.0);
    // d(film point)/d(tangent) near the axis at both depths, per wavelength: the Newton step's
    // Jacobian (rotational symmetry makes it a scalar to first order).
    for (double wl : wavelengths_nm) {
      std::array<double, 2> j{};
      for (int k = 0; k < 2; ++k) {
        const double w = k == 0 ? w_near_ : 0.0, h = 1e-3;
        const PupilPoint centre{0.0, 0.0};
        SensorHit a, b;
        model.map({0.0, 0.0, w}, wl, {&centre, 1}, {&a, 1});
        model.map({h, 0.0, w}, wl, {&centre, 1}, {&b, 1});
        j[static_cast<std::size_t>(k)] = (b.x_mm - a.x_mm) / h;
        if (!(std::abs(j[static_cast<std::size_t>(k)]) > 1e-9)) {
          throw ComputationError("multiview: the " + std::string(to_string(model.kind())) + " model maps no field at " +
                                 std::to_string(wl) + " nm");
        }
      }
      jacobian_.push_back(j);
    }
    // The mean transmission over the sampled domain (the unit disc; a mask: [-1, 1]^2), so that
    // every aperture passes the light of the f-number's disc, as the scatter path's weights do.
    if (aperture.kind() == Aperture::Kind::Circular) {
      mean_transmission_ = 1.0;
    } else {
      double sum = 0.0;
      const int n = 256;
      for (int i = 0; i < n; ++i) {
        for (int k = 0; k < n; ++k) sum += aperture.transmission(pupil({(i + 0.5) / n, (k + 0.5) / n, 0}));
      }
      mean_transmission_ = sum / (n * n);
      if (!(mean_transmission_ > 0.0)) throw OptionsError("the aperture passes no light");
    }
  }

  PupilPoint pupil(const LensSample& s) const {
    if (aperture_.kind() == Aperture::Kind::Mask) return {2.0 * s.u - 1.0, 2.0 * s.v - 1.0};
    const double r = std::sqrt(s.u), phi = 2.0 * std::numbers::pi * s.v;
    return {r * std::cos(phi), r * std::sin(phi)};
  }

  PixelRay ray(double fx, double fy, const LensSample& s, double wavelength_nm) const override {
    const PupilPoint rho = pupil(s);
    const double transmission = aperture_.transmission(rho);
    if (!(transmission > 0.0)) return {};
    const auto& j = jacobian_[static_cast<std::size_t>(s.node)];
    double t1x = fx / j[0], t1y = fy / j[0];
    SensorHit hit;
    if (!solve(fx, fy, rho, w_near_, wavelength_nm, j[0], t1x, t1y, hit, false)) return {};
    const double weight = vignetting_ ? hit.weight : 1.0;
    // Clear apertures of the first-order models, at the focus-plane point: the model's discs, or
    // widened where they pass far less than the real lens (a retrofocus's frame edge was black:
    // IlluminationTable).
    thread_local std::vector<PupilDisc> discs;
    const ScenePoint near{t1x, t1y, w_near_};
    model_.clip_discs(near, discs);
    const bool widened = illumination_ != nullptr && illumination_->widen(near, discs);
    if (disc_clearance(rho, discs) < 0.0) return {};
    // At infinity the model's own discs still stop the ray (as before), but where the focus-plane
    // point's discs were widened: those would stop what the widened ones pass.
    double t2x = fx / j[1], t2y = fy / j[1];
    SensorHit far;
    if (!solve(fx, fy, rho, 0.0, wavelength_nm, j[1], t2x, t2y, far, !widened)) return {};
    TangentLine line;
    line.a_x = t2x;
    line.a_y = t2y;
    line.b_x = (t1x - t2x) / w_near_;
    line.b_y = (t1y - t2y) / w_near_;
    return pixel_ray(line, model_.camera().frame(), weight * transmission / mean_transmission_);
  }

 private:
  // Tangents (tx, ty) at inverse depth w whose ray through `rho` lands on (fx, fy): Newton from the
  // axial Jacobian, then secant steps (the slope along the last step: the guess lies on the film
  // point's azimuth, so the steps are radial); false when the iteration does not settle, or where
  // `clipped`, when the model's discs stop the ray. With the axial Jacobian alone a model with a
  // retrofocus's 16 % barrel (Seidel, lentil 0005) converged too slowly to settle in its iterations
  // beyond 40 deg, and the frame's edge was black.
  bool solve(double fx, double fy, const PupilPoint& rho, double w, double wavelength_nm, double jacobian, double& tx, double& ty,
             SensorHit& hit, bool clipped) const {
    double slope = jacobian, last_tx = 0.0, last_ty = 0.0, last_x = 0.0, last_y = 0.0;
    for (int iteration = 0; iteration < kSolveIterations; ++iteration) {
      if (clipped) {
        model_.map({tx, ty, w}, wavelength_nm, {&rho, 1}, {&hit, 1});
      } else {
        model_.map_passing({tx, ty, w}, wavelength_nm, {&rho, 1}, {&hit, 1});
      }
      if (!hit.ok || !std::isfinite(hit.x_mm) || !std::isfinite(hit.y_mm)) return false;
      const double rx = fx - hit.x_mm, ry = fy - hit.y_mm;
      if (rx * rx + ry * ry < 1e-14) return true;  // 0.1 nm on the film
      if (iteration > 0) {
        const double dtx = tx - last_tx, dty = ty - last_ty, step = dtx * dtx + dty * dty;
        const double secant = ((hit.x_mm - last_x) * dtx + (hit.y_mm - last_y) * dty) / step;
        // Only a slope of the axial one's sign and size (within a factor of 8): a fold or a
        // rounding-sized step would send the next guess anywhere.
        if (step > 0.0 && std::isfinite(secant) && secant / jacobian > 0.125 && secant / jacobian < 8.0) slope = secant;
      }
      last_tx = tx;
      last_ty = ty;
      last_x = hit.x_mm;
      last_y = hit.y_mm;
      tx += rx / slope;
      ty += ry / slope;
    }
    return false;
  }

  const RayModel& model_;
  const Aperture& aperture_;
  bool vignetting_;
  const render_detail::IlluminationTable* illumination_;
  double w_near_ = 0.0;
  double mean_transmission_ = 1.0;
  std::vector<std::array<double, 2>> jacobian_;
};

}  // namespace

LensRayTable::LensRayTable(const RayModel& model, const Aperture& aperture, std::vector<double> wavelengths_nm,
                           std::vector<LensSample> samples, const LensRayTableOptions& options)
    : samples_(std::move(samples)), wavelengths_nm_(std::move(wavelengths_nm)) {
  if (options.grid_px < 1) throw OptionsError("the lens ray grid step must be at least 1 px");
  const bool traced = model.kind() == RayModelKind::Exact || model.kind() == RayModelKind::Poly;
  if (traced && aperture.kind() != Aperture::Kind::Circular) {
    throw OptionsError("--method multiview with --model " + std::string(to_string(model.kind())) + " and a " + aperture.to_string() +
                       " aperture: not implemented (its rays sample the lens's own circular stop); use --model seidel, paraxial or thin, "
                       "or --method scatter");
  }
  if (traced) source_ = std::make_unique<CameraSource>(model, wavelengths_nm_, options.vignetting);
  else source_ = std::make_unique<InverseSource>(model, aperture, wavelengths_nm_, options.vignetting, options.illumination);

  const PinholeFrame& frame = model.camera().frame();
  camera_ = &model.camera();
  width_ = frame.width_px();
  height_ = frame.height_px();
  grid_ = options.grid_px;
  nodes_x_ = (width_ - 1 + grid_ - 1) / grid_ + 1;
  nodes_y_ = (height_ - 1 + grid_ - 1) / grid_ + 1;
  const std::size_t per_sample = static_cast<std::size_t>(nodes_x_) * static_cast<std::size_t>(nodes_y_);
  grid_rays_.assign(per_sample * samples_.size(), PixelRay{});
  const long long total = static_cast<long long>(grid_rays_.size());
  const int threads = options.threads > 0 ? options.threads : 0;
#pragma omp parallel for schedule(dynamic, 256) num_threads(threads > 0 ? threads : omp_get_max_threads())
  for (long long i = 0; i < total; ++i) {
    const std::size_t j = static_cast<std::size_t>(i) / per_sample, node = static_cast<std::size_t>(i) % per_sample;
    const double x = static_cast<double>(node % static_cast<std::size_t>(nodes_x_)) * grid_ + 0.5;
    const double y = static_cast<double>(node / static_cast<std::size_t>(nodes_x_)) * grid_ + 0.5;
    grid_rays_[static_cast<std::size_t>(i)] = direct_ray(x, y, j);
  }
  direct_rays_ = 0;
}

LensRayTable::~LensRayTable() = default;

std::size_t LensRayTable::direct_rays() const { return direct_rays_.load(std::memory_order_relaxed); }

PixelRay LensRayTable::direct_ray(double x_px, double y_px, std::size_t j) const {
  const LensSample& s = samples_[j];
  const auto [fx, fy] = camera_->sensor_point_mm({x_px, y_px});
  return source_->ray(fx, fy, s, wavelengths_nm_[static_cast<std::size_t>(s.node)]);
}

double LensRayTable::mean_weight(double x_px, double y_px, std::span<const LensSample> samples) const {
  if (samples.empty()) return 0.0;
  const auto [fx, fy] = camera_->sensor_point_mm({x_px, y_px});
  double sum = 0.0;
  for (const LensSample& s : samples) sum += source_->ray(fx, fy, s, wavelengths_nm_[static_cast<std::size_t>(s.node)]).weight;
  return sum / static_cast<double>(samples.size());
}

PixelRay LensRayTable::ray(int x, int y, std::size_t j) const {
  const int ix = x / grid_, iy = y / grid_;
  const int ix1 = std::min(ix + 1, nodes_x_ - 1), iy1 = std::min(iy + 1, nodes_y_ - 1);
  const float tx = static_cast<float>(x - ix * grid_) / static_cast<float>(grid_);
  const float ty = static_cast<float>(y - iy * grid_) / static_cast<float>(grid_);
  const PixelRay* base = grid_rays_.data() + j * static_cast<std::size_t>(nodes_x_) * static_cast<std::size_t>(nodes_y_);
  const PixelRay& a = base[static_cast<std::size_t>(iy) * nodes_x_ + ix];
  const PixelRay& b = base[static_cast<std::size_t>(iy) * nodes_x_ + ix1];
  const PixelRay& c = base[static_cast<std::size_t>(iy1) * nodes_x_ + ix];
  const PixelRay& d = base[static_cast<std::size_t>(iy1) * nodes_x_ + ix1];
  if (tx == 0.0f && ty == 0.0f) return a;
  const int stopped_corners = (a.weight <= 0.0f) + (b.weight <= 0.0f) + (c.weight <= 0.0f) + (d.weight <= 0.0f);
  // Stopped at every corner: stopped inside (the region where a pupil sample passes is convex
  // enough over a cell that no beam edge enters and leaves between corners).
  if (stopped_corners == 4) return {};
  if (stopped_corners > 0) {
    // The beam's edge crosses this cell: the pixel's own ray.
    direct_rays_.fetch_add(1, std::memory_order_relaxed);
    return direct_ray(x + 0.5, y + 0.5, j);
  }
  const float wa = (1 - tx) * (1 - ty), wb = tx * (1 - ty), wc = (1 - tx) * ty, wd = tx * ty;
  PixelRay r;
  r.inf_x = wa * a.inf_x + wb * b.inf_x + wc * c.inf_x + wd * d.inf_x;
  r.inf_y = wa * a.inf_y + wb * b.inf_y + wc * c.inf_y + wd * d.inf_y;
  r.k_x = wa * a.k_x + wb * b.k_x + wc * c.k_x + wd * d.k_x;
  r.k_y = wa * a.k_y + wb * b.k_y + wc * c.k_y + wd * d.k_y;
  r.weight = wa * a.weight + wb * b.weight + wc * c.weight + wd * d.weight;
  return r;
}

}  // namespace lensmith
