// Wavelength groups of the spectral scatter. Each pixel's linear Rec.709 colour is a smooth spectrum
// (SpectralBasis) carried at the nodes of a SpectralQuadrature; a pixel whose bokeh the lens does
// not separate by colour sends all its light at one wavelength, others in G contiguous runs of
// nodes. Run g carries RGB out = M_g * RGB in at its middle node's wavelength, and the M_g of a
// split sum to the identity (the quadrature's calibration), so grey stays grey whatever G is.
#pragma once

#include <array>
#include <vector>

#include "lensmith/camera/camera.h"

namespace lensmith::render_detail {

struct SpectralGroup {
  double wavelength_nm = 0.0;
  std::array<std::array<float, 3>, 3> m{};  // RGB out = m * RGB in
  float alpha = 1.0f;                       // its share of the coverage (nodes in the run / all nodes)
};

class SpectralGroups {
 public:
  // spectral = false: one group at the camera's reference wavelength with M = identity.
  SpectralGroups(const Camera& camera, bool spectral, int samples);
  int max_count() const { return static_cast<int>(groups_.size()); }
  // The split into `count` runs (1..max_count()).
  const std::vector<SpectralGroup>& split(int count) const { return groups_[static_cast<std::size_t>(count - 1)]; }
  // The extreme nodes, where the chromatic spread of a footprint is probed.
  double lowest_nm() const { return lowest_nm_; }
  double highest_nm() const { return highest_nm_; }

 private:
  std::vector<std::vector<SpectralGroup>> groups_;  // groups_[G - 1]
  double lowest_nm_ = 0.0;
  double highest_nm_ = 0.0;
};

}  // namespace lensmith::render_detail
