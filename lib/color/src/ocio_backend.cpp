// OpenColorIO 2.1 behind lensmith's working space (ocio_backend.h, color_management.h).
#include "ocio_backend.h"

#include <OpenColorIO/OpenColorIO.h>

#include <memory>

namespace OCIO = OCIO_NAMESPACE;

namespace lensmith::color_detail {

struct OcioConversions {
  OCIO::ConstCPUProcessorRcPtr to_working;    // input colour space -> working (null: none asked)
  OCIO::ConstCPUProcessorRcPtr from_working;  // working -> output colour space
};

namespace {

constexpr const char* kAcesInterchange = "aces_interchange";

// A failure on the way, caught by open() and handed back as OcioFailure.
struct Failure {
  bool options_error;
  std::string message;
};

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
    throw Failure{true, flag + " " + name + ": no colour space or role of that name in the OCIO config " + path + " (it has " +
                            some_colorspaces(config) + ")"};
  }
}

// OCIO's 4x4 row-major matrix of a 3x3 (row-major).
OCIO::MatrixTransformRcPtr matrix_transform(const std::array<double, 9>& m) {
  double m44[16] = {};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m44[4 * i + j] = m[static_cast<std::size_t>(3 * i + j)];
  m44[15] = 1.0;
  OCIO::MatrixTransformRcPtr t = OCIO::MatrixTransform::Create();
  t->setMatrix(m44);
  return t;
}

void make(OcioConversions& out, const ColorManagementOptions& options, const std::string& config_path,
          const std::array<double, 9>& ap0_to_rec709, std::string& working_route) {
  OCIO::ConstConfigRcPtr config;
  try {
    config = OCIO::Config::CreateFromFile(config_path.c_str());
    config->validate();
  } catch (const OCIO::Exception& e) {
    throw Failure{false, config_path + ": not a valid OpenColorIO config: " + e.what()};
  }
  if (!options.input_colorspace.empty()) require_colorspace(config, config_path, options.input_colorspace, "--input-colorspace");
  if (!options.output_colorspace.empty()) require_colorspace(config, config_path, options.output_colorspace, "--output-colorspace");

  // Working space = `working` colour space of the config, then `tail` (a matrix, or nothing).
  std::string working;
  OCIO::MatrixTransformRcPtr tail;
  if (!options.working_colorspace.empty()) {
    require_colorspace(config, config_path, options.working_colorspace, "--working-colorspace");
    working = options.working_colorspace;
    working_route = "colour space " + working + " (--working-colorspace)";
  } else if (config->getColorSpace(kAcesInterchange)) {
    working = kAcesInterchange;
    tail = matrix_transform(ap0_to_rec709);
    working_route = std::string("the config's aces_interchange role (") + config->getColorSpace(kAcesInterchange)->getName() +
                    ") and the ACES AP0 -> linear Rec.709 Bradford matrix";
  } else {
    throw Failure{true, config_path + " has no aces_interchange role (an OCIO 1 config?): name its linear Rec.709 (sRGB primaries) "
                        "colour space with --working-colorspace, e.g. \"Utility - Linear - sRGB\" in ACES 1.x configs"};
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
      throw Failure{true, config_path + ": cannot convert between " + from_space + " and the working space: " + e.what()};
    }
  };
  if (!options.input_colorspace.empty()) out.to_working = processor(options.input_colorspace, true);
  if (!options.output_colorspace.empty()) out.from_working = processor(options.output_colorspace, false);
}

OcioConversions* open(const ColorManagementOptions& options, const std::string& config_path, const std::array<double, 9>& ap0_to_rec709,
                      std::string& working_route, OcioFailure& failure) {
  auto conversions = std::make_unique<OcioConversions>();
  try {
    make(*conversions, options, config_path, ap0_to_rec709, working_route);
  } catch (const Failure& f) {
    failure = {f.options_error, f.message};
    return nullptr;
  } catch (const std::exception& e) {
    failure = {false, config_path + ": OpenColorIO failed: " + e.what()};
    return nullptr;
  }
  return conversions.release();
}

void close(OcioConversions* conversions) { delete conversions; }

void apply(const OcioConversions& conversions, bool to_working, float* pixels, long count, int channels) {
  const OCIO::ConstCPUProcessorRcPtr& processor = to_working ? conversions.to_working : conversions.from_working;
  if (!processor || count == 0) return;
  // One row of all the pixels, R, G, B read at a stride of `channels` floats: the other channels
  // (alpha, depth, passes) are left as they are.
  const auto stride = static_cast<std::ptrdiff_t>(channels * sizeof(float));
  OCIO::PackedImageDesc image(pixels, count, 1, OCIO::CHANNEL_ORDERING_RGB, OCIO::BIT_DEPTH_F32, sizeof(float), stride, stride * count);
  processor->apply(image);
}

}  // namespace

const OcioBackend& ocio_backend() {
  static const OcioBackend backend{kOcioBackendAbi, &open, &close, &apply};
  return backend;
}

}  // namespace lensmith::color_detail
