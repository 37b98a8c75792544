// The fit's speed against the exact tracer (LensFit::measure_speed): the same passing rays from the
// sensor to the outer pupil through the tracer's batch path and the fit's batch evaluation, each on
// one thread, median of 5 runs. Asked for by `lensmith fit`; bench/polyfit_bench.cpp measures more.
#include <algorithm>
#include <chrono>
#include <cmath>

#include "lens_fit_stages.h"

namespace lensmith {

namespace {

constexpr int kRuns = 5;

template <class F>
double median_seconds(int runs, F f) {
  std::vector<double> t;
  for (int r = 0; r < runs; ++r) {
    const auto start = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

}  // namespace

void LensFit::measure_speed(const Prescription& lens) {
  check_matches(lens);
  using polyfit_detail::Candidate;
  const std::optional<CoaxialCore> core = coaxial_core(lens);  // what the maps describe
  if (!core) throw OptionsError("LensFit::measure_speed: '" + lens.name + "' " + why_not_fittable(lens).value_or("cannot be fitted"));
  const polyfit_detail::RaySampler sampler(core->lens, options_);
  const std::size_t wanted = static_cast<std::size_t>(options_.test_rays);
  const std::vector<Candidate> rays = sampler.collect(
      polyfit_detail::stream_of(options_.seed, polyfit_detail::Stream::Speed), wanted,
      [](const Candidate& c) { return c.passes; }, [&](const std::vector<Candidate>& kept) { return kept.size() >= wanted; },
      {}, 0.0, 1.0);
  const std::size_t count = rays.size();
  std::vector<double> x(count), y(count), dx(count), dy(count), nm(count);
  for (std::size_t i = 0; i < count; ++i) {
    x[i] = rays[i].sensor.x_mm;
    y[i] = rays[i].sensor.y_mm;
    dx[i] = rays[i].sensor.dx;
    dy[i] = rays[i].sensor.dy;
    nm[i] = rays[i].wavelength_nm;
  }
  std::vector<double> ox(count), oy(count), odx(count), ody(count);
  RayBatch batch;
  const double exact_s = median_seconds(kRuns, [&] {
    batch.resize(count);
    for (std::size_t i = 0; i < count; ++i) {
      batch.x_mm[i] = x[i];
      batch.y_mm[i] = y[i];
      batch.z_mm[i] = sensor_z_mm_;
      const double dz = std::sqrt(std::max(0.0, 1.0 - dx[i] * dx[i] - dy[i] * dy[i]));
      batch.l[i] = -dx[i];
      batch.m[i] = -dy[i];
      batch.n[i] = -dz;
      batch.wavelength_nm[i] = nm[i];
    }
    sampler.tracer().trace_batch(batch, TraceDirection::Backward, /*threads=*/1);
  });
  const double poly_s = median_seconds(kRuns, [&] { outer_rays(x, y, dx, dy, nm, ox, oy, odx, ody); });
  timing_.exact_ns_per_ray = 1e9 * exact_s / static_cast<double>(count);
  timing_.poly_ns_per_ray = 1e9 * poly_s / static_cast<double>(count);
}

}  // namespace lensmith
