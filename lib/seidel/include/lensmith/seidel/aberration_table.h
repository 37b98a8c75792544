// Born & Wolf coefficients B..F and first-order parameters tabulated over wavelength (64 samples,
// 380-780 nm by default) and object distance, for the bokeh renderer: cheap to interpolate, linear
// in wavelength and in inverse object distance (dioptres), which is how they vary smoothly.
#pragma once

#include <cstddef>
#include <ostream>
#include <string>
#include <vector>

#include "lensmith/paraxial/paraxial_spectral_table.h"
#include "lensmith/seidel/aberration_vector.h"

namespace lensmith {

struct AberrationTableOptions {
  double min_wavelength_nm = 380.0;
  double max_wavelength_nm = 780.0;
  int wavelength_samples = 64;                       // >= 2
  std::vector<double> object_distances_mm{kInfinity};  // each > 0 or +inf; sorted far to near on build
  SeidelOptions seidel;                              // aperture / field overrides (wavelength, distance ignored)
  void validate() const;                             // throws OptionsError naming the field
};

struct AberrationSample {
  double wavelength_nm = 0.0;
  double object_distance_mm = kInfinity;
  AberrationCoefficients coefficients;
  ParaxialSample paraxial;  // EFL, principal planes, pupils, image distance at this wavelength and distance
};

class AberrationTable {
 public:
  AberrationTable(const Prescription& lens, const AberrationTableOptions& options = {});

  const std::vector<double>& wavelengths_nm() const { return wavelengths_nm_; }
  const std::vector<double>& object_distances_mm() const { return distances_mm_; }
  // Sample at wavelength index i and distance index j.
  const AberrationSample& sample(std::size_t i, std::size_t j) const { return samples_[j * wavelengths_nm_.size() + i]; }
  // The same, to replace its coefficients (the camera layer fits them to real rays).
  AberrationSample& sample(std::size_t i, std::size_t j) { return samples_[j * wavelengths_nm_.size() + i]; }
  // Bilinear interpolation in wavelength and in 1 / object distance; clamps outside the table.
  AberrationSample at(double wavelength_nm, double object_distance_mm) const;
  // The coefficients of at() alone, without its paraxial data (a renderer asks per footprint).
  AberrationCoefficients coefficients_at(double wavelength_nm, double object_distance_mm) const;
  std::string to_string() const;

 private:
  // The table cell around (wavelength, 1 / distance): its corner indices and fractions.
  struct Cell {
    std::size_t i, i1;
    double ti;
    std::size_t j, j1;
    double tj;
  };
  Cell cell(double wavelength_nm, double object_distance_mm) const;

  std::vector<double> wavelengths_nm_;
  std::vector<double> distances_mm_;
  std::vector<double> inverse_distances_per_mm_;  // 1 / distance, ascending (0 = infinity)
  std::vector<AberrationSample> samples_;
};

}  // namespace lensmith
