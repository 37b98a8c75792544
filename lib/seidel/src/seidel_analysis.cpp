#include "lensmith/seidel/seidel_analysis.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"

namespace lensmith {

namespace {

std::string format(const char* pattern, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, pattern, value);
  return buffer;
}

// The prescription with the caller's aperture and field overrides applied.
Prescription with_overrides(const Prescription& lens, const SeidelOptions& options) {
  Prescription p = lens;
  if (options.entrance_pupil_diameter_mm) p.aperture = {ApertureSpec::Kind::EntrancePupilDiameter, *options.entrance_pupil_diameter_mm};
  if (options.f_number) p.aperture = {ApertureSpec::Kind::ImageSpaceFNumber, *options.f_number};
  if (options.object_distance_mm) p.object_distance_mm = *options.object_distance_mm;
  if (options.field_angle_deg) p.field = FieldSpec{FieldSpec::Kind::AngleDeg, {*options.field_angle_deg}};
  if (options.object_height_mm) p.field = FieldSpec{FieldSpec::Kind::ObjectHeightMm, {*options.object_height_mm}};
  return p;
}

}  // namespace

SeidelSums& SeidelSums::operator+=(const SeidelSums& o) {
  S1 += o.S1;
  S2 += o.S2;
  S3 += o.S3;
  S4 += o.S4;
  S5 += o.S5;
  C1 += o.C1;
  C2 += o.C2;
  return *this;
}

std::string SeidelSums::to_string() const {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, "S1=%.6g S2=%.6g S3=%.6g S4=%.6g S5=%.6g C1=%.6g C2=%.6g (mm)", S1, S2, S3, S4, S5, C1, C2);
  return buffer;
}

WavefrontCoefficients WavefrontCoefficients::in_waves(double wavelength_nm) const {
  const double lambda_mm = mm_from_nm(wavelength_nm);
  WavefrontCoefficients w = *this;
  for (double* v : {&w.W040, &w.W131, &w.W222, &w.W220, &w.W311, &w.W020, &w.W111}) *v /= lambda_mm;
  return w;
}

std::string WavefrontCoefficients::to_string() const {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, "W040=%.6g W131=%.6g W222=%.6g W220=%.6g W311=%.6g W020=%.6g W111=%.6g", W040, W131,
                W222, W220, W311, W020, W111);
  return buffer;
}

std::string TransverseAberrations::to_string() const {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, "TSA=%.6g TCO=%.6g TAS=%.6g SAS=%.6g PTB=%.6g DST=%.6g TAX=%.6g TLAT=%.6g (mm)", TSA, TCO,
                TAS, SAS, PTB, DST, TAX, TLAT);
  return buffer;
}

std::string LongitudinalAberrations::to_string() const {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, "LSA=%.6g LTAS=%.6g LSAS=%.6g LPTZ=%.6g LAX=%.6g (mm)", LSA, LTAS, LSAS, LPTZ, LAX);
  return buffer;
}

double FieldCurvatures::petzval_radius_mm() const { return petzval_per_mm == 0.0 ? kInfinity : -1.0 / petzval_per_mm; }

std::string FieldCurvatures::to_string() const {
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, "TCV=%.6g SCV=%.6g PCV=%.6g (1/mm)", tangential_per_mm, sagittal_per_mm, petzval_per_mm);
  return buffer;
}

void SeidelOptions::validate() const {
  if (colour_wavelengths_nm) {
    const auto [s, l] = *colour_wavelengths_nm;
    if (!(s > 100.0 && l < 20000.0 && s < l)) {
      throw OptionsError("SeidelOptions::colour_wavelengths_nm = (" + format("%g", s) + ", " + format("%g", l) +
                         "): must be short < long within (100, 20000) nm");
    }
  }
  if (wavelength_nm != 0.0 && !(wavelength_nm > 100.0 && wavelength_nm < 20000.0)) {
    throw OptionsError("SeidelOptions::wavelength_nm = " + format("%g", wavelength_nm) + ": must lie in (100, 20000) nm or be 0");
  }
  if (object_distance_mm && !(*object_distance_mm > 0.0)) {
    throw OptionsError("SeidelOptions::object_distance_mm = " + format("%g", *object_distance_mm) + ": must be > 0 (or infinity)");
  }
  if (entrance_pupil_diameter_mm && f_number) {
    throw OptionsError("SeidelOptions: entrance_pupil_diameter_mm and f_number both set: give one");
  }
  if (entrance_pupil_diameter_mm && !(std::isfinite(*entrance_pupil_diameter_mm) && *entrance_pupil_diameter_mm > 0.0)) {
    throw OptionsError("SeidelOptions::entrance_pupil_diameter_mm = " + format("%g", *entrance_pupil_diameter_mm) + ": must be > 0");
  }
  if (f_number && !(std::isfinite(*f_number) && *f_number > 0.0)) {
    throw OptionsError("SeidelOptions::f_number = " + format("%g", *f_number) + ": must be > 0");
  }
  if (field_angle_deg && object_height_mm) throw OptionsError("SeidelOptions: field_angle_deg and object_height_mm both set: give one");
  if (field_angle_deg && !(std::abs(*field_angle_deg) < 90.0)) {
    throw OptionsError("SeidelOptions::field_angle_deg = " + format("%g", *field_angle_deg) + ": must lie in (-90, 90)");
  }
  if (object_height_mm && !std::isfinite(*object_height_mm)) throw OptionsError("SeidelOptions::object_height_mm: must be finite");
}

SeidelAnalysis::SeidelAnalysis(const Prescription& lens, const SeidelOptions& options)
    : paraxial_([&] {
        options.validate();
        Prescription p = with_overrides(lens, options);
        p.validate();
        if (const auto why = p.why_not_rotationally_symmetric()) {
          // Third-order theory expands the aberrations of a rotationally symmetric system (mirrors included).
          throw ComputationError("Seidel sums do not apply: the system is not rotationally symmetric (" + *why +
                                 "); use real-ray analyses (spot, fan) instead");
        }
        if (!p.field) {
          throw PrescriptionError("Seidel sums need a field (the chief ray): the lens gives none; pass a field angle or object height");
        }
        ParaxialOptions po;
        po.wavelength_nm = options.wavelength_nm;
        return ParaxialSystem(p, po);
      }()) {
  // The overrides change only aperture, field and object distance, which the paraxial rays carry;
  // surfaces and media come from the lens as given.
  const Prescription& p = lens;
  const ParaxialRayTable& marginal = paraxial_.marginal_ray();
  const ParaxialRayTable& chief = *paraxial_.chief_ray();
  lagrange_ = *paraxial_.lagrange_invariant();
  const double H = lagrange_;

  const std::size_t count = p.surfaces.size();
  surfaces_.resize(count);
  aspheric_.resize(count);
  const double lambda = paraxial_.wavelength_nm();
  if (options.colour_wavelengths_nm) {
    colour_wavelengths_nm_ = *options.colour_wavelengths_nm;
  } else if (p.wavelengths_nm.size() >= 2) {
    const auto [lo, hi] = std::minmax_element(p.wavelengths_nm.begin(), p.wavelengths_nm.end());
    colour_wavelengths_nm_ = {*lo, *hi};
  }
  const double short_nm = colour_wavelengths_nm_[0], long_nm = colour_wavelengths_nm_[1];
  auto dispersion = [&](const Glass& g) { return g.index(short_nm) - g.index(long_nm); };
  double n = p.object_medium.index(lambda);
  double dn = dispersion(p.object_medium);  // n(short) - n(long) of the medium before the surface
  double u = marginal.object_slope;
  double ubar = chief.object_slope;

  for (std::size_t k = 0; k < count; ++k) {
    const Surface& s = p.surfaces[k];
    const ParaxialRayRow& m = marginal.rows[k];
    const ParaxialRayRow& c = chief.rows[k];
    const double n_after = m.n_after;
    const double dn_after = dispersion(s.medium);
    const double curvature = s.paraxial_curvature_per_mm();
    const double y = m.y_mm;
    const double ybar = c.y_mm;
    // Refraction invariants A = n i and A-bar = n i-bar (Welford eq. 8.21).
    const double A = n * (u + y * curvature);
    const double Abar = n * (ubar + ybar * curvature);
    const double delta_u_over_n = m.u_after / n_after - u / n;
    const double delta_inv_n = 1.0 / n_after - 1.0 / n;
    const double delta_inv_n2 = 1.0 / (n_after * n_after) - 1.0 / (n * n);
    const double delta_dispersion = dn_after / n_after - dn / n;

    SeidelSums& t = surfaces_[k];
    t.S1 = -A * A * y * delta_u_over_n;
    t.S2 = -A * Abar * y * delta_u_over_n;
    t.S3 = -Abar * Abar * y * delta_u_over_n;
    t.S4 = -H * H * curvature * delta_inv_n;
    // Division-free form of S_V = (Abar/A)(S_III + S_IV), valid where A = 0 (Welford eq. 8.28).
    t.S5 = -Abar * (Abar * Abar * delta_inv_n2 * y - (H + Abar * y) * ybar * curvature * delta_inv_n);
    t.C1 = A * y * delta_dispersion;
    t.C2 = Abar * y * delta_dispersion;

    // Conic and aspheric terms (Welford sec. 8.5): the fourth-order sag coefficient beyond that of
    // the sphere of the paraxial curvature, G, adds 8 G (n' - n) y^4 to S_I and the same times
    // e, e^2, e^3 (e = ybar / y) to S_II, S_III, S_V; written without dividing by y.
    const double base_c = s.curvature_per_mm;
    const double G = (1.0 + s.conic) * base_c * base_c * base_c / 8.0 + s.even_asphere[1] - curvature * curvature * curvature / 8.0;
    if (G != 0.0) {
      const double w = 8.0 * G * (n_after - n);
      SeidelSums& a = aspheric_[k];
      a.S1 = w * y * y * y * y;
      a.S2 = w * y * y * y * ybar;
      a.S3 = w * y * y * ybar * ybar;
      a.S5 = w * y * ybar * ybar * ybar;
      t += a;
    }
    sums_ += t;

    n = n_after;
    dn = dn_after;
    u = m.u_after;
    ubar = c.u_after;
  }
  image_slope_ = u;
  image_index_ = n;
  if (H != 0.0) {
    const double h2 = H * H;
    curvatures_ = {(3.0 * sums_.S3 + sums_.S4) / h2, (sums_.S3 + sums_.S4) / h2, sums_.S4 / h2};
  } else {
    // S_III and S_IV grow as H^2 (S_IV = -H^2 c (1/n' - 1/n) per surface): the curvatures do not
    // depend on the field, but on the axis both are 0. Take them from a nominal field (1 degree, or
    // 1 mm of object height for a near object); the paraxial rays are linear in it.
    SeidelOptions nominal = options;
    if (std::isinf(paraxial_.object_distance_mm())) {
      nominal.field_angle_deg = 1.0;
      nominal.object_height_mm.reset();
    } else {
      nominal.object_height_mm = 1.0;
      nominal.field_angle_deg.reset();
    }
    curvatures_ = SeidelAnalysis(lens, nominal).field_curvatures();
  }
}

WavefrontCoefficients SeidelAnalysis::wavefront() const {
  WavefrontCoefficients w;
  w.W040 = sums_.S1 / 8.0;
  w.W131 = sums_.S2 / 2.0;
  w.W222 = sums_.S3 / 2.0;
  w.W220 = (sums_.S3 + sums_.S4) / 4.0;
  w.W311 = sums_.S5 / 2.0;
  w.W020 = sums_.C1 / 2.0;
  w.W111 = sums_.C2;
  return w;
}

TransverseAberrations SeidelAnalysis::transverse() const {
  const double k = 1.0 / (2.0 * image_index_ * image_slope_);
  TransverseAberrations t;
  t.TSA = sums_.S1 * k;
  t.TCO = 3.0 * sums_.S2 * k;
  t.TAS = (3.0 * sums_.S3 + sums_.S4) * k;
  t.SAS = (sums_.S3 + sums_.S4) * k;
  t.PTB = sums_.S4 * k;
  t.DST = sums_.S5 * k;
  t.TAX = sums_.C1 * 2.0 * k;
  t.TLAT = sums_.C2 * 2.0 * k;
  return t;
}

LongitudinalAberrations SeidelAnalysis::longitudinal() const {
  const TransverseAberrations t = transverse();
  const double k = -1.0 / image_slope_;
  return {t.TSA * k, t.TAS * k, t.SAS * k, t.PTB * k, t.TAX * k};
}

FieldCurvatures SeidelAnalysis::field_curvatures() const { return curvatures_; }

std::string SeidelAnalysis::to_string() const {
  std::ostringstream os;
  char line[256];
  os << "Third-order (Seidel) aberrations at " << format("%.4f", wavelength_nm()) << " nm, object "
     << (std::isinf(paraxial_.object_distance_mm()) ? std::string("at infinity") : format("%.6g mm from surface 1", paraxial_.object_distance_mm()))
     << "\n  Welford sums (mm; S_I > 0 = undercorrected spherical aberration; C_I, C_II from n(" << format("%.4f", colour_wavelengths_nm_[0])
     << " nm) - n(" << format("%.4f", colour_wavelengths_nm_[1]) << " nm))\n";
  std::snprintf(line, sizeof line, "  %5s %12s %12s %12s %12s %12s %12s %12s\n", "surf", "S_I", "S_II", "S_III", "S_IV", "S_V", "C_I", "C_II");
  os << line;
  for (std::size_t k = 0; k < surfaces_.size(); ++k) {
    const SeidelSums& s = surfaces_[k];
    std::snprintf(line, sizeof line, "  %5zu %12.6f %12.6f %12.6f %12.6f %12.6f %12.6f %12.6f\n", k + 1, s.S1, s.S2, s.S3, s.S4, s.S5, s.C1, s.C2);
    os << line;
    const SeidelSums& a = aspheric_[k];
    if (a.S1 != 0.0 || a.S2 != 0.0) {
      std::snprintf(line, sizeof line, "  %5s %12.6f %12.6f %12.6f %12s %12.6f   (aspheric part, included above)\n", "asph", a.S1, a.S2, a.S3, "", a.S5);
      os << line;
    }
  }
  std::snprintf(line, sizeof line, "  %5s %12.6f %12.6f %12.6f %12.6f %12.6f %12.6f %12.6f\n", "sum", sums_.S1, sums_.S2, sums_.S3, sums_.S4, sums_.S5,
                sums_.C1, sums_.C2);
  os << line;
  const WavefrontCoefficients w = wavefront().in_waves(wavelength_nm());
  os << "\n  Wavefront coefficients (waves at " << format("%.4f", wavelength_nm()) << " nm)\n";
  std::snprintf(line, sizeof line, "    W040 %10.6f  W131 %10.6f  W222 %10.6f  W220 %10.6f  W311 %10.6f  W020 %10.6f  W111 %10.6f\n", w.W040, w.W131,
                w.W222, w.W220, w.W311, w.W020, w.W111);
  os << line;
  const TransverseAberrations t = transverse();
  os << "\n  Transverse third-order aberrations at full aperture and field (mm)\n";
  std::snprintf(line, sizeof line, "    TSA %10.6f  TCO %10.6f  TAS %10.6f  SAS %10.6f  PTB %10.6f  DST %10.6f  TAX %10.6f  TLAT %10.6f\n", t.TSA,
                t.TCO, t.TAS, t.SAS, t.PTB, t.DST, t.TAX, t.TLAT);
  os << line;
  const LongitudinalAberrations l = longitudinal();
  os << "\n  Longitudinal (mm, + = focus behind the paraxial image)\n";
  std::snprintf(line, sizeof line, "    LSA %10.6f  LTAS %10.6f  LSAS %10.6f  LPTZ %10.6f  LAX %10.6f\n", l.LSA, l.LTAS, l.LSAS, l.LPTZ, l.LAX);
  os << line;
  const FieldCurvatures f = field_curvatures();
  os << "\n  Field curvatures (1/mm, + = curving toward the lens)\n";
  std::snprintf(line, sizeof line, "    TCV %10.6f  SCV %10.6f  PCV %10.6f   Petzval radius %.4f mm\n", f.tangential_per_mm, f.sagittal_per_mm,
                f.petzval_per_mm, f.petzval_radius_mm());
  os << line;
  std::snprintf(line, sizeof line, "\n  Lagrange invariant H = %.6f mm, image-space marginal slope u' = %.6f, n' = %.6f\n", lagrange_, image_slope_, image_index_);
  os << line;
  return os.str();
}

}  // namespace lensmith
