// An optical material: refractive index relative to air as a function of wavelength.
// Dispersion formulas 1, 2 and 3 of the refractiveindex.info database (M. N. Polyanskiy,
// Sci. Data 11, 94 (2024); docs/glass.md), a model glass from nd and Vd, and constant indices.
#pragma once

#include <array>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace lensmith {

// Inclusive wavelength interval in nanometres.
struct WavelengthRange {
  double min_nm = 0.0;
  double max_nm = 0.0;
  bool contains(double wavelength_nm) const { return wavelength_nm >= min_nm && wavelength_nm <= max_nm; }
  friend bool operator==(const WavelengthRange&, const WavelengthRange&) = default;
};

class Glass {
 public:
  // How n(lambda) is computed. The numeric values match refractiveindex.info's "formula N".
  enum class Formula {
    Sellmeier = 1,      // n^2 - 1 = C1 + sum_i C(2i) l^2 / (l^2 - C(2i+1)^2), l in um
    Sellmeier2 = 2,     // n^2 - 1 = C1 + sum_i C(2i) l^2 / (l^2 - C(2i+1)),   l in um
    Polynomial = 3,     // n^2 = C1 + sum_i C(2i) l^C(2i+1),                  l in um
    // Zemax AGF formulas with no refractiveindex.info equivalent (200 + the AGF number; the others
    // become formulas 2 and 3 when an AGF is read):
    Herzberger = 203,     // n = A + B L + C L^2 + D l^2 + E l^4 + F l^6, L = 1 / (l^2 - 0.028)
    AgfSellmeier2 = 204,  // n^2 - 1 = A + B1 l^2 / (l^2 - L1^2) + B2 / (l^2 - L2^2)
    Conrady = 205,        // n = n0 + A / l + B / l^3.5
    Handbook1 = 207,      // n^2 = A + B / (l^2 - C) - D l^2
    Handbook2 = 208,      // n^2 = A + B l^2 / (l^2 - C) - D l^2
    ModelCauchy = 100,  // model glass from nd, Vd: n = A + B / l^2 (docs/glass.md)
    Constant = 101,     // n independent of wavelength (air, or an index without dispersion data)
  };

  // Availability as the vendor's catalogue states it: the Zemax AGF status codes 0..3
  // (docs/glass.md, "Status"). Unspecified for glasses from data sheets that give none and for
  // model, constant and air.
  enum class Status { Unspecified, Standard, Preferred, Obsolete, Special };
  // "unspecified", "standard", "preferred", "obsolete", "special": the words of the JSON format.
  static std::string_view status_name(Status status);

  // Air: n = 1 at every wavelength (catalogue indices are relative to air).
  static Glass air();
  // A wavelength-independent index n > 0, e.g. from a pbrt lens file. `name` is for display.
  static Glass constant(double n, std::string name = {});
  // A model glass that reproduces nd at 587.5618 nm and Vd = (nd - 1) / (nF - nC) exactly, using
  // Cauchy's n = A + B / lambda^2. Throws GlassError unless nd >= 1 and Vd > 0.
  static Glass model(double nd, double vd);
  // A catalogue glass. Throws GlassError when the coefficient count does not fit the formula.
  static Glass from_formula(std::string name, std::string vendor, Formula formula, std::vector<double> coefficients,
                            WavelengthRange valid_range_nm, double catalog_nd, double catalog_vd);

  // Refractive index at `wavelength_nm`, without a range check (extrapolates outside it).
  double index(double wavelength_nm) const;
  // Refractive index; throws GlassError naming the glass and its range when the wavelength lies
  // outside the range where the formula is valid.
  double index_checked(double wavelength_nm) const;
  // True when `wavelength_nm` lies inside the valid range (always true for air, constant, model).
  bool covers(double wavelength_nm) const;

  // nd computed from the formula at the helium d line (587.5618 nm).
  double nd() const;
  // Vd = (nd - 1) / (nF - nC) computed from the formula; +infinity for a constant index.
  double vd() const;
  // nF - nC from the formula (F = 486.1327 nm, C = 656.2725 nm).
  double principal_dispersion() const;

  const std::string& name() const { return name_; }
  const std::string& vendor() const { return vendor_; }
  Formula formula() const { return formula_; }
  const std::vector<double>& coefficients() const { return coefficients_; }
  const WavelengthRange& valid_range_nm() const { return range_nm_; }
  // nd and Vd as printed in the catalogue (NaN when the catalogue gives none).
  double catalog_nd() const { return catalog_nd_; }
  double catalog_vd() const { return catalog_vd_; }
  bool is_air() const { return formula_ == Formula::Constant && constant_index_ == 1.0 && name_ == "air"; }

  Status status() const { return status_; }
  // The glass the vendor names as this one's successor ("N-SF15" for SF15), or "" when none.
  const std::string& replaced_by() const { return replaced_by_; }
  // Records the catalogue status (used by GlassCatalog when it reads a catalogue).
  void set_catalog_status(Status status, std::string replaced_by = {});

  // Equal when every field is equal; a missing catalogue nd or Vd (NaN) equals a missing one, so
  // a glass always equals its copy.
  friend bool operator==(const Glass& a, const Glass& b);
  // "SCHOTT N-BK7 (formula 2, 300-2500 nm, nd 1.51680, Vd 64.17)"
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const Glass& g) { return os << g.to_string(); }

 private:
  std::string name_;
  std::string vendor_;
  Formula formula_ = Formula::Constant;
  std::vector<double> coefficients_;
  WavelengthRange range_nm_{0.0, 1.0e9};
  double catalog_nd_ = 0.0;
  double catalog_vd_ = 0.0;
  double constant_index_ = 1.0;
  Status status_ = Status::Unspecified;
  std::string replaced_by_;
};

// How far a model glass (Glass::model) of this Abbe number strays from real glass, for warnings:
// the worst difference from every built-in catalogue glass of its class (crowns Vd >= 50, middle
// 35-50, flints < 35), measured with each glass's own nd and Vd (docs/glass.md), e.g. "within 2e-4
// from 450 to 700 nm, up to 8e-4 at 400 nm and 3e-4 at 750 nm (worst of the catalogues' crowns)".
std::string model_glass_accuracy(double vd);

}  // namespace lensmith
