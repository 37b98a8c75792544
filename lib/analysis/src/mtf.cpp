// FFT MTF: the pupil function's autocorrelation by two 2-D FFTs (lensmith/analysis/mtf.h says what and
// why; Goodman, Introduction to Fourier Optics, eq. 6-31).
#include "lensmith/analysis/mtf.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <sstream>

#include <unsupported/Eigen/FFT>

#include "analysis_detail.h"
#include "lensmith/analysis/wavefront.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"
#include "lensmith/glass/glass.h"
#include "lensmith/paraxial/paraxial_system.h"

namespace lensmith {

namespace {

using Complex = std::complex<double>;

// In-place 2-D FFT of an m x m row-major array (rows, then columns).
void fft2(std::vector<Complex>& a, int m, bool inverse, Eigen::FFT<double>& fft) {
  std::vector<Complex> in(static_cast<std::size_t>(m)), out(static_cast<std::size_t>(m));
  const auto mm = static_cast<std::size_t>(m);
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t line = 0; line < mm; ++line) {
      for (std::size_t k = 0; k < mm; ++k) in[k] = pass == 0 ? a[line * mm + k] : a[k * mm + line];
      if (inverse) fft.inv(out, in);
      else fft.fwd(out, in);
      for (std::size_t k = 0; k < mm; ++k) (pass == 0 ? a[line * mm + k] : a[k * mm + line]) = out[k];
    }
  }
}

// The OTF (normalised to 1 at 0) and the PSF's peak of a pupil function placed in an m x m array.
struct Transfer {
  std::vector<Complex> otf;
  double psf_peak = 0.0;
};

Transfer transfer(std::vector<Complex> pupil, int m, Eigen::FFT<double>& fft) {
  fft2(pupil, m, false, fft);
  Transfer t;
  for (Complex& c : pupil) {
    const double intensity = std::norm(c);
    t.psf_peak = std::max(t.psf_peak, intensity);
    c = intensity;
  }
  fft2(pupil, m, true, fft);
  const Complex zero = pupil[0];
  for (Complex& c : pupil) c /= zero;
  t.otf = std::move(pupil);
  return t;
}

// The OTF at a fractional shift s (samples, >= 0) along x (along_y false) or y, linear between samples;
// shifts beyond the array's half are past the cutoff (0).
Complex otf_at(const std::vector<Complex>& otf, int m, double s, bool along_y) {
  if (!(s < 0.5 * m - 1.0)) return 0.0;
  const int k = static_cast<int>(s);
  const double t = s - k;
  auto at = [&](int i) { return along_y ? otf[static_cast<std::size_t>(i) * static_cast<std::size_t>(m)] : otf[static_cast<std::size_t>(i)]; };
  return (1.0 - t) * at(k) + t * at(k + 1);
}

// The pupil function of a wavefront map, and the same pupil without aberration, in the corner of m x m
// arrays (rows from py = -1). `defocus_waves` (waves of the map's wavelength per unit 1 - cos a) and
// `sine_per_rho` (sin a at the rim) add a spherical wave's defocus, n' dz (1 - cos a) (through focus).
void fill_pupil(const WavefrontMap& map, int m, std::vector<Complex>& pupil, std::vector<Complex>& perfect, double defocus_waves = 0.0,
                double sine_per_rho = 0.0) {
  const int n = map.grid;
  pupil.assign(static_cast<std::size_t>(m) * static_cast<std::size_t>(m), 0.0);
  perfect.assign(pupil.size(), 0.0);
  for (int row = 0; row < n; ++row) {
    for (int col = 0; col < n; ++col) {
      const OpdSample& o = map.map[static_cast<std::size_t>(row) * static_cast<std::size_t>(n) + static_cast<std::size_t>(col)];
      if (o.status != RayStatus::Ok || !std::isfinite(o.opd_waves)) continue;
      const std::size_t at = static_cast<std::size_t>(row) * static_cast<std::size_t>(m) + static_cast<std::size_t>(col);
      double w = o.opd_waves;
      if (defocus_waves != 0.0) {
        const double sin_a = std::min(1.0, std::hypot(o.px, o.py) * sine_per_rho);
        w += defocus_waves * (1.0 - std::sqrt(1.0 - sin_a * sin_a));
      }
      // The amplitude (1, or the ray's Fresnel transmittance's root) apodises both: the aberration-free pupil
      // is the same pupil without its phase.
      pupil[at] = std::polar(o.amplitude, 2.0 * kPi * w);
      perfect[at] = o.amplitude;
    }
  }
}

int transform_size(int pupil_samples, int padding) {
  int m = 1;
  while (m < pupil_samples * padding) m *= 2;
  return m;
}

// The wavelength in the image space's medium, mm (an image in glass: lambda / n').
double medium_wavelength_mm(const AnalysisContext& context, double nm) {
  return mm_from_nm(nm) / std::abs(context.lens().surfaces.back().medium.index(nm));
}

// The OPD maps a pupil function is made of (no Zernike fit, short fans).
Wavefront pupil_wavefront(const AnalysisContext& context, int pupil_samples, bool transmittance) {
  WavefrontOptions w;
  w.grid = pupil_samples;
  w.transmittance = transmittance;
  w.zernike_terms = 1;
  w.fan_samples = 3;
  return compute_wavefront(context, w);
}

// Each wavelength's share of the polychromatic OTF and PSF: `weights` normalised to sum 1 (one per analysed
// wavelength, each >= 0), or equal shares when empty (OpticStudio weights the OTFs so).
std::vector<double> wavelength_shares(const std::vector<double>& weights, std::size_t waves, const char* who) {
  if (weights.empty()) return std::vector<double>(waves, 1.0 / static_cast<double>(waves));
  if (weights.size() != waves) {
    throw OptionsError(std::string(who) + "::wavelength_weights: " + std::to_string(weights.size()) + " weights for " + std::to_string(waves) +
                       " wavelengths: give one per wavelength");
  }
  double sum = 0.0;
  for (double w : weights) {
    if (!(std::isfinite(w) && w >= 0.0)) throw OptionsError(std::string(who) + "::wavelength_weights: each weight must be finite and >= 0");
    sum += w;
  }
  if (!(sum > 0.0)) throw OptionsError(std::string(who) + "::wavelength_weights: at least one weight must be > 0");
  std::vector<double> shares;
  for (double w : weights) shares.push_back(w / sum);
  return shares;
}

}  // namespace

void MtfOptions::validate() const {
  analysis_detail::check_count("MtfOptions::pupil_samples", pupil_samples, 16, 512);
  analysis_detail::check_count("MtfOptions::padding", padding, 2, 16);
  analysis_detail::check_count("MtfOptions::frequency_samples", frequency_samples, 2, 1001);
  if (!(max_frequency_per_mm >= 0.0) || !std::isfinite(max_frequency_per_mm)) {
    throw OptionsError("MtfOptions::max_frequency_per_mm = " + std::to_string(max_frequency_per_mm) + ": must be finite and >= 0 (0: the cutoff)");
  }
}

Mtf compute_mtf(const AnalysisContext& context, const MtfOptions& options) {
  options.validate();
  const Wavefront wavefront = pupil_wavefront(context, options.pupil_samples, options.transmittance);
  const int n = options.pupil_samples;
  const int m = transform_size(n, options.padding);
  const double exit_pupil_radius_mm = 0.5 * context.paraxial().exit_pupil().diameter_mm;
  const double step_mm = 2.0 * exit_pupil_radius_mm / (n - 1);  // pupil sample step on the exit pupil

  Mtf out;
  out.lens_name = wavefront.lens_name;
  out.wavelengths_nm = wavefront.wavelengths_nm;
  const std::size_t waves = out.wavelengths_nm.size();
  const std::vector<double> share = wavelength_shares(options.wavelength_weights, waves, "MtfOptions");
  // The cutoff at the reference wavelength on axis (the first field's radius); the curves run to the
  // shortest wavelength's, the highest any wavelength passes.
  // The wavelength in the image space's medium sets the scale.
  auto medium_wavelength_mm = [&](double nm) { return lensmith::medium_wavelength_mm(context, nm); };
  const double radius_mm = std::abs(wavefront.maps.front().reference_radius_mm);
  out.cutoff_per_mm = 2.0 * exit_pupil_radius_mm / (medium_wavelength_mm(wavefront.reference_wavelength_nm) * radius_mm);
  double top = options.max_frequency_per_mm;
  for (double nm : out.wavelengths_nm) {
    if (options.max_frequency_per_mm == 0.0) top = std::max(top, 2.0 * exit_pupil_radius_mm / (medium_wavelength_mm(nm) * radius_mm));
  }
  for (int i = 0; i < options.frequency_samples; ++i) out.frequencies_per_mm.push_back(top * i / (options.frequency_samples - 1));

  Eigen::FFT<double> fft;
  const auto nf = out.frequencies_per_mm.size();
  for (std::size_t f = 0; f < wavefront.maps.size(); f += waves) {
    MtfCurve curve;
    curve.relative_field = wavefront.maps[f].relative_field;
    curve.field_value = wavefront.maps[f].field_value;
    curve.field_label = wavefront.maps[f].field_label;
    std::vector<Complex> t(nf), s(nf), limit(nf), geometric_t(nf), geometric_s(nf);
    for (std::size_t k = 0; k < waves; ++k) {
      const WavefrontMap& map = wavefront.maps[f + k];
      std::vector<Complex> pupil, perfect;
      fill_pupil(map, m, pupil, perfect);
      const Transfer real = transfer(std::move(pupil), m, fft), ideal = transfer(std::move(perfect), m, fft);
      curve.strehl += real.psf_peak / ideal.psf_peak * share[k];
      // The geometric MTF: the landing points of the wavefront's own rays, Fourier transformed directly.
      std::vector<double> xs, ys;
      for (const OpdSample& o : map.map) {
        if (o.status != RayStatus::Ok || !std::isfinite(o.opd_waves)) continue;
        xs.push_back(o.x_mm - map.reference.x_mm);
        ys.push_back(o.y_mm - map.reference.y_mm);
      }
      for (std::size_t i = 0; i < nf && !xs.empty(); ++i) {
        Complex gt = 0.0, gs = 0.0;
        const double w = 2.0 * kPi * out.frequencies_per_mm[i];
        for (std::size_t r = 0; r < xs.size(); ++r) {
          gt += std::polar(1.0, w * ys[r]);
          gs += std::polar(1.0, w * xs[r]);
        }
        geometric_t[i] += gt * share[k] / static_cast<double>(xs.size());
        geometric_s[i] += gs * share[k] / static_cast<double>(xs.size());
      }
      // A shift of one sample is the frequency step / (lambda R).
      const double per_sample = step_mm / (medium_wavelength_mm(map.wavelength_nm) * std::abs(map.reference_radius_mm));
      for (std::size_t i = 0; i < nf; ++i) {
        const double shift = out.frequencies_per_mm[i] / per_sample;
        t[i] += otf_at(real.otf, m, shift, true) * share[k];
        s[i] += otf_at(real.otf, m, shift, false) * share[k];
        limit[i] += otf_at(ideal.otf, m, shift, true) * share[k];
      }
    }
    for (std::size_t i = 0; i < nf; ++i) {
      curve.tangential.push_back(std::abs(t[i]));
      curve.sagittal.push_back(std::abs(s[i]));
      curve.diffraction_limit.push_back(std::abs(limit[i]));
      curve.geometric_tangential.push_back(std::abs(geometric_t[i]));
      curve.geometric_sagittal.push_back(std::abs(geometric_s[i]));
    }
    out.fields.push_back(std::move(curve));
  }
  return out;
}

ThroughFocusMtf compute_through_focus_mtf(const AnalysisContext& context, double frequency_per_mm, const std::vector<double>& focus_shifts_mm,
                                          const MtfOptions& options) {
  options.validate();
  if (!(frequency_per_mm > 0.0) || !std::isfinite(frequency_per_mm)) {
    throw OptionsError("through-focus MTF: the frequency must be > 0 cycles/mm, got " + std::to_string(frequency_per_mm));
  }
  if (focus_shifts_mm.empty()) throw OptionsError("through-focus MTF: no focus shifts given");
  const Wavefront wavefront = pupil_wavefront(context, options.pupil_samples, options.transmittance);
  const int n = options.pupil_samples, m = transform_size(n, options.padding);
  const double exit_pupil_radius_mm = 0.5 * context.paraxial().exit_pupil().diameter_mm;
  const double step_mm = 2.0 * exit_pupil_radius_mm / (n - 1);
  const std::size_t waves = wavefront.wavelengths_nm.size();
  const std::vector<double> share = wavelength_shares(options.wavelength_weights, waves, "MtfOptions");
  ThroughFocusMtf out;
  out.lens_name = wavefront.lens_name;
  out.frequency_per_mm = frequency_per_mm;
  out.focus_shifts_mm = focus_shifts_mm;
  Eigen::FFT<double> fft;
  for (std::size_t f = 0; f < wavefront.maps.size(); f += waves) {
    MtfCurve curve;
    curve.relative_field = wavefront.maps[f].relative_field;
    curve.field_value = wavefront.maps[f].field_value;
    curve.field_label = wavefront.maps[f].field_label;
    for (double dz : focus_shifts_mm) {
      Complex t = 0.0, s = 0.0, limit = 0.0;
      for (std::size_t k = 0; k < waves; ++k) {
        const WavefrontMap& map = wavefront.maps[f + k];
        const double wave_mm = medium_wavelength_mm(context, map.wavelength_nm);
        const double radius = std::abs(map.reference_radius_mm);
        // n' dz (1 - cos a) in waves of the vacuum wavelength = dz (1 - cos a) / lambda'.
        std::vector<Complex> pupil, perfect;
        fill_pupil(map, m, pupil, perfect, dz / wave_mm, exit_pupil_radius_mm / radius);
        const Transfer real = transfer(std::move(pupil), m, fft), ideal = transfer(std::move(perfect), m, fft);
        const double shift = frequency_per_mm / (step_mm / (wave_mm * radius));
        t += otf_at(real.otf, m, shift, true) * share[k];
        s += otf_at(real.otf, m, shift, false) * share[k];
        limit += otf_at(ideal.otf, m, shift, true) * share[k];
      }
      curve.tangential.push_back(std::abs(t));
      curve.sagittal.push_back(std::abs(s));
      curve.diffraction_limit.push_back(std::abs(limit));
    }
    out.fields.push_back(std::move(curve));
  }
  return out;
}

std::string ThroughFocusMtf::to_string() const {
  std::ostringstream os;
  char cell[128];
  std::snprintf(cell, sizeof cell, "%.2f", frequency_per_mm);
  os << "Through-focus MTF at " << cell << " cycles/mm (FFT): " << lens_name << "\n";
  for (const MtfCurve& c : fields) {
    os << "\nField " << c.field_label << " (relative " << c.relative_field << ")\n  focus shift mm  tangential  sagittal  diffraction limit\n";
    for (std::size_t i = 0; i < focus_shifts_mm.size(); ++i) {
      std::snprintf(cell, sizeof cell, "  %14.4f  %10.4f  %8.4f  %17.4f\n", focus_shifts_mm[i], c.tangential[i], c.sagittal[i], c.diffraction_limit[i]);
      os << cell;
    }
  }
  return os.str();
}

void PsfOptions::validate() const {
  analysis_detail::check_count("PsfOptions::pupil_samples", pupil_samples, 16, 512);
  analysis_detail::check_count("PsfOptions::padding", padding, 2, 16);
  analysis_detail::check_count("PsfOptions::size", size, 8, transform_size(pupil_samples, padding));
}

Psf compute_psf(const AnalysisContext& context, const PsfOptions& options) {
  options.validate();
  const Wavefront wavefront = pupil_wavefront(context, options.pupil_samples, options.transmittance);
  const int n = options.pupil_samples, m = transform_size(n, options.padding);
  const double step_mm = 2.0 * (0.5 * context.paraxial().exit_pupil().diameter_mm) / (n - 1);
  // The image-plane sampling of a wavelength's transform: lambda' R / (m dp).
  auto spacing_mm = [&](const WavefrontMap& map) {
    return medium_wavelength_mm(context, map.wavelength_nm) * std::abs(map.reference_radius_mm) / (m * step_mm);
  };
  Psf out;
  out.lens_name = wavefront.lens_name;
  out.wavelengths_nm = wavefront.wavelengths_nm;
  out.size = options.size;
  const std::size_t waves = out.wavelengths_nm.size();
  const std::vector<double> share = wavelength_shares(options.wavelength_weights, waves, "PsfOptions");
  std::size_t reference = 0;
  for (std::size_t k = 0; k < waves; ++k) {
    if (out.wavelengths_nm[k] == wavefront.reference_wavelength_nm) reference = k;
  }
  out.spacing_mm = spacing_mm(wavefront.maps[reference]);
  const int size = options.size;
  Eigen::FFT<double> fft;
  for (std::size_t f = 0; f < wavefront.maps.size(); f += waves) {
    FieldPsf field;
    field.relative_field = wavefront.maps[f].relative_field;
    field.field_value = wavefront.maps[f].field_value;
    field.field_label = wavefront.maps[f].field_label;
    field.centre = wavefront.maps[f].reference;
    field.intensity.assign(static_cast<std::size_t>(size) * static_cast<std::size_t>(size), 0.0);
    for (std::size_t k = 0; k < waves; ++k) {
      const WavefrontMap& map = wavefront.maps[f + k];
      std::vector<Complex> pupil, perfect;
      fill_pupil(map, m, pupil, perfect);
      fft2(pupil, m, false, fft);
      fft2(perfect, m, false, fft);
      double ideal_peak = 0.0, peak = 0.0;
      for (const Complex& c : perfect) ideal_peak = std::max(ideal_peak, std::norm(c));
      for (const Complex& c : pupil) peak = std::max(peak, std::norm(c));
      field.strehl += peak / ideal_peak * share[k];
      // Sample the periodic transform at each output point, bilinearly. The transform's index runs
      // against the image coordinate: a wavefront leading at +x (W rising with px) sends its light to -x
      // (e_x = -(R / n') dW/dx), while its transform peaks at a positive index.
      const double d = spacing_mm(map);
      auto at = [&](int i, int j) {
        const int wi = ((i % m) + m) % m, wj = ((j % m) + m) % m;
        return std::norm(pupil[static_cast<std::size_t>(wj) * static_cast<std::size_t>(m) + static_cast<std::size_t>(wi)]);
      };
      for (int r = 0; r < size; ++r) {
        const double y = (0.5 * size - r) * out.spacing_mm;
        for (int c = 0; c < size; ++c) {
          const double x = (c - 0.5 * size) * out.spacing_mm;
          const double u = -x / d, v = -y / d;
          const int i = static_cast<int>(std::floor(u)), j = static_cast<int>(std::floor(v));
          const double tu = u - i, tv = v - j;
          const double value = (1 - tu) * (1 - tv) * at(i, j) + tu * (1 - tv) * at(i + 1, j) + (1 - tu) * tv * at(i, j + 1) + tu * tv * at(i + 1, j + 1);
          field.intensity[static_cast<std::size_t>(r) * static_cast<std::size_t>(size) + static_cast<std::size_t>(c)] +=
              value / ideal_peak * share[k];
        }
      }
    }
    double total = 0.0, sx = 0.0, sy = 0.0;
    for (int r = 0; r < size; ++r) {
      for (int c = 0; c < size; ++c) {
        const double v = field.intensity[static_cast<std::size_t>(r) * static_cast<std::size_t>(size) + static_cast<std::size_t>(c)];
        total += v;
        sx += v * (c - 0.5 * size) * out.spacing_mm;
        sy += v * (0.5 * size - r) * out.spacing_mm;
      }
    }
    field.centroid_x_mm = total > 0.0 ? sx / total : 0.0;
    field.centroid_y_mm = total > 0.0 ? sy / total : 0.0;
    out.fields.push_back(std::move(field));
  }
  return out;
}

std::string Psf::to_string() const {
  std::ostringstream os;
  char cell[160];
  os << "PSF (FFT of the pupil function): " << lens_name << "\n";
  std::snprintf(cell, sizeof cell, "%d x %d samples %.3f um apart (%.1f um across)", size, size, um_from_mm(spacing_mm),
                um_from_mm(spacing_mm * size));
  os << cell << ", about the reference chief ray; polychromatic, weighted as given (else equal weights); 1 = the aberration-free peak.\n";
  for (const FieldPsf& f : fields) {
    double peak = 0.0;
    for (double v : f.intensity) peak = std::max(peak, v);
    std::snprintf(cell, sizeof cell, ": Strehl ratio %.4f, peak %.4f, centroid (%.3f, %.3f) um", f.strehl, peak, um_from_mm(f.centroid_x_mm),
                  um_from_mm(f.centroid_y_mm));
    os << "Field " << f.field_label << " (relative " << f.relative_field << ")" << cell << "\n";
  }
  return os.str();
}

std::string Mtf::to_string() const {
  std::ostringstream os;
  char cell[128];
  os << "MTF (FFT of the pupil function): " << lens_name << "\n";
  std::snprintf(cell, sizeof cell, "%.1f", cutoff_per_mm);
  os << "Diffraction cutoff " << cell << " cycles/mm at the reference wavelength on axis; polychromatic, weighted as given (else equal weights) over";
  for (double w : wavelengths_nm) os << " " << w;
  os << " nm.\n";
  for (const MtfCurve& c : fields) {
    std::snprintf(cell, sizeof cell, "%.4f", c.strehl);
    os << "\nField " << c.field_label << " (relative " << c.relative_field << "), Strehl ratio " << cell << "\n";
    os << "  cycles/mm  tangential  sagittal  diffraction limit  geometric T  geometric S\n";
    for (std::size_t i = 0; i < frequencies_per_mm.size(); ++i) {
      std::snprintf(cell, sizeof cell, "  %9.2f  %10.4f  %8.4f  %17.4f  %11.4f  %11.4f\n", frequencies_per_mm[i], c.tangential[i], c.sagittal[i],
                    c.diffraction_limit[i], c.geometric_tangential[i], c.geometric_sagittal[i]);
      os << cell;
    }
  }
  return os.str();
}

}  // namespace lensmith
