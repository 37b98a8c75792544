// libFuzzer target: the analytic-scene reader (lensmith-scene JSON). Inputs that name an image
// texture are skipped: those read a file from disk, which is lensmith::imageio's business, not the parser's.
#include <cstdint>
#include <string_view>

#include "lensmith/core/errors.h"
#include "lensmith/scene/scene_json.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  if (text.find("image") != std::string_view::npos) return 0;
  try {
    const lensmith::Scene scene = lensmith::read_scene_json(text, "fuzz.json");
    scene.validate();  // whatever is accepted must be a valid scene
  } catch (const lensmith::Error&) {
  }
  return 0;
}
