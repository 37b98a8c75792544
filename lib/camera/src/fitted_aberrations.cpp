// Third-order coefficients fitted to real rays, for the seidel model (RayModelOptions::
// seidel_coefficients, docs/bokeh.md "Seidel coefficients").
//
// Why: Asberg's method (Marsicano 2023, sec. 3.10) moves each ray by the third-order aberration
// vector computed from the Seidel sums. A corrected lens balances its third-order aberrations against
// higher orders: the pbrt double Gauss at f/2 has a third-order transverse spherical aberration of
// -0.102 mm at the rim of the pupil, while its real marginal ray misses the paraxial focus by
// +0.044 mm (and by -0.007 mm at half the pupil, where the third order dominates). The truncated
// vector blurs a point on the focus plane to a 50 um RMS spot where the real lens gives 13 um
// (`lensmith validate pbrt-dgauss-50mm --focus 1.2`). Welford (Aberrations of Optical Systems,
// 1986, sec. 8.4) and Born & Wolf (sec. 5.5) both warn that the Seidel terms describe a well
// corrected system only near its axis and at small apertures.
//
// What: at one field the aberration vector is linear in its terms (FieldTerms: B, C y0^2, D y0^2,
// E y0^3, F y0), and so is the sensor point of Asberg's construction (SeidelRayGeometry), so the
// terms that bring the model's rays closest to the exact tracer's in the least-squares sense solve
// a small linear system. The fit is made at the camera's sensor (where the picture is formed), per
// object distance of the model's table, at fields from the axis to the table's maximum field (the
// frame's corner) and a few wavelengths, over a pupil grid at the camera's f-number, with the rays
// the real lens passes; pupil points correspond through the aperture stop (the exact model's
// normalisation), so pupil aberrations that move a defocused beam are fitted too. Fitting per field
// rather than one polynomial in y0 for the whole frame matters for wide-angle lenses, whose
// aberrations grow faster than y0^3 towards the corner: one global fit trades the centre's accuracy
// for the corner's. The spot's shape (the hits less their centroid) fixes the pupil-dependent terms,
// the centroid the distortion. Between the fitted wavelengths the terms themselves are interpolated
// linearly. On the axis the radial term (D y0^2, zero in the sums) carries the real lens's best
// focus shift.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

#include "lensmith/core/grid_interval.h"
#include "model_implementations.h"

namespace lensmith::camera_detail {

namespace {

// Wavelengths of the table at which the terms are fitted (its first, last and evenly between).
constexpr int kFitWavelengths = 5;
// Fields per distance and wavelength, at y0 = k / (kFitFields - 1).
constexpr int kFitFields = 9;
// Cells per axis of the pupil lattice; the fit uses its corners inside the unit disc (113 of 169).
constexpr int kFitPupilGrid = 12;
// A field needs at least this many passing rays (each gives two equations for five unknowns); with
// fewer it keeps the sums.
constexpr int kMinFitRays = 16;
// Where fewer rays than this pass the full grid in either model, the grid is laid again over the box
// around what passes.
constexpr std::size_t kDenseBelow = 48;
// A fit whose spot over the model's own passing pupil reaches more than this many times as far as
// the real spot's and the sums' (plus a pixel) is extrapolating where no real ray passed: the field
// keeps its sums.
constexpr double kExtrapolationGrowth = 1.5;
// Where the real rays reach less than this pupil radius, the spherical term (rho^3) is not fitted.
constexpr double kSphericalReach = 0.5;
// Ridge added to the normal equations, relative to their mean diagonal: keeps a term the rays do not
// see (coma and distortion on the axis) at zero instead of at noise.
constexpr double kRidge = 1e-9;


// The corners of a kFitPupilGrid x kFitPupilGrid lattice of equal cells over [x0, x1] x [y0, y1],
// row by row ((kFitPupilGrid + 1)^2 points, those outside the unit pupil too: the light integrates
// over cells that the iris cuts).
void pupil_lattice(double x0, double x1, double y0, double y1, std::vector<PupilPoint>& out) {
  out.clear();
  for (int j = 0; j <= kFitPupilGrid; ++j) {
    for (int i = 0; i <= kFitPupilGrid; ++i) {
      out.push_back({x0 + (x1 - x0) * i / kFitPupilGrid, y0 + (y1 - y0) * j / kFitPupilGrid});
    }
  }
}

bool in_pupil(const PupilPoint& q) { return q.x * q.x + q.y * q.y <= 1.0; }

// The light a model passes through the lattice `pupil` (pupil_lattice) with `hits`: each cell as
// two triangles, each passing the share of its area where the linear interpolation of its corners'
// clearances (with the iris's, 1 - |q|) is >= 0 (passing_share), times its corners' mean weight.
// Counting passing lattice points instead would step by a whole cell wherever the edge of a
// vignetted beam crosses one: on a 12 x 12 grid the light of the Canon 35 mm's defocused corner
// beams wobbled by up to 8 % from field to field, and a uniform sky came out in bands.
double lattice_light(const std::vector<PupilPoint>& pupil, const std::vector<SensorHit>& hits, double cell_area) {
  const auto side = static_cast<std::size_t>(kFitPupilGrid) + 1;
  auto clearance = [&](std::size_t p) {
    const double iris = 1.0 - std::hypot(pupil[p].x, pupil[p].y);
    return hits[p].ok || hits[p].unclipped ? std::min(hits[p].clearance, iris) : std::min(-1.0, iris);
  };
  auto weight = [&](std::size_t a, std::size_t b, std::size_t c) {
    double sum = 0.0;
    int count = 0;
    for (const std::size_t p : {a, b, c}) {
      if (!(hits[p].ok || hits[p].unclipped)) continue;
      sum += hits[p].weight;
      ++count;
    }
    return count > 0 ? sum / count : 0.0;
  };
  double light = 0.0;
  for (std::size_t j = 0; j + 1 < side; ++j) {
    for (std::size_t i = 0; i + 1 < side; ++i) {
      const std::size_t a = j * side + i, b = a + 1, c = a + side, d = c + 1;
      light += 0.5 * cell_area * passing_share(clearance(a), clearance(b), clearance(d)) * weight(a, b, d);
      light += 0.5 * cell_area * passing_share(clearance(a), clearance(d), clearance(c)) * weight(a, d, c);
    }
  }
  return light;
}

// The least-squares terms of the real rays `hits` of one scene point through `pupil` (see the file
// comment); false when too few rays pass or the system is singular.
bool fit_field(const SeidelRayGeometry& geometry, const std::vector<PupilPoint>& pupil, const std::vector<SensorHit>& hits,
               FieldTerms& out) {
  using Row = Eigen::Matrix<double, 6, 1>;  // five basis columns and the residual
  std::vector<Row> rows;
  Row mean_x = Row::Zero(), mean_y = Row::Zero();
  double reach = 0.0;  // the largest pupil radius that passes
  for (std::size_t p = 0; p < pupil.size(); ++p) {
    if (!hits[p].ok) continue;
    reach = std::max(reach, std::hypot(pupil[p].x, pupil[p].y));
    double x0, y0;
    geometry.sensor_point(pupil[p], FieldTerms{}, x0, y0);
    Row ax, ay;
    for (int m = 0; m < 5; ++m) {
      FieldTerms unit;
      unit[m] = 1.0;
      double x, y;
      geometry.sensor_point(pupil[p], unit, x, y);
      ax[m] = x - x0;
      ay[m] = y - y0;
    }
    ax[5] = hits[p].x_mm - x0;
    ay[5] = hits[p].y_mm - y0;
    rows.push_back(ax);
    rows.push_back(ay);
    mean_x += ax;
    mean_y += ay;
  }
  const auto n = static_cast<double>(rows.size() / 2);
  if (rows.size() / 2 < static_cast<std::size_t>(kMinFitRays)) return false;
  mean_x /= n;
  mean_y /= n;
  // The shape: every term but distortion from the centred rows.
  constexpr int kShape[4] = {0, 1, 2, 4};
  Eigen::Matrix4d normal = Eigen::Matrix4d::Zero();
  Eigen::Vector4d rhs = Eigen::Vector4d::Zero();
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const Row d = rows[r] - (r % 2 == 0 ? mean_x : mean_y);
    Eigen::Vector4d a;
    for (int m = 0; m < 4; ++m) a[m] = d[kShape[m]];
    normal += a * a.transpose();
    rhs += a * d[5];
  }
  normal.diagonal().array() += kRidge * normal.trace() / 4.0;
  if (reach < kSphericalReach) {
    // Over a small patch of the pupil rho^3 is told from rho only by noise, and the model's rays
    // beyond the patch would carry the difference far: no spherical term.
    normal.row(0).setZero();
    normal.col(0).setZero();
    normal(0, 0) = 1.0;
    rhs[0] = 0.0;
  }
  const Eigen::LDLT<Eigen::Matrix4d> solver(normal);
  if (solver.info() != Eigen::Success || !solver.isPositive()) return false;
  const Eigen::Vector4d shape = solver.solve(rhs);
  if (!shape.allFinite()) return false;
  // The centroid: what the shape terms leave of its offset, along the distortion's direction (y).
  double left = mean_y[5];
  for (int m = 0; m < 4; ++m) left -= shape[m] * mean_y[kShape[m]];
  FieldTerms t;
  for (int m = 0; m < 4; ++m) t[kShape[m]] = shape[m];
  t.distortion = geometry.y0 > 0.0 && std::abs(mean_y[3]) > 0.0 ? left / mean_y[3] : 0.0;
  out = t;
  return std::isfinite(t.distortion);
}

// The largest distance (mm) of `points` from their centroid; 0 for none.
double reach_about_centroid(const std::vector<std::pair<double, double>>& points) {
  if (points.empty()) return 0.0;
  double sx = 0.0, sy = 0.0;
  for (const auto& [x, y] : points) sx += x, sy += y;
  sx /= static_cast<double>(points.size()), sy /= static_cast<double>(points.size());
  double reach = 0.0;
  for (const auto& [x, y] : points) reach = std::max(reach, std::hypot(x - sx, y - sy));
  return reach;
}

// The reach of the spot the points `pupil[p]` in the unit pupil with `use[p].ok` map to by `terms`.
double spot_reach_mm(const SeidelRayGeometry& geometry, const std::vector<PupilPoint>& pupil, const std::vector<SensorHit>& use,
                     const FieldTerms& terms) {
  std::vector<std::pair<double, double>> points;
  for (std::size_t p = 0; p < pupil.size(); ++p) {
    if (!use[p].ok || !in_pupil(pupil[p])) continue;
    double x, y;
    geometry.sensor_point(pupil[p], terms, x, y);
    points.emplace_back(x, y);
  }
  return reach_about_centroid(points);
}

// Whether the fitted terms, carried over the pupil the model itself passes (its first-order
// clipping, which is not the real lens's where a clear aperture cuts a cat's eye), throw rays far
// beyond both the real spot and the sums' one: a third-order fit to a clipped beam's rays can grow
// large where no ray constrained it (a 35 mm lens's frame corner: B = 0.78 mm, 14 px at the rim).
// The field then keeps its sums.
bool extrapolates(const SeidelRayGeometry& geometry, const std::vector<PupilPoint>& pupil, const std::vector<SensorHit>& hits,
                  const std::vector<SensorHit>& own, const FieldTerms& fit, const FieldTerms& sums, double pixel_mm) {
  std::vector<std::pair<double, double>> real;
  for (const SensorHit& h : hits) {
    if (h.ok) real.emplace_back(h.x_mm, h.y_mm);
  }
  const double fitted = spot_reach_mm(geometry, pupil, own, fit);
  const double summed = spot_reach_mm(geometry, pupil, own, sums);
  return fitted > kExtrapolationGrowth * std::max(reach_about_centroid(real), summed) + pixel_mm;
}

}  // namespace

FittedAberrations::FittedAberrations(const Camera& camera, const ExactModel& exact, const AberrationTable& table,
                                     const ModelMap& model) {
  const std::vector<double>& lambdas = table.wavelengths_nm();
  const std::vector<double>& distances = table.object_distances_mm();
  for (double d : distances) inverse_distances_per_mm_.push_back(inverse_per_mm(d));
  const std::size_t nodes = std::min<std::size_t>(kFitWavelengths, lambdas.size());
  std::vector<std::size_t> node_index(nodes, 0);
  for (std::size_t n = 0; n < nodes; ++n) {
    if (nodes > 1) node_index[n] = (n * (lambdas.size() - 1) + (nodes - 1) / 2) / (nodes - 1);
    wavelengths_nm_.push_back(lambdas[node_index[n]]);
  }
  for (int k = 0; k < kFitFields; ++k) fields_.push_back(static_cast<double>(k) / (kFitFields - 1));
  terms_.assign(distances.size() * nodes * fields_.size(), FieldTerms{});
  light_.assign(terms_.size(), 1.0);
  std::vector<PupilPoint> full;
  pupil_lattice(-1.0, 1.0, -1.0, 1.0, full);
  const double full_cell_area = 4.0 / (kFitPupilGrid * kFitPupilGrid);
  const int tasks = static_cast<int>(distances.size() * nodes);
#pragma omp parallel for schedule(dynamic, 1)
  for (int task = 0; task < tasks; ++task) {
    const std::size_t j = static_cast<std::size_t>(task) / nodes, n = static_cast<std::size_t>(task) % nodes;
    const AberrationSample& s = table.sample(node_index[n], j);
    const AberrationCoefficients& c = s.coefficients;
    const FirstOrderSample fo = camera.first_order(s.wavelength_nm);
    // The depth, from the perspective centre, of the table's object distance (from surface 1).
    const double w = inverse_per_mm(s.object_distance_mm + camera.z_perspective_mm());
    const double pixel_mm = 1.0 / std::abs(camera.px_per_sensor_mm());
    std::vector<PupilPoint> pupil;
    std::vector<SensorHit> hits, own;
    for (std::size_t k = 0; k < fields_.size(); ++k) {
      const ScenePoint point{0.0, fields_[k] * c.max_field_tangent, w};
      const SeidelRayGeometry geometry(camera, fo, point, c.max_field_tangent);
      // Both models on the full grid; where little passes (a lens opened beyond its clear
      // apertures), again on a grid over the box around what passes in either.
      pupil = full;
      hits.resize(pupil.size());
      own.resize(pupil.size());
      exact.map(point, s.wavelength_nm, pupil, hits);
      model(point, s.wavelength_nm, pupil, own);
      std::size_t passing = 0, own_passing = 0;
      double x0 = kInfinity, x1 = -kInfinity, y0 = kInfinity, y1 = -kInfinity;
      for (std::size_t p = 0; p < pupil.size(); ++p) {
        if (!in_pupil(pupil[p])) continue;
        passing += hits[p].ok;
        own_passing += own[p].ok;
        if (!(hits[p].ok || own[p].ok)) continue;
        x0 = std::min(x0, pupil[p].x), x1 = std::max(x1, pupil[p].x);
        y0 = std::min(y0, pupil[p].y), y1 = std::max(y1, pupil[p].y);
      }
      double cell_area = full_cell_area;
      if ((passing < kDenseBelow || own_passing < kDenseBelow) && x0 <= x1) {
        const double cell = 2.0 / kFitPupilGrid;
        x0 = std::max(-1.0, x0 - cell), x1 = std::min(1.0, x1 + cell), y0 = std::max(-1.0, y0 - cell), y1 = std::min(1.0, y1 + cell);
        pupil_lattice(x0, x1, y0, y1, pupil);
        cell_area = (x1 - x0) * (y1 - y0) / (kFitPupilGrid * kFitPupilGrid);
        hits.resize(pupil.size());
        own.resize(pupil.size());
        exact.map(point, s.wavelength_nm, pupil, hits);
        model(point, s.wavelength_nm, pupil, own);
      }
      FieldTerms fit;
      const bool ok = fit_field(geometry, pupil, hits, fit);
      // The light: the same lattice through both.
      const double real_light = lattice_light(pupil, hits, cell_area), own_light = lattice_light(pupil, own, cell_area);
      if (own_light > 0.0) light_[(j * nodes + n) * fields_.size() + k] = real_light / own_light;
      const FieldTerms sums = FieldTerms::at(c, geometry.y0);
      FieldTerms& t = terms_[(j * nodes + n) * fields_.size() + k];
      if (!ok || extrapolates(geometry, pupil, hits, own, fit, sums, pixel_mm)) {
        t = sums;
        continue;
      }
      t = fit;
    }
  }
  // Both models' weights are normalised so that the on-axis point of the focus plane passes a mean
  // of 1 over the pupil (ray_model.h); on this lattice their ratio there departs from 1 only by how
  // the interpolated clearances meet the two clipping edges: divide that out per wavelength.
  for (std::size_t n = 0; n < nodes; ++n) {
    std::vector<SensorHit> hits(full.size()), own(full.size());
    const ScenePoint axis{0.0, 0.0, inverse_per_mm(camera.focus_distance_mm())};
    exact.map(axis, wavelengths_nm_[n], full, hits);
    model(axis, wavelengths_nm_[n], full, own);
    const double real_light = lattice_light(full, hits, full_cell_area), own_light = lattice_light(full, own, full_cell_area);
    if (!(real_light > 0.0 && own_light > 0.0)) continue;
    for (std::size_t j = 0; j < distances.size(); ++j) {
      for (std::size_t k = 0; k < fields_.size(); ++k) light_[(j * nodes + n) * fields_.size() + k] *= own_light / real_light;
    }
  }
}

double FittedAberrations::fitted_terms(double wavelength_nm, double object_distance_mm, double y0, FieldTerms& terms) const {
  const std::pair<std::size_t, double> jd = grid_interval(inverse_distances_per_mm_, inverse_per_mm(object_distance_mm));
  const std::pair<std::size_t, double> nw = grid_interval(wavelengths_nm_, wavelength_nm);
  const std::pair<std::size_t, double> kf = grid_interval(fields_, y0);
  const std::size_t j = jd.first, n = nw.first, k = kf.first;
  const std::size_t j1 = std::min(j + 1, inverse_distances_per_mm_.size() - 1);
  const std::size_t n1 = std::min(n + 1, wavelengths_nm_.size() - 1);
  const std::size_t k1 = std::min(k + 1, fields_.size() - 1);
  // Trilinear interpolation of value(j, n, k).
  auto interpolate = [&](const auto& value) {
    auto along_field = [&](std::size_t jj, std::size_t nn) { return value(jj, nn, k) + (value(jj, nn, k1) - value(jj, nn, k)) * kf.second; };
    const double near = along_field(j, n) + (along_field(j, n1) - along_field(j, n)) * nw.second;
    const double far = along_field(j1, n) + (along_field(j1, n1) - along_field(j1, n)) * nw.second;
    return near + (far - near) * jd.second;
  };
  for (int m = 0; m < 5; ++m) {
    terms[m] = interpolate([&](std::size_t jj, std::size_t nn, std::size_t kk) { return at(jj, nn, kk)[m]; });
  }
  return interpolate([&](std::size_t jj, std::size_t nn, std::size_t kk) {
    return light_[(jj * wavelengths_nm_.size() + nn) * fields_.size() + kk];
  });
}

}  // namespace lensmith::camera_detail
