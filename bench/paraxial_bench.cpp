// Paraxial speed: ParaxialSpectralTable (64 wavelengths, 380-780 nm) and ParaxialSystem construction,
// on Smith's Cooke triplet (7 surfaces, model glasses) and Angenieux's double Gauss (US 2,701,982,
// 15 surfaces, Schott catalogue glasses). Figures and the 1 ms budget: docs/performance.md.
#include <benchmark/benchmark.h>

#include <cmath>
#include <optional>

#include "lensmith/glass/glass_catalog.h"
#include "lensmith/paraxial/paraxial_spectral_table.h"
#include "lensmith/paraxial/paraxial_system.h"

namespace {

using namespace lensmith;

Surface make_surface(double radius_mm, double thickness_mm, const MaterialSpec& material, double semi_diameter_mm) {
  Surface s;
  s.curvature_per_mm = std::isinf(radius_mm) ? 0.0 : 1.0 / radius_mm;
  s.thickness_mm = thickness_mm;
  s.material = material;
  s.medium = material.resolve(GlassCatalog::builtin());
  s.semi_diameter_mm = semi_diameter_mm;
  return s;
}

// W. J. Smith, Modern Optical Engineering, 4th ed., ch. 6; model glasses from n_d and delta n.
Prescription smith_cooke_triplet() {
  const MaterialSpec sk4 = MaterialSpec::model(1.61272, 0.61272 / 0.010450);
  const MaterialSpec sf2 = MaterialSpec::model(1.64769, 0.64769 / 0.019151);
  const MaterialSpec air = MaterialSpec::air();
  Prescription p;
  p.surfaces = {
      make_surface(37.40, 5.90, sk4, 14.7),     make_surface(-341.48, 12.93, air, 14.7),
      make_surface(-42.65, 2.50, sf2, 10.8),    make_surface(36.40, 2.00, air, 10.8),
      make_surface(kInfinity, 9.85, air, 10.3), make_surface(204.52, 5.90, sk4, 11.6),
      make_surface(-37.05, 77.405, air, 11.6),
  };
  p.surfaces[4].is_stop = true;
  p.aperture = ApertureSpec{ApertureSpec::Kind::EntrancePupilDiameter, 29.2};
  p.field = FieldSpec{FieldSpec::Kind::AngleDeg, {deg_from_rad(std::atan(0.21))}};
  return p;
}

// Angenieux double Gauss, US 2,701,982 (1953), as in the lentil lens database (entry 0001),
// with the patent's glass types taken from the Schott catalogue.
Prescription angenieux_double_gauss() {
  const MaterialSpec sf5 = MaterialSpec::catalog("N-SF5", "SCHOTT");
  const MaterialSpec baf10 = MaterialSpec::catalog("N-BAF10", "SCHOTT");
  const MaterialSpec lak9 = MaterialSpec::catalog("N-LAK9", "SCHOTT");
  const MaterialSpec sf15 = MaterialSpec::catalog("SF15", "SCHOTT");
  const MaterialSpec sk16 = MaterialSpec::catalog("N-SK16", "SCHOTT");
  const MaterialSpec air = MaterialSpec::air();
  Prescription p;
  p.surfaces = {
      make_surface(164.13, 10.99, sf5, 54),        make_surface(559.2, 0.23, air, 54),
      make_surface(100.12, 11.45, baf10, 51),      make_surface(213.54, 0.23, air, 51),
      make_surface(58.04, 22.95, lak9, 41),        make_surface(2551.1, 2.58, sf5, 41),
      make_surface(32.39, 15.66, air, 27),         make_surface(kInfinity, 15.0, air, 25.5),
      make_surface(-40.42, 2.74, sf15, 25),        make_surface(192.98, 27.92, sk16, 36),
      make_surface(-55.53, 0.23, air, 36),         make_surface(192.98, 7.98, lak9, 35),
      make_surface(-225.3, 0.23, air, 35),         make_surface(175.09, 8.48, lak9, 35),
      make_surface(-203.55, 55.724, air, 35),
  };
  p.surfaces[7].is_stop = true;
  p.aperture = ApertureSpec{ApertureSpec::Kind::FloatByStop, 0.0};
  p.field = FieldSpec{FieldSpec::Kind::AngleDeg, {12.0}};
  return p;
}

void BM_SpectralTable(benchmark::State& state, Prescription (*make)()) {
  const Prescription lens = make();
  for (auto _ : state) {
    ParaxialSpectralTable table(lens);
    benchmark::DoNotOptimize(table.samples().data());
  }
  state.counters["surfaces"] = static_cast<double>(lens.surfaces.size());
  state.counters["wavelengths"] = 64;
}

void BM_SystemConstruction(benchmark::State& state, Prescription (*make)()) {
  const Prescription lens = make();
  for (auto _ : state) {
    ParaxialSystem system(lens);
    benchmark::DoNotOptimize(system.efl_mm());
  }
  state.counters["surfaces"] = static_cast<double>(lens.surfaces.size());
}

// A finite object (2 m) exercises the image-conjugate path of the kernel.
void BM_SpectralTableFiniteObject(benchmark::State& state) {
  const Prescription lens = angenieux_double_gauss();
  SpectralTableOptions options;
  options.object_distance_mm = 2000.0;
  for (auto _ : state) {
    ParaxialSpectralTable table(lens, options);
    benchmark::DoNotOptimize(table.samples().data());
  }
}

}  // namespace

BENCHMARK_CAPTURE(BM_SpectralTable, smith_triplet_7_surfaces, smith_cooke_triplet)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_SpectralTable, double_gauss_15_surfaces, angenieux_double_gauss)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SpectralTableFiniteObject)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_SystemConstruction, smith_triplet_7_surfaces, smith_cooke_triplet)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_SystemConstruction, double_gauss_15_surfaces, angenieux_double_gauss)
    ->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
