#include "lensmith/prescription/material.h"

#include <cstdio>

#include "lensmith/core/errors.h"

namespace lensmith {

Glass MaterialSpec::resolve(const GlassCatalog& catalogue) const {
  switch (kind) {
    case Kind::Air: return Glass::air();
    case Kind::Catalog: return catalogue.get(glass, vendor);
    case Kind::Model:
      if (vd) return Glass::model(nd, *vd);
      return Glass::constant(nd);
  }
  throw GlassError("material of unknown kind");
}

std::string MaterialSpec::to_string() const {
  char buffer[96];
  switch (kind) {
    case Kind::Air: return "air";
    case Kind::Catalog: return vendor.empty() ? glass : vendor + ":" + glass;
    case Kind::Model:
      if (vd) {
        std::snprintf(buffer, sizeof buffer, "model nd=%.6g Vd=%.4g", nd, *vd);
      } else {
        std::snprintf(buffer, sizeof buffer, "n=%.6g", nd);
      }
      return buffer;
  }
  return "?";
}

}  // namespace lensmith
