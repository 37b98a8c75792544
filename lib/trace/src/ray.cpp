// A geometric ray and the statuses of a sequential trace: printing only (the tracing itself lives in
// sequential_tracer.cpp). Spellings of the statuses are those of `--json` output.
#include "lensmith/trace/ray.h"

#include <sstream>

namespace lensmith {

std::string_view to_string(RayStatus status) {
  switch (status) {
    case RayStatus::Ok: return "ok";
    case RayStatus::Missed: return "missed";
    case RayStatus::Vignetted: return "vignetted";
    case RayStatus::TotalInternalReflection: return "tir";
    case RayStatus::NotConverged: return "not_converged";
    case RayStatus::InvalidInput: return "invalid_input";
  }
  return "unknown";
}

std::string Ray::to_string() const {
  std::ostringstream os;
  // 17 significant digits: a failing check must show the numbers that differ, not their rounding.
  os.precision(17);
  os << "Ray{position_mm (" << position_mm.x() << ", " << position_mm.y() << ", " << position_mm.z()
     << "), direction (" << direction.x() << ", " << direction.y() << ", " << direction.z() << "), "
     << wavelength_nm << " nm}";
  return os.str();
}

}  // namespace lensmith
