// Image-level validation: `lensmith bokeh` with each fast ray model and each method, run on the pinhole render of
// an analytic scene, against the same scene rendered through the real lens by the exact tracer
// (which sees what a single image cannot: the hidden background), and on the scene's layered input
// (which has it, up to a number of surfaces). PSNR and SSIM on x/(1+x) values,
// over the frame and over a band around depth edges, with error maps (docs/validation.md).
#pragma once

#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "lensmith/camera/ray_model.h"
#include "lensmith/render/image_metrics.h"

namespace lensmith {

struct ImageValidationOptions {
  std::vector<std::filesystem::path> scenes;  // lensmith-scene JSON files
  std::vector<RayModelKind> models{RayModelKind::Paraxial, RayModelKind::Seidel};
  std::shared_ptr<const LensFit> fit;  // for the poly model; empty: fitted when needed
  SeidelCoefficients seidel_coefficients = SeidelCoefficients::Fitted;  // for the seidel model
  int width_px = 320;
  int height_px = 180;
  int spp = 64;                 // samples per pixel of the ground truth
  double band_radius_px = 4.0;  // depth-edge band
  int threads = 0;
  // Also each model on the scene's layered input (render_pinhole_layers, this many layers, read as a
  // deep image): what knowing the hidden surfaces buys. 0: the flat picture only.
  int layers = 4;
  // The depth-of-field methods scored, each on the flat and the layered input: "scatter"
  // (render_bokeh), "multiview" (render_multiview, `multiview_samples` lens rays per pixel) and
  // "lightfield" (render_lightfield, `lightfield_views` views), "ewa" (render_ewa) and "gather"
  // (render_gather); lightfield and ewa on the flat input only (they take one surface per pixel),
  // gather on the flat input and as Tan et al.'s hybrid, the flat input with up to
  // `gather_trace_rays` exact rays per half-resolution pixel traced into the scene where its ray
  // mask says (input "flat + traced rays").
  std::vector<std::string> methods{"scatter", "multiview", "lightfield", "ewa", "gather"};
  int multiview_samples = 32;
  int lightfield_views = 36;
  int gather_trace_rays = 256;
  // When set: <scene>-truth.png, <scene>-<model>[-<method>][-layered].png and -error.png, and
  // <scene>-methods.png, all of them side by side (per model a row of pictures, a row of errors).
  std::filesystem::path picture_dir;
  void validate() const;              // throws OptionsError
};

struct ImageValidationEntry {
  std::string scene;
  RayModelKind model = RayModelKind::Seidel;
  std::string method = "scatter";  // "scatter", "multiview", "lightfield", "ewa" or "gather"
  // "flat" (picture and depth), "layered N" (deep, N peeled layers) or "flat + traced rays" (gather's
  // hybrid)
  std::string input = "flat";
  ImageComparison comparison;
  // PSNR over the pixels where hidden surfaces can show: within half the largest blur of a hidden
  // surface from a pixel whose first surface hides another (from the layered render; NaN without).
  double hidden_psnr_db = std::numeric_limits<double>::quiet_NaN();
  double seconds = 0.0;  // the render's wall time
};

struct ImageValidation {
  std::vector<ImageValidationEntry> entries;
  std::vector<std::size_t> hidden_pixels;  // per scene: pixels in the hidden-surface region (0 without layers)
  std::vector<ImageComparison> unblurred;  // the pinhole image itself against the truth, per scene
  std::vector<std::string> scenes;
  std::string to_markdown() const;
};

ImageValidation validate_images(const Prescription& lens, const CameraOptions& camera, const ImageValidationOptions& options);

}  // namespace lensmith
