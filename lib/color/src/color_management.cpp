// OpenColorIO 2.1 behind lensmith's working space (color_management.h).
#include "lensmith/color/color_management.h"

#include <OpenColorIO/OpenColorIO.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <system_error>

#include "lensmith/color/rgb_primaries.h"
#include "lensmith/core/errors.h"

namespace OCIO = OCIO_NAMESPACE;

namespace lensmith {

struct ColorManagement::Processors {
  OCIO::ConstCPUProcessorRcPtr to_working;    // input colour space -> working (null: none asked)
  OCIO::ConstCPUProcessorRcPtr from_working;  // working -> output colour space
};

namespace {

constexpr const char* kAcesInterchange = "aces_interchange";

// A few of the config's colour space names, for an error message.
std::string some_colorspaces(const OCIO::ConstConfigRcPtr& config) {
  std::string names;
  const int n = config->getNumColorSpaces();
  for (int i = 0; i < n && i < 12; ++i) names += std::string(i ? ", " : "") + config->getColorSpaceNameByIndex(i);
  if (n > 12) names += ", ... (" + std::to_string(n) + " in all)";
  return names;
}

void require_colorspace(const OCIO::ConstConfigRcPtr& config, const std::string& path, const std::string& name, const std::string& flag) {
  if (!config->getColorSpace(name.c_str())) {
    throw OptionsError(flag + " " + name + ": no colour space or role of that name in the OCIO config " + path + " (it has " +
                       some_colorspaces(config) + ")");
  }
}

// OCIO's 4x4 row-major matrix of a 3x3.
OCIO::MatrixTransformRcPtr matrix_transform(const Matrix3& m) {
  double m44[16] = {};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m44[4 * i + j] = m.m[i][j];
  m44[15] = 1.0;
  OCIO::MatrixTransformRcPtr t = OCIO::MatrixTransform::Create();
  t->setMatrix(m44);
  return t;
}

void apply(const OCIO::ConstCPUProcessorRcPtr& processor, std::span<float> pixels, int channels) {
  if (!processor || pixels.empty()) return;
  if (channels < 3 || pixels.size() % static_cast<std::size_t>(channels) != 0) {
    throw OptionsError("colour management: " + std::to_string(pixels.size()) + " floats are not pixels of " + std::to_string(channels) +
                       " channels (at least R, G, B)");
  }
  // One row of all the pixels, R, G, B read at a stride of `channels` floats: the other channels
  // (alpha, depth, passes) are left as they are.
  const auto count = static_cast<long>(pixels.size() / static_cast<std::size_t>(channels));
  const auto stride = static_cast<std::ptrdiff_t>(channels * sizeof(float));
  OCIO::PackedImageDesc image(pixels.data(), count, 1, OCIO::CHANNEL_ORDERING_RGB, OCIO::BIT_DEPTH_F32, sizeof(float), stride,
                              stride * count);
  processor->apply(image);
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
  OCIO::ConstConfigRcPtr config;
  try {
    config = OCIO::Config::CreateFromFile(config_path_.c_str());
    config->validate();
  } catch (const OCIO::Exception& e) {
    throw IoError(config_path_ + ": not a valid OpenColorIO config: " + e.what());
  }
  if (!options.input_colorspace.empty()) require_colorspace(config, config_path_, options.input_colorspace, "--input-colorspace");
  if (!options.output_colorspace.empty()) require_colorspace(config, config_path_, options.output_colorspace, "--output-colorspace");

  // Working space = `working` colour space of the config, then `tail` (a matrix, or nothing).
  std::string working;
  OCIO::MatrixTransformRcPtr tail;
  if (!options.working_colorspace.empty()) {
    require_colorspace(config, config_path_, options.working_colorspace, "--working-colorspace");
    working = options.working_colorspace;
    working_route_ = "colour space " + working + " (--working-colorspace)";
  } else if (config->getColorSpace(kAcesInterchange)) {
    working = kAcesInterchange;
    tail = matrix_transform(rgb_conversion(kAcesAp0Primaries, kRec709Primaries));
    working_route_ = std::string("the config's aces_interchange role (") + config->getColorSpace(kAcesInterchange)->getName() +
                     ") and the ACES AP0 -> linear Rec.709 Bradford matrix";
  } else {
    throw OptionsError(config_path_ + " has no aces_interchange role (an OCIO 1 config?): name its linear Rec.709 (sRGB primaries) "
                       "colour space with --working-colorspace, e.g. \"Utility - Linear - sRGB\" in ACES 1.x configs");
  }
  const auto processor = [&](const std::string& from_space, bool to_working) -> OCIO::ConstCPUProcessorRcPtr {
    OCIO::GroupTransformRcPtr group = OCIO::GroupTransform::Create();
    OCIO::ColorSpaceTransformRcPtr space = OCIO::ColorSpaceTransform::Create();
    space->setSrc(from_space.c_str());
    space->setDst(working.c_str());
    group->appendTransform(space);
    if (tail) group->appendTransform(tail);
    try {
      return config
          ->getProcessor(group, to_working ? OCIO::TRANSFORM_DIR_FORWARD : OCIO::TRANSFORM_DIR_INVERSE)
          ->getOptimizedCPUProcessor(OCIO::BIT_DEPTH_F32, OCIO::BIT_DEPTH_F32, OCIO::OPTIMIZATION_DEFAULT);
    } catch (const OCIO::Exception& e) {
      throw OptionsError(config_path_ + ": cannot convert between " + from_space + " and the working space: " + e.what());
    }
  };
  if (!options.input_colorspace.empty()) processors_->to_working = processor(options.input_colorspace, true);
  if (!options.output_colorspace.empty()) processors_->from_working = processor(options.output_colorspace, false);
}

ColorManagement::~ColorManagement() = default;
ColorManagement::ColorManagement(ColorManagement&&) noexcept = default;
ColorManagement& ColorManagement::operator=(ColorManagement&&) noexcept = default;

void ColorManagement::input_to_working(std::span<float> pixels, int channels) const { apply(processors_->to_working, pixels, channels); }

void ColorManagement::working_to_output(std::span<float> pixels, int channels) const {
  apply(processors_->from_working, pixels, channels);
}

}  // namespace lensmith
