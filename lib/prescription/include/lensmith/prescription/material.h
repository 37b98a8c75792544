// What a lens file says a medium is (a catalogue glass, air, or a model glass), next to the glass it
// was resolved to. Resolution never substitutes a default: an unknown name is an error.
#pragma once

#include <cmath>
#include <limits>
#include <optional>
#include <ostream>
#include <string>

#include "lensmith/glass/glass.h"
#include "lensmith/glass/glass_catalog.h"

namespace lensmith {

struct MaterialSpec {
  enum class Kind {
    Air,      // n = 1
    Catalog,  // a catalogue glass by name, optionally with vendor
    Model,    // a model glass from nd and Vd (Vd absent: no dispersion, n = nd at every wavelength)
  };
  Kind kind = Kind::Air;
  std::string glass;       // Catalog: the glass name as written, e.g. "N-BK7"
  std::string vendor;      // Catalog: optional vendor, e.g. "SCHOTT"; empty = search all
  double nd = 1.0;         // Model: index at 587.5618 nm
  std::optional<double> vd;  // Model: Abbe number; empty = dispersion-free

  static MaterialSpec air() { return {}; }
  static MaterialSpec catalog(std::string name, std::string vendor = {}) {
    MaterialSpec m;
    m.kind = Kind::Catalog;
    m.glass = std::move(name);
    m.vendor = std::move(vendor);
    return m;
  }
  static MaterialSpec model(double nd, std::optional<double> vd) {
    MaterialSpec m;
    m.kind = Kind::Model;
    m.nd = nd;
    m.vd = vd;
    return m;
  }

  // Resolves to a Glass: Air -> Glass::air(); Catalog -> catalogue.get() (throws GlassError with the
  // closest names); Model -> Glass::model(nd, vd) or Glass::constant(nd).
  Glass resolve(const GlassCatalog& catalogue) const;

  friend bool operator==(const MaterialSpec&, const MaterialSpec&) = default;
  // "air", "N-BK7", "SCHOTT:N-BK7", "model nd=1.6700 Vd=47.2", "n=1.6700"
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const MaterialSpec& m) { return os << m.to_string(); }
};

}  // namespace lensmith
