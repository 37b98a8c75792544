// Refractive index of a glass from its catalogue dispersion formula, a Cauchy model glass from nd
// and Vd, or a constant. Formulas 1-3 as defined by refractiveindex.info ("Dispersion formulas",
// refractiveindex-info-dispersion-formulas.pdf; M. N. Polyanskiy, Sci. Data 11, 94 (2024)),
// wavelength in micrometres; the model glass is derived in docs/glass.md.
#include "lensmith/glass/glass.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"

namespace lensmith {

namespace {

// Largest |exponent| of formula 3 evaluated by repeated multiplication; catalogue exponents are
// even integers from -12 to 4, and anything else falls back to std::pow.
constexpr double kMaxIntegerExponent = 64.0;

// base^exponent for an integer exponent, by squaring: exact to a few ulp and several times faster
// than std::pow, which matters because index() runs inside ray-tracing loops.
double integer_power(double base, int exponent) {
  double factor = exponent < 0 ? 1.0 / base : base;
  unsigned k = static_cast<unsigned>(exponent < 0 ? -exponent : exponent);
  double result = 1.0;
  while (k != 0) {
    if (k & 1U) result *= factor;
    factor *= factor;
    k >>= 1U;
  }
  return result;
}

// printf-style formatting for messages (GCC 12 has no std::format).
template <typename... Args>
std::string format(const char* pattern, Args... args) {
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, pattern, args...);
  return buffer;
}

// A wavelength for messages: "300", "326.11", "184.89" nm (no trailing zeros).
std::string wavelength_text(double wavelength_nm) { return format("%.6g", wavelength_nm); }

bool same_or_both_nan(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }

bool is_catalogue_formula(Glass::Formula formula) {
  return formula == Glass::Formula::Sellmeier || formula == Glass::Formula::Sellmeier2 || formula == Glass::Formula::Polynomial ||
         formula == Glass::Formula::Herzberger || formula == Glass::Formula::AgfSellmeier2 || formula == Glass::Formula::Conrady ||
         formula == Glass::Formula::Handbook1 || formula == Glass::Formula::Handbook2;
}

// Coefficients an AGF-only formula takes (0: C1 and pairs, any odd count).
std::size_t fixed_coefficient_count(Glass::Formula formula) {
  switch (formula) {
    case Glass::Formula::Herzberger: return 6;
    case Glass::Formula::AgfSellmeier2: return 5;
    case Glass::Formula::Conrady: return 3;
    case Glass::Formula::Handbook1:
    case Glass::Formula::Handbook2: return 4;
    default: return 0;
  }
}

}  // namespace

std::string_view Glass::status_name(Status status) {
  switch (status) {
    case Status::Unspecified: return "unspecified";
    case Status::Standard: return "standard";
    case Status::Preferred: return "preferred";
    case Status::Obsolete: return "obsolete";
    case Status::Special: return "special";
  }
  return "unspecified";
}

Glass Glass::air() { return constant(1.0, "air"); }

Glass Glass::constant(double n, std::string name) {
  if (!(n > 0.0) || !std::isfinite(n)) {
    throw GlassError("constant index n = " + format("%g", n) + ": must be finite and > 0");
  }
  Glass g;
  g.name_ = name.empty() ? format("n=%.6g", n) : std::move(name);
  g.formula_ = Formula::Constant;
  g.constant_index_ = n;
  // A constant index is its own nd; it has no dispersion, so Vd is infinite.
  g.catalog_nd_ = n;
  g.catalog_vd_ = kInfinity;
  return g;
}

Glass Glass::model(double nd, double vd) {
  if (!(nd >= 1.0) || !std::isfinite(nd)) throw GlassError("model glass: nd = " + format("%g", nd) + ": must be >= 1");
  if (!(vd > 0.0) || !std::isfinite(vd)) throw GlassError("model glass: Vd = " + format("%g", vd) + ": must be > 0");
  // Cauchy n = A + B / l^2 has two parameters, fixed by the two catalogue numbers:
  //   nF - nC = B (1/lF^2 - 1/lC^2) = (nd - 1) / Vd   and   A = nd - B / ld^2.
  const double inv_sq_d = 1.0 / (um_from_nm(kWavelengthD_nm) * um_from_nm(kWavelengthD_nm));
  const double inv_sq_f = 1.0 / (um_from_nm(kWavelengthF_nm) * um_from_nm(kWavelengthF_nm));
  const double inv_sq_c = 1.0 / (um_from_nm(kWavelengthC_nm) * um_from_nm(kWavelengthC_nm));
  const double b = (nd - 1.0) / vd / (inv_sq_f - inv_sq_c);
  const double a = nd - b * inv_sq_d;
  Glass g;
  g.name_ = format("model nd=%.6g Vd=%.4g", nd, vd);
  g.formula_ = Formula::ModelCauchy;
  g.coefficients_ = {a, b};
  g.catalog_nd_ = nd;
  g.catalog_vd_ = vd;
  return g;
}

Glass Glass::from_formula(std::string name, std::string vendor, Formula formula, std::vector<double> coefficients,
                          WavelengthRange valid_range_nm, double catalog_nd, double catalog_vd) {
  const std::string label = vendor.empty() ? name : vendor + " " + name;
  if (name.empty()) throw GlassError("catalogue glass with an empty name");
  if (!is_catalogue_formula(formula)) {
    throw GlassError("glass " + label + ": formula " + std::to_string(static_cast<int>(formula)) +
                     " is not a catalogue dispersion formula (1, 2, 3, or an AGF formula 203, 204, 205, 207, 208)");
  }
  // Formulas 1-3 are C1 followed by (coefficient, pole or exponent) pairs; the AGF-only ones have
  // a fixed count.
  if (const std::size_t fixed = fixed_coefficient_count(formula); fixed > 0) {
    if (coefficients.size() != fixed) {
      throw GlassError("glass " + label + ": formula " + std::to_string(static_cast<int>(formula)) + " needs " + std::to_string(fixed) +
                       " coefficients; got " + std::to_string(coefficients.size()));
    }
  } else if (coefficients.size() % 2 != 1) {
    throw GlassError("glass " + label + ": formula " + std::to_string(static_cast<int>(formula)) +
                     " needs C1 followed by pairs of coefficients (an odd count); got " +
                     std::to_string(coefficients.size()));
  }
  for (std::size_t i = 0; i < coefficients.size(); ++i) {
    if (!std::isfinite(coefficients[i])) {
      throw GlassError("glass " + label + ": coefficient C" + std::to_string(i + 1) + " is not a finite number");
    }
  }
  if (!(valid_range_nm.min_nm > 0.0) || !(valid_range_nm.max_nm > valid_range_nm.min_nm) ||
      !std::isfinite(valid_range_nm.max_nm)) {
    throw GlassError("glass " + label + ": wavelength range " + wavelength_text(valid_range_nm.min_nm) + "-" +
                     wavelength_text(valid_range_nm.max_nm) + " nm: must satisfy 0 < min < max");
  }
  Glass g;
  g.name_ = std::move(name);
  g.vendor_ = std::move(vendor);
  g.formula_ = formula;
  g.coefficients_ = std::move(coefficients);
  g.range_nm_ = valid_range_nm;
  g.catalog_nd_ = catalog_nd;
  g.catalog_vd_ = catalog_vd;
  return g;
}

void Glass::set_catalog_status(Status status, std::string replaced_by) {
  status_ = status;
  replaced_by_ = std::move(replaced_by);
}

double Glass::index(double wavelength_nm) const {
  const std::vector<double>& c = coefficients_;
  const double l = um_from_nm(wavelength_nm);
  const double l2 = l * l;
  switch (formula_) {
    case Formula::Constant: return constant_index_;
    case Formula::ModelCauchy: return c[0] + c[1] / l2;
    case Formula::Sellmeier: {
      // n^2 - 1 = C1 + sum C(2i) l^2 / (l^2 - C(2i+1)^2)
      double n2 = 1.0 + c[0];
      for (std::size_t i = 1; i + 1 < c.size(); i += 2) n2 += c[i] * l2 / (l2 - c[i + 1] * c[i + 1]);
      return std::sqrt(n2);
    }
    case Formula::Sellmeier2: {
      // n^2 - 1 = C1 + sum C(2i) l^2 / (l^2 - C(2i+1))
      double n2 = 1.0 + c[0];
      for (std::size_t i = 1; i + 1 < c.size(); i += 2) n2 += c[i] * l2 / (l2 - c[i + 1]);
      return std::sqrt(n2);
    }
    case Formula::Herzberger: {
      const double big_l = 1.0 / (l2 - 0.028);
      return c[0] + c[1] * big_l + c[2] * big_l * big_l + l2 * (c[3] + l2 * (c[4] + l2 * c[5]));
    }
    case Formula::AgfSellmeier2: return std::sqrt(1.0 + c[0] + c[1] * l2 / (l2 - c[2] * c[2]) + c[3] / (l2 - c[4] * c[4]));
    case Formula::Conrady: return c[0] + c[1] / l + c[2] / (l2 * l * std::sqrt(l));
    case Formula::Handbook1: return std::sqrt(c[0] + c[1] / (l2 - c[2]) - c[3] * l2);
    case Formula::Handbook2: return std::sqrt(c[0] + c[1] * l2 / (l2 - c[2]) - c[3] * l2);
    case Formula::Polynomial: {
      // n^2 = C1 + sum C(2i) l^C(2i+1)
      double n2 = c[0];
      for (std::size_t i = 1; i + 1 < c.size(); i += 2) {
        const double exponent = c[i + 1];
        const bool small_integer = std::abs(exponent) <= kMaxIntegerExponent && exponent == std::trunc(exponent);
        n2 += c[i] * (small_integer ? integer_power(l, static_cast<int>(exponent)) : std::pow(l, exponent));
      }
      return std::sqrt(n2);
    }
  }
  return std::numeric_limits<double>::quiet_NaN();
}

double Glass::index_checked(double wavelength_nm) const {
  const std::string label = vendor_.empty() ? name_ : vendor_ + " " + name_;
  if (!covers(wavelength_nm)) {
    throw GlassError("glass " + label + ": wavelength " + wavelength_text(wavelength_nm) +
                     " nm is outside the range " + wavelength_text(range_nm_.min_nm) + "-" +
                     wavelength_text(range_nm_.max_nm) + " nm where its dispersion formula is valid");
  }
  const double n = index(wavelength_nm);
  // Inside the range this cannot happen for catalogue data; it catches wavelength <= 0 or NaN
  // given to a model glass.
  if (!(n > 0.0) || !std::isfinite(n)) {
    throw GlassError("glass " + label + ": no real refractive index at wavelength " + wavelength_text(wavelength_nm) + " nm");
  }
  return n;
}

bool Glass::covers(double wavelength_nm) const {
  return is_catalogue_formula(formula_) ? range_nm_.contains(wavelength_nm) : true;
}

double Glass::nd() const { return index(kWavelengthD_nm); }

double Glass::principal_dispersion() const { return index(kWavelengthF_nm) - index(kWavelengthC_nm); }

double Glass::vd() const {
  const double dispersion = principal_dispersion();
  if (dispersion == 0.0) return kInfinity;
  return (nd() - 1.0) / dispersion;
}

bool operator==(const Glass& a, const Glass& b) {
  return a.name_ == b.name_ && a.vendor_ == b.vendor_ && a.formula_ == b.formula_ &&
         a.coefficients_ == b.coefficients_ && a.range_nm_ == b.range_nm_ &&
         same_or_both_nan(a.catalog_nd_, b.catalog_nd_) && same_or_both_nan(a.catalog_vd_, b.catalog_vd_) &&
         a.constant_index_ == b.constant_index_ && a.status_ == b.status_ && a.replaced_by_ == b.replaced_by_;
}

std::string Glass::to_string() const {
  switch (formula_) {
    case Formula::Constant:
      if (name_ == format("n=%.6g", constant_index_)) return "constant n = " + format("%.6g", constant_index_);
      return name_ + " (constant n = " + format("%.6g", constant_index_) + ")";
    case Formula::ModelCauchy:
      return "model glass (Cauchy from nd " + format("%.5f", catalog_nd_) + ", Vd " + format("%.2f", catalog_vd_) + ")";
    case Formula::Sellmeier:
    case Formula::Sellmeier2:
    case Formula::Polynomial:
    case Formula::Herzberger:
    case Formula::AgfSellmeier2:
    case Formula::Conrady:
    case Formula::Handbook1:
    case Formula::Handbook2: break;
  }
  std::string s = vendor_.empty() ? name_ : vendor_ + " " + name_;
  s += " (formula " + std::to_string(static_cast<int>(formula_)) + ", " + wavelength_text(range_nm_.min_nm) + "-" +
       wavelength_text(range_nm_.max_nm) + " nm";
  if (!std::isnan(catalog_nd_)) {
    s += ", nd " + format("%.5f", catalog_nd_) + ", Vd " + format("%.2f", catalog_vd_);
  } else if (covers(kWavelengthD_nm)) {
    s += ", nd " + format("%.5f", nd()) + ", Vd " + format("%.2f", vd()) + " from the formula";
  }
  if (status_ == Status::Obsolete) {
    s += replaced_by_.empty() ? std::string(", obsolete") : ", obsolete, replaced by " + replaced_by_;
  }
  return s + ")";
}

std::string model_glass_accuracy(double vd) {
  // Measured over the 1634 vendor glasses (tools: the model built from each glass's formula nd and
  // Vd, compared with its formula where that covers the wavelength); tests/glass/glass_test.cpp
  // keeps the 450 and 650 nm bounds.
  if (vd >= 50.0) return "within 2e-4 from 450 to 700 nm, up to 8e-4 at 400 nm and 3e-4 at 750 nm (worst of the catalogues' crowns)";
  if (vd >= 35.0) return "within 1e-3 from 450 to 700 nm, up to 3.5e-3 at 400 nm (worst of the catalogues' Vd 35-50 glasses)";
  return "off by up to 7e-3 at 450 nm, 1.4e-2 at 700 nm and 3e-2 at 400 nm (worst of the catalogues' flints)";
}

}  // namespace lensmith
