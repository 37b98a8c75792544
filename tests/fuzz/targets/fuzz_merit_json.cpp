// libFuzzer target: the merit-file reader (docs/optimize.md). Whatever it accepts is validated against a
// small lens, and, when it is small enough to evaluate quickly, evaluated: a merit function that passes
// validation must evaluate to numbers or to a stated failure, never crash.
#include <cstdint>
#include <string_view>

#include "lensmith/core/errors.h"
#include "lensmith/design/optimizer.h"

namespace {

// A singlet with a field: every operand kind applies to it.
lensmith::Prescription singlet() {
  using namespace lensmith;
  Prescription p;
  Surface front;
  front.curvature_per_mm = 1.0 / 50.0;
  front.thickness_mm = 4.0;
  front.material = MaterialSpec::model(1.5168, 64.17);
  front.medium = Glass::model(1.5168, 64.17);
  front.semi_diameter_mm = 8.0;
  front.is_stop = true;
  Surface back;
  back.curvature_per_mm = -1.0 / 50.0;
  back.thickness_mm = 47.0;
  back.semi_diameter_mm = 8.0;
  p.surfaces = {front, back};
  p.aperture = ApertureSpec{ApertureSpec::Kind::EntrancePupilDiameter, 10.0};
  p.field = FieldSpec{FieldSpec::Kind::AngleDeg, {0.0, 5.0}};
  return p;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const lensmith::MeritFunction merit = lensmith::parse_merit_function(text, "fuzz.json");
    (void)merit.to_string();
    static const lensmith::Prescription lens = singlet();
    merit.validate(lens);
    std::size_t work = 0;
    for (const lensmith::Operand& o : merit.operands) work += o.relative_fields.size() * (o.wavelengths_nm.size() + 1);
    if (merit.operands.size() <= 8 && work <= 32) (void)lensmith::evaluate_merit(lens, merit);
  } catch (const lensmith::Error&) {
  }
  return 0;
}
