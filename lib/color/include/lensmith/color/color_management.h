// Colour management with OpenColorIO: pictures in a studio's colour spaces (ACEScg plates, say) in
// and out of lensmith's working space, linear Rec.709 (rgb.h), in which the spectral pipeline turns
// RGB into spectra (spectral_basis.h) and back. docs/color-management.md.
//
// The working space is found in the config, not assumed by name: the config's `aces_interchange`
// role (ACES2065-1, which OCIO 2 configs name so that any two configs can exchange pictures) is
// reached with OCIO, and linear Rec.709 from there by lensmith's own matrix (AP0 -> Rec.709 with
// Bradford adaptation, rgb_primaries.h). A config without that role (an OCIO 1 config) needs the
// name of its own linear Rec.709 space: `working_colorspace`. Colour spaces are converted with OCIO's
// CPU processor in 32-bit float, in place; values outside the working gamut stay (negative
// components), since the spectral pipeline is linear in RGB.
#pragma once

#include <cstddef>
#include <memory>
#include <ostream>
#include <span>
#include <string>

namespace lensmith {

struct ColorManagementOptions {
  std::string config;              // an OCIO config file; empty: the file $OCIO names
  std::string input_colorspace;    // the input picture's colour space in the config; empty: linear Rec.709 (no conversion)
  std::string output_colorspace;   // the output's; empty: linear Rec.709 (no conversion)
  std::string working_colorspace;  // the config's linear Rec.709, for configs without an aces_interchange role

  bool active() const { return !input_colorspace.empty() || !output_colorspace.empty(); }
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const ColorManagementOptions& o) { return os << o.to_string(); }
};

class ColorManagement {
 public:
  // Loads the config (from options.config, else $OCIO) and builds both conversions. Throws IoError
  // when no config is named or it cannot be read or is invalid, OptionsError when a colour space is
  // not in the config (listing some that are) or the working space cannot be found.
  explicit ColorManagement(const ColorManagementOptions& options);
  ~ColorManagement();
  ColorManagement(ColorManagement&&) noexcept;
  ColorManagement& operator=(ColorManagement&&) noexcept;

  const ColorManagementOptions& options() const { return options_; }
  const std::string& config_path() const { return config_path_; }
  // How the working space was reached, for notes and metadata: "aces_interchange role (ACES2065-1)
  // and the AP0 -> Rec.709 Bradford matrix" or "colour space lin_rec709 (--working-colorspace)".
  const std::string& working_route() const { return working_route_; }

  // Converts the first three of every `channels` floats of `pixels` (interleaved, premultiplied
  // RGB(A...)) in place: input colour space -> working, or working -> output colour space. A
  // conversion that was not asked for does nothing.
  void input_to_working(std::span<float> pixels, int channels) const;
  void working_to_output(std::span<float> pixels, int channels) const;

 private:
  struct Processors;
  ColorManagementOptions options_;
  std::string config_path_;
  std::string working_route_;
  std::unique_ptr<Processors> processors_;
};

}  // namespace lensmith
