// Uncoated Fresnel transmittance (Born & Wolf, Principles of Optics, sec. 1.5.3, eqs. 21a-b and 40).
#include "lensmith/trace/fresnel.h"

#include <cmath>

namespace lensmith {

double fresnel_transmittance(double n1, double cos1, double n2, double cos2) {
  const double rs = (n1 * cos1 - n2 * cos2) / (n1 * cos1 + n2 * cos2);
  const double rp = (n2 * cos1 - n1 * cos2) / (n2 * cos1 + n1 * cos2);
  return 1.0 - 0.5 * (rs * rs + rp * rp);
}

double path_transmittance(const SequentialTracer& tracer, const Eigen::Vector3d& direction_before, std::span<const SurfaceHit> path,
                          double wavelength_nm, bool backward) {
  double t = 1.0;
  Eigen::Vector3d incoming = direction_before;
  for (const SurfaceHit& h : path) {
    const double n_before = tracer.index_after(h.surface - 1, wavelength_nm);
    const double n_after = tracer.index_after(h.surface, wavelength_nm);
    const double n1 = backward ? n_after : n_before;
    const double n2 = backward ? n_before : n_after;
    if (n1 != n2) t *= fresnel_transmittance(n1, std::abs(incoming.dot(h.normal)), n2, std::abs(h.direction_after.dot(h.normal)));
    incoming = h.direction_after;
  }
  return t;
}

}  // namespace lensmith
