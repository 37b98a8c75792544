#include "spectral_groups.h"

#include "lensmith/color/spectral_quadrature.h"

namespace lensmith::render_detail {

namespace {
// The renderer's spectral range (nm), that of the camera's paraxial tables.
constexpr double kMinWavelengthNm = 380.0;
constexpr double kMaxWavelengthNm = 780.0;
}  // namespace

SpectralGroups::SpectralGroups(const Camera& camera, bool spectral, int samples) {
  const double reference = camera.reference_wavelength_nm();
  SpectralGroup white;
  white.wavelength_nm = reference;
  for (int c = 0; c < 3; ++c) white.m[static_cast<std::size_t>(c)][static_cast<std::size_t>(c)] = 1.0f;
  if (!spectral) {
    groups_ = {{white}};
    lowest_nm_ = highest_nm_ = reference;
    return;
  }
  SpectralQuadratureOptions q;
  q.sample_count = samples;
  q.min_wavelength_nm = kMinWavelengthNm;
  q.max_wavelength_nm = kMaxWavelengthNm;
  const SpectralQuadrature quadrature(q);
  const std::size_t n = quadrature.size();
  lowest_nm_ = quadrature.wavelengths_nm().front();
  highest_nm_ = quadrature.wavelengths_nm().back();
  groups_.assign(n, {});
  groups_[0] = {white};
  for (std::size_t count = 2; count <= n; ++count) {
    for (std::size_t g = 0; g < count; ++g) {
      const std::size_t begin = g * n / count, end = (g + 1) * n / count;
      SpectralGroup group;
      group.wavelength_nm = quadrature.wavelengths_nm()[(begin + end - 1) / 2];
      group.alpha = static_cast<float>(static_cast<double>(end - begin) / static_cast<double>(n));
      std::array<std::array<double, 3>, 3> m{};
      for (std::size_t i = begin; i < end; ++i) {
        const Rgb weight = quadrature.rgb_weights(i);
        const Rgb basis = quadrature.basis().basis_values(quadrature.wavelengths_nm()[i]);
        for (int out = 0; out < 3; ++out) {
          for (int in = 0; in < 3; ++in) m[static_cast<std::size_t>(out)][static_cast<std::size_t>(in)] += weight[out] * basis[in];
        }
      }
      for (std::size_t out = 0; out < 3; ++out) {
        for (std::size_t in = 0; in < 3; ++in) group.m[out][in] = static_cast<float>(m[out][in]);
      }
      groups_[count - 1].push_back(group);
    }
  }
}

}  // namespace lensmith::render_detail
