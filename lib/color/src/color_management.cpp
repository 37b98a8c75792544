// Colour management (color_management.h): the config and the options checked here, the conversions
// made and applied by OpenColorIO through ocio_backend.h.
#include "lensmith/color/color_management.h"

#include <array>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <system_error>

#include "lensmith/color/rgb_primaries.h"
#include "lensmith/core/errors.h"
#include "ocio_backend.h"

namespace lensmith {

struct ColorManagement::Processors {
  const color_detail::OcioBackend* backend = nullptr;
  color_detail::OcioConversions* conversions = nullptr;
  Processors() = default;
  Processors(const Processors&) = delete;
  Processors& operator=(const Processors&) = delete;
  ~Processors() {
    if (conversions != nullptr) backend->close(conversions);
  }
};

namespace {

void apply(const color_detail::OcioBackend& backend, const color_detail::OcioConversions& conversions, bool to_working,
           std::span<float> pixels, int channels) {
  if (pixels.empty()) return;
  if (channels < 3 || pixels.size() % static_cast<std::size_t>(channels) != 0) {
    throw OptionsError("colour management: " + std::to_string(pixels.size()) + " floats are not pixels of " + std::to_string(channels) +
                       " channels (at least R, G, B)");
  }
  backend.apply(conversions, to_working, pixels.data(), static_cast<long>(pixels.size() / static_cast<std::size_t>(channels)), channels);
}

}  // namespace

std::string ColorManagementOptions::to_string() const {
  std::ostringstream os;
  os << "ColorManagementOptions{config " << (config.empty() ? "$OCIO" : config) << ", input "
     << (input_colorspace.empty() ? "linear Rec.709" : input_colorspace) << ", output "
     << (output_colorspace.empty() ? "linear Rec.709" : output_colorspace);
  if (!working_colorspace.empty()) os << ", working " << working_colorspace;
  os << "}";
  return os.str();
}

ColorManagement::ColorManagement(const ColorManagementOptions& options) : options_(options), processors_(std::make_unique<Processors>()) {
  config_path_ = options.config;
  if (config_path_.empty()) {
    const char* env = std::getenv("OCIO");
    if (env == nullptr || *env == '\0') {
      throw IoError("colour spaces need an OpenColorIO config: give --ocio CONFIG or set $OCIO (docs/color-management.md)");
    }
    config_path_ = env;
  }
  std::error_code ec;
  if (!std::filesystem::is_regular_file(config_path_, ec)) {
    throw IoError(config_path_ + ": no such OpenColorIO config file" + (options.config.empty() ? " (from $OCIO)" : ""));
  }
  // The aces_interchange role's way to the working space: ACES AP0 -> linear Rec.709, Bradford.
  const Matrix3 m = rgb_conversion(kAcesAp0Primaries, kRec709Primaries);
  std::array<double, 9> ap0_to_rec709{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) ap0_to_rec709[static_cast<std::size_t>(3 * i + j)] = m.m[i][j];
  processors_->backend = &color_detail::ocio_backend();
  color_detail::OcioFailure failure;
  processors_->conversions = processors_->backend->open(options, config_path_, ap0_to_rec709, working_route_, failure);
  if (processors_->conversions == nullptr) {
    if (failure.options_error) throw OptionsError(failure.message);
    throw IoError(failure.message);
  }
}

ColorManagement::~ColorManagement() = default;
ColorManagement::ColorManagement(ColorManagement&&) noexcept = default;
ColorManagement& ColorManagement::operator=(ColorManagement&&) noexcept = default;

void ColorManagement::input_to_working(std::span<float> pixels, int channels) const {
  apply(*processors_->backend, *processors_->conversions, true, pixels, channels);
}

void ColorManagement::working_to_output(std::span<float> pixels, int channels) const {
  apply(*processors_->backend, *processors_->conversions, false, pixels, channels);
}

}  // namespace lensmith
