// libFuzzer target: the polynomial-fit reader (lensmith-fit JSON). Whatever it accepts must evaluate
// and aim without crashing: the ray model calls these on every pixel.
#include <cstdint>
#include <string_view>

#include "lensmith/core/errors.h"
#include "lensmith/polyfit/lens_fit.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const lensmith::LensFit fit = lensmith::LensFit::parse(text, "fuzz.json");
    const lensmith::PlaneRay ray{1.0, -2.0, 0.05, 0.02};
    (void)fit.from_sensor(ray, 550.0);
    (void)fit.from_outer(ray, 550.0);
    (void)fit.transmittance(ray, 550.0);
    (void)fit.aim_from_sensor(1.0, 2.0, 0.5, -0.5, 550.0);
    (void)fit.aim_from_object({0.01, -0.02, 1e-3, 10.0}, 0.5, 0.5, 550.0);
  } catch (const lensmith::Error&) {
  }
  return 0;
}
