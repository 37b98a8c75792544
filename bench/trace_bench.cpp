// Exact ray tracing speed: single-ray forward traces through every shipped lens (ns per ray and per surface)
// and the OpenMP batch path (rays per second on 1 thread and on all of them). The reference point is the
// 160-200 ns per surface per ray (float) of a published polynomial-optics renderer's exact tracer. Figures:
// docs/performance.md.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <cmath>
#include <string>
#include <vector>

#include "lensmith/paraxial/paraxial_system.h"
#include "lensmith/glass/glass_catalog.h"
#include "lensmith/prescription/lens_library.h"
#include "lensmith/trace/ray_aiming.h"
#include "lensmith/trace/sequential_tracer.h"

namespace {

using namespace lensmith;

// Rays over 70 % of the field and the whole pupil (a golden-angle spiral), at the primary wavelength, kept
// only when they reach the image: every timed ray crosses every surface, so time / surfaces is the cost of
// one surface crossing.
std::vector<Ray> sample_rays(const SequentialTracer& tracer, std::size_t count) {
  const RayAimer aimer(tracer);
  const Prescription& lens = tracer.lens();
  std::vector<Ray> rays;
  rays.reserve(count);
  constexpr double kGoldenAngle = 2.39996322972865332;
  const std::size_t candidates = 4 * count;
  for (std::size_t i = 0; rays.size() < count && i < candidates; ++i) {
    const double relative_field = 0.7 * static_cast<double>(i % 8) / 7.0;
    const FieldPoint field = lens.field ? aimer.field_at(relative_field) : FieldPoint::angle_deg(10.0 * relative_field);
    const double radius = std::sqrt((static_cast<double>(i) + 0.5) / static_cast<double>(candidates));
    const double angle = kGoldenAngle * static_cast<double>(i);
    const Ray ray =
        aimer.make_ray(field, {radius * std::cos(angle), radius * std::sin(angle)}, lens.primary_wavelength_nm()).ray;
    if (tracer.trace_forward(ray).ok()) rays.push_back(ray);
  }
  // Repeat the survivors if fewer than `count` got through (a heavily vignetted lens).
  for (std::size_t i = 0; rays.size() < count; ++i) rays.push_back(rays[i]);
  return rays;
}

void BM_TraceForward(benchmark::State& state, const std::string& id) {
  const Prescription lens = LensLibrary::load(id).prescription;
  const SequentialTracer tracer(lens);
  const std::vector<Ray> rays = sample_rays(tracer, 4096);
  std::size_t next = 0;
  for (auto _ : state) {
    const TraceResult r = tracer.trace_forward(rays[next]);
    benchmark::DoNotOptimize(r.ray.position_mm.data());
    next = (next + 1) & 4095;
  }
  const auto surfaces = static_cast<double>(lens.surfaces.size());
  const auto iterations = static_cast<double>(state.iterations());
  state.counters["surfaces"] = surfaces;
  // Seconds per surface crossing (shown with an SI prefix: "28n" = 28 ns).
  state.counters["time_per_surface"] =
      benchmark::Counter(iterations * surfaces, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// trace_batch on 65536 rays with `state.range(0)` OpenMP threads (0 = all). Refilling the batch from the
// inputs is not timed.
void BM_TraceBatch(benchmark::State& state, const std::string& id) {
  const Prescription lens = LensLibrary::load(id).prescription;
  const SequentialTracer tracer(lens);
  constexpr std::size_t kRays = 65536;
  const std::vector<Ray> rays = sample_rays(tracer, kRays);
  RayBatch batch;
  batch.resize(kRays);
  const int threads = state.range(0) == 0 ? omp_get_num_procs() : static_cast<int>(state.range(0));
  omp_set_num_threads(threads);
  for (auto _ : state) {
    state.PauseTiming();
    for (std::size_t i = 0; i < kRays; ++i) batch.set(i, rays[i]);
    state.ResumeTiming();
    tracer.trace_batch(batch, TraceDirection::Forward);
    benchmark::DoNotOptimize(batch.x_mm.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(kRays));
  state.counters["threads"] = threads;
  state.counters["surfaces"] = static_cast<double>(lens.surfaces.size());
  state.counters["time_per_surface"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * static_cast<double>(kRays) * static_cast<double>(lens.surfaces.size()),
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// A million rays of beams at five field angles (0 to 20 deg along y) through 95 % of the paraxial
// entrance pupil (a golden-angle spiral), from the plane z = -10 mm: the work bench/python_trace_bench.py
// gives the Python module, so that the two figures compare (docs/performance.md, "Python").
// Only trace_batch is timed, on every core.
void BM_TraceBatchBeams(benchmark::State& state, const std::string& id) {
  const Prescription lens = LensLibrary::load(id).prescription;
  const SequentialTracer tracer(lens);
  const ParaxialSystem paraxial(lens);
  constexpr std::size_t kRays = 1000000;
  const double z_pupil = paraxial.entrance_pupil().z_mm, radius = 0.95 * paraxial.entrance_pupil().diameter_mm / 2.0;
  constexpr double kGoldenAngle = 2.39996322972865332, kPi = 3.14159265358979323846;
  RayBatch input;
  input.resize(kRays);
  for (std::size_t i = 0; i < kRays; ++i) {
    const double angle = 20.0 * static_cast<double>(i % 5) / 4.0 * kPi / 180.0;
    const double r = radius * std::sqrt((static_cast<double>(i) + 0.5) / static_cast<double>(kRays));
    const double px = r * std::cos(kGoldenAngle * static_cast<double>(i)), py = r * std::sin(kGoldenAngle * static_cast<double>(i));
    const double m = std::sin(angle), n = std::cos(angle), t = (z_pupil + 10.0) / n;
    input.set(i, Ray{{px, py - m * t, -10.0}, {0.0, m, n}, lens.primary_wavelength_nm()});
  }
  omp_set_num_threads(omp_get_num_procs());
  RayBatch batch = input;
  for (auto _ : state) {
    state.PauseTiming();
    batch = input;
    state.ResumeTiming();
    tracer.trace_batch(batch, TraceDirection::Forward);
    benchmark::DoNotOptimize(batch.x_mm.data());
  }
  std::size_t passed = 0;
  for (RayStatus s : batch.status) passed += s == RayStatus::Ok;
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(kRays));
  state.counters["passed"] = static_cast<double>(passed);
  state.counters["surfaces"] = static_cast<double>(lens.surfaces.size());
}

// RayAimer::make_ray for Smith's triplet over the field and pupil, paraxial or real-stop aiming.
void BM_AimRay(benchmark::State& state, RayAiming aiming) {
  const Prescription lens = LensLibrary::load("smith-cooke-triplet").prescription;
  const SequentialTracer tracer(lens);
  AimOptions options;
  options.aiming = aiming;
  const RayAimer aimer(tracer, options);
  std::size_t i = 0;
  for (auto _ : state) {
    const double relative_field = static_cast<double>(i % 8) / 7.0;
    const double py = -0.9 + 1.8 * static_cast<double>(i % 11) / 10.0;
    const AimedRay ray = aimer.make_ray(aimer.field_at(relative_field), {0.3, py}, lens.primary_wavelength_nm());
    benchmark::DoNotOptimize(ray.ray.position_mm.data());
    ++i;
  }
}

// The cost of one surface crossing per surface type (issue 18): a stack of 12 weak surfaces alternating
// glass (n = 1.5) and air, 4 mm apart, as spheres on the coaxial path, the same spheres on the general path
// (an identity coordinate break in front moves the lens there), toroids, biconics, cylinders, spheres each between a
// tilting break and its inverse, and a stack of 12 flat-and-curved mirrors (a beam folded back and forth).
enum class StackKind { CoaxialSpheres, GeneralSpheres, Toroids, Biconics, Cylinders, TiltedSpheres, Mirrors };

Prescription surface_stack(StackKind kind) {
  Prescription p;
  p.name = "stack";
  Surface stop;
  stop.thickness_mm = 4.0;
  stop.semi_diameter_mm = 5.0;
  stop.is_stop = true;
  p.surfaces.push_back(stop);
  if (kind == StackKind::GeneralSpheres) {
    Surface b;
    b.kind = SurfaceKind::CoordinateBreak;
    p.surfaces.push_back(b);
  }
  for (int k = 0; k < 12; ++k) {
    Surface s;
    s.curvature_per_mm = (k % 2 == 0 ? 1.0 : -1.0) / 200.0;
    s.thickness_mm = 4.0;
    if (kind == StackKind::Mirrors) {
      s.mirror = true;
      s.thickness_mm = k % 2 == 0 ? -4.0 : 4.0;
      s.curvature_per_mm = k % 2 == 0 ? 0.0 : 1.0 / 400.0;
    } else if (k % 2 == 0) {
      s.material = MaterialSpec::model(1.5, std::nullopt);
    }
    if (kind == StackKind::Toroids || kind == StackKind::Biconics) {
      s.kind = kind == StackKind::Toroids ? SurfaceKind::Toroidal : SurfaceKind::Biconic;
      s.curvature_x_per_mm = 1.3 * s.curvature_per_mm;
    }
    if (kind == StackKind::Cylinders) {  // curved in x (lentil's "cyl-y"), flat in y: the closed-form cylinder
      s.kind = SurfaceKind::Biconic;
      s.curvature_x_per_mm = s.curvature_per_mm;
      s.curvature_per_mm = 0.0;
    }
    if (kind == StackKind::TiltedSpheres) {
      Surface tilt;
      tilt.kind = SurfaceKind::CoordinateBreak;
      tilt.coordinate_break = CoordinateBreak{0.01, 0.0, 0.2, 0.0, 0.0, false};
      Surface untilt = tilt;
      untilt.coordinate_break = tilt.coordinate_break.inverse();
      untilt.thickness_mm = s.thickness_mm;
      s.thickness_mm = 0.0;
      p.surfaces.push_back(tilt);
      p.surfaces.push_back(s);
      p.surfaces.push_back(untilt);
      continue;
    }
    p.surfaces.push_back(s);
  }
  p.surfaces.back().thickness_mm = 20.0;
  p.aperture = ApertureSpec{ApertureSpec::Kind::EntrancePupilDiameter, 8.0};
  p.resolve_materials(GlassCatalog::builtin());
  return p;
}

void BM_TraceSurfaceKind(benchmark::State& state, StackKind kind) {
  const Prescription lens = surface_stack(kind);
  const SequentialTracer tracer(lens);
  std::vector<Ray> rays;
  for (int i = 0; rays.size() < 4096 && i < 100000; ++i) {
    Ray r;
    const double a = 2.39996322972865332 * i, rho = 3.5 * std::sqrt((i + 0.5) / 4096.0);
    r.position_mm = Eigen::Vector3d(rho * std::cos(a), rho * std::sin(a), -1.0);
    r.direction = Eigen::Vector3d(0.0, 0.02, 1.0).normalized();
    r.wavelength_nm = kWavelengthD_nm;
    if (tracer.trace_forward(r).ok()) rays.push_back(r);
  }
  if (rays.empty()) {
    state.SkipWithError("no ray gets through the stack");
    return;
  }
  std::size_t next = 0;
  for (auto _ : state) {
    const TraceResult r = tracer.trace_forward(rays[next]);
    benchmark::DoNotOptimize(r.ray.position_mm.data());
    next = (next + 1) % rays.size();
  }
  state.counters["time_per_surface"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * 12.0, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// Median of 5 repetitions, as docs/performance.md reports.
const int kRegistered = [] {
  for (const ShippedLens& lens : LensLibrary::list()) {
    benchmark::RegisterBenchmark(("BM_TraceForward/" + lens.id).c_str(), BM_TraceForward, lens.id)
        ->Unit(benchmark::kNanosecond)
        ->Repetitions(5)
        ->ReportAggregatesOnly(true);
  }
  for (const char* id : {"smith-cooke-triplet", "angenieux-double-gauss-1953", "aspherical-fisheye"}) {
    benchmark::RegisterBenchmark((std::string("BM_TraceBatch/") + id).c_str(), BM_TraceBatch, std::string(id))
        ->Arg(1)
        ->Arg(0)
        ->ArgName("threads")
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->Repetitions(5)
        ->ReportAggregatesOnly(true);
  }
  benchmark::RegisterBenchmark("BM_TraceBatchBeams/angenieux-double-gauss-1953", BM_TraceBatchBeams,
                               std::string("angenieux-double-gauss-1953"))
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime()
      ->Repetitions(5)
      ->ReportAggregatesOnly(true);
  for (const auto& [name, kind] : {std::pair{"coaxial_spheres", StackKind::CoaxialSpheres}, std::pair{"general_spheres", StackKind::GeneralSpheres},
                                   std::pair{"toroids", StackKind::Toroids}, std::pair{"biconics", StackKind::Biconics},
                                   std::pair{"cylinders", StackKind::Cylinders},
                                   std::pair{"tilted_spheres", StackKind::TiltedSpheres}, std::pair{"mirrors", StackKind::Mirrors}}) {
    benchmark::RegisterBenchmark((std::string("BM_TraceSurfaceKind/") + name).c_str(), BM_TraceSurfaceKind, kind)
        ->Unit(benchmark::kNanosecond)
        ->Repetitions(5)
        ->ReportAggregatesOnly(true);
  }
  benchmark::RegisterBenchmark("BM_AimRay/smith-cooke-triplet/paraxial_pupil", BM_AimRay,
                               RayAiming::ParaxialEntrancePupil)
      ->Unit(benchmark::kNanosecond)
      ->Repetitions(5)
      ->ReportAggregatesOnly(true);
  benchmark::RegisterBenchmark("BM_AimRay/smith-cooke-triplet/real_stop", BM_AimRay, RayAiming::RealStop)
      ->Unit(benchmark::kMicrosecond)
      ->Repetitions(5)
      ->ReportAggregatesOnly(true);
  return 0;
}();

}  // namespace

BENCHMARK_MAIN();
