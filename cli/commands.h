// The lensmith command's subcommands: each fills an options struct from the command line, makes
// one library call and prints the result. main.cpp turns exceptions into exit codes.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "lensmith/camera/ray_model.h"
#include "lensmith/core/diagnostic.h"
#include "lensmith/prescription/prescription.h"

namespace lensmith {
struct AnalysisOptions;
namespace plot {
class Canvas;
struct PlotOptions;
}  // namespace plot
}  // namespace lensmith

namespace lensmith::cli {

// Exit codes (documented in docs/cli.md).
inline constexpr int kExitOk = 0;
inline constexpr int kExitUsage = 2;         // bad command line
inline constexpr int kExitInput = 3;         // a lens file, glass or option value is wrong
inline constexpr int kExitComputation = 4;   // the lens has no answer (e.g. afocal: no focal length)
inline constexpr int kExitIo = 5;            // a file could not be read or written
inline constexpr int kExitThreshold = 6;     // lensmith validate: a declared threshold was missed
inline constexpr int kExitFrames = 7;        // lensmith bokeh --frames: some frames failed (the others were written)
inline constexpr int kExitInternal = 70;     // a bug: please report it

struct GlobalOptions {
  bool quiet = false;  // --quiet: no warnings or progress on stderr
};

struct InfoOptions {
  std::string lens;                          // file path or shipped lens name
  std::optional<double> wavelength_nm;       // default: the lens's primary wavelength
  std::optional<double> object_distance_m;   // metres from the object to surface 1; default: the lens's
  bool json = false;
  bool spectral = false;                     // add the 64-wavelength table
};
int run_info(const InfoOptions& options, const GlobalOptions& global);

struct LensesOptions {
  std::string lentil_database;  // list the entries of a lentil lenses.json instead
  bool json = false;
};
int run_lenses(const LensesOptions& options, const GlobalOptions& global);

struct ConvertOptions {
  std::string lens;
  std::string output;  // native JSON file to write
  std::optional<double> scale_to_efl_mm;  // scale the lens so its EFL (primary wavelength) becomes this
};
int run_convert(const ConvertOptions& options, const GlobalOptions& global);

// Options every real-ray analysis command shares (spot, fan, analyze); docs/cli.md.
struct RealRayCommandOptions {
  std::string lens;
  std::vector<double> relative_fields{0.0, 0.7, 1.0};  // --fields: fractions of the maximum field, 0..1
  std::vector<double> wavelengths_nm;                   // --wavelength: default the lens's
  std::optional<double> field_angle_deg;                // --field-angle: what relative field 1 means, deg
  std::string image = "prescribed";                     // --image prescribed|paraxial
  std::string aim;  // --aim paraxial|real; empty = as the lens file says (Prescription::ray_aiming)
  std::string png;                                      // --png FILE: write a picture
  bool json = false;
};

// Helpers the real-ray commands share (real_ray_command.cpp).
// The library options for `options`; throws OptionsError for an unknown --image or --aim word.
AnalysisOptions make_analysis_options(const RealRayCommandOptions& options);
// What `lensmith layout` draws by default, also for `lensmith optimize --png`: bundles that fill the real stop
// where real aiming exists (unless `aim_given`), on axis only for a lens without a field (unless `field_given`).
void apply_layout_defaults(const Prescription& lens, bool aim_given, bool field_given, AnalysisOptions& analysis);
// Plot options with the default font; warns once on stderr (unless quiet) when there is none.
plot::PlotOptions make_plot_options(const GlobalOptions& global);
struct SeidelCommandOptions {
  std::string lens;
  std::optional<double> wavelength_nm;      // default: the lens's primary wavelength
  std::optional<double> object_distance_m;  // metres from the object to surface 1; default: the lens's
  std::optional<double> field_angle_deg;    // maximum field; default: the lens's
  std::optional<double> epd_mm;             // entrance-pupil diameter; default: the lens's aperture
  std::optional<double> f_number;           // image-space F/#, instead of --epd
  std::string png;                          // --png FILE: the Seidel diagram
  bool json = false;
};
int run_seidel(const SeidelCommandOptions& options, const GlobalOptions& global);

// Writes `canvas` to `png` atomically; throws IoError when `png` is the lens file itself.
void write_picture(const plot::Canvas& canvas, const std::string& png, const std::string& lens, const GlobalOptions& global);

struct TraceCommandOptions {
  std::string lens;
  std::optional<double> field_angle_deg;   // --field-angle: object-space angle along y, deg
  std::optional<double> object_height_mm;  // --object-height: finite objects, mm along y
  std::optional<double> relative_field;    // --field: fraction of the lens's maximum field
  std::string pupil = "0,0";               // --pupil PX,PY in the unit disc
  std::optional<double> wavelength_nm;
  std::string image = "prescribed";
  std::string aim;  // empty = as the lens file says
  bool json = false;
};
int run_trace(const TraceCommandOptions& options, const GlobalOptions& global);
// "" when `text` is a valid --pupil value (PX,PY in the unit disc), else what is wrong with it.
std::string check_pupil_text(const std::string& text);

struct SpotCommandOptions {
  RealRayCommandOptions common;
  int rings = 6;                  // --rings: hexapolar rings
  std::optional<int> random_rays; // --random N: uniform random pupil points instead
  std::uint64_t seed = 1;         // --seed
};
int run_spot(const SpotCommandOptions& options, const GlobalOptions& global);

struct LayoutCommandOptions {
  RealRayCommandOptions common;  // lens, --fields, --field-angle, --aim (default real), --png
  int rays = 5;                  // --rays: rays per field bundle, from pupil edge to edge (1-101)
};
int run_layout(const LayoutCommandOptions& options, const GlobalOptions& global);

struct OptimizeCommandOptions {
  std::string lens;
  std::string merit;              // --merit: the merit file (docs/optimize.md)
  std::string output;             // -o: the optimised lens, lensmith JSON
  std::string png;                // --png: the layouts before and after
  int iterations = 50;            // --iterations: per stage (1-10000)
  bool keep_model_glass = false;  // --keep-model-glass: no substitution of catalogue glasses
  int threads = 0;                // --threads
  bool json = false;
};
int run_optimize(const OptimizeCommandOptions& options, const GlobalOptions& global);

struct FanCommandOptions {
  RealRayCommandOptions common;
  int samples = 41;  // --samples: pupil points per fan, odd
};
int run_fan(const FanCommandOptions& options, const GlobalOptions& global);

struct WavefrontCommandOptions {
  RealRayCommandOptions common;
  int grid = 64;                        // --grid: pupil samples across
  std::string zernike = "fringe";       // --zernike fringe|standard
  std::optional<int> terms;             // --terms: Zernike terms fitted (default 37)
  bool map_in_json = false;             // --json-map: the OPD grid in the JSON too
};
int run_wavefront(const WavefrontCommandOptions& options, const GlobalOptions& global);

struct MtfCommandOptions {
  RealRayCommandOptions common;
  int pupil_samples = 64;                     // --pupil-samples
  std::optional<double> max_frequency_per_mm;  // --max-frequency (default: the cutoff)
  int frequency_samples = 51;                 // --frequencies
  std::optional<double> through_focus_per_mm;  // --through-focus F: the MTF at F cycles/mm against focus
  double focus_range_mm = 0.1;                // --focus-range: shifts from -R to +R
  int focus_steps = 21;                       // --focus-steps
  bool fresnel = false;                       // --fresnel: the pupil amplitude from uncoated Fresnel transmittance
  std::vector<double> weights;                // --weights: one per wavelength (default equal)
};
int run_mtf(const MtfCommandOptions& options, const GlobalOptions& global);

struct PsfCommandOptions {
  RealRayCommandOptions common;
  int pupil_samples = 64;  // --pupil-samples
  int size = 128;          // --size: samples across the picture
  bool grid_in_json = false;  // --json-grid
  bool fresnel = false;       // --fresnel
  std::vector<double> weights;  // --weights
};
int run_psf(const PsfCommandOptions& options, const GlobalOptions& global);

struct AnalyzeCommandOptions {
  RealRayCommandOptions common;
  std::string what;              // --what distortion|field-curves|focal-shift|illumination|pupil
  std::optional<int> samples;    // --samples: field samples (wavelength samples for focal-shift)
  std::optional<int> grid;       // --grid: pupil grid cells across (illumination, pupil)
};
int run_analyze(const AnalyzeCommandOptions& options, const GlobalOptions& global);

struct BokehCommandOptions {
  std::string fit;                           // --fit FILE: the poly model's fit (default: fitted in the run)
  std::string image;                         // --image: all-in-focus picture (EXR/HDR linear; 8-bit sRGB)
  std::string depth;                         // --depth FILE[:CHANNEL]; empty = the image file's Z channel
  std::string depth_kind = "z";              // z | distance | inverse
  std::string depth_unit = "m";              // m | cm | mm
  std::string invalid_depth = "error";       // error | far | near
  std::string output;                        // -o: .exr (float + metadata) or .png/.jpg/.tif (sRGB)
  std::string lens;                          // --lens: file or shipped name
  bool thin_lens = false;                    // --thin-lens: an ideal thin lens instead
  std::optional<double> focal_length_mm;     // --focal-length (thin lens)
  std::optional<double> f_number;            // --fstop; default: the lens's own
  std::optional<double> focus_m;             // --focus, metres from the entrance pupil (or --focus-pixel)
  std::string focus_pixel;                   // --focus-pixel X,Y: focus on the depth map's value there
  // Colour management (docs/color-management.md): names in an OpenColorIO config.
  std::string ocio_config;                   // --ocio FILE (default $OCIO)
  std::string input_colorspace;              // --input-colorspace NAME (default: linear Rec.709, no conversion)
  std::string output_colorspace;             // --output-colorspace NAME (default: the input's for .exr, else linear Rec.709)
  std::string working_colorspace;            // --working-colorspace NAME: the config's linear Rec.709 (configs without aces_interchange)
  bool keep_depth = false;                   // --keep-depth: the input's planar depth as Z in an EXR output
  bool desqueeze = false;                    // --desqueeze: an anamorphic's picture at the input's width, not squeezed
  std::string other_channels = "keep";       // --other-channels keep|defocus|drop: an EXR input's other passes
  std::optional<double> sensor_width_mm;     // --sensor-width of the pinhole image; default the EXR's or 36
  std::optional<double> pinhole_focal_length_mm;  // --pinhole-focal-length; default: the lens EFL
  std::optional<double> hfov_deg;            // --hfov instead
  std::optional<int> blades;                 // --blades N
  double blade_rotation_deg = 0.0;           // --blade-rotation
  std::string aperture_image;                // --aperture-image PNG
  std::string model;                         // --model thin|paraxial|seidel|exact; default seidel (thin with --thin-lens)
  std::string seidel_coefficients = "fitted";  // --seidel-coefficients fitted|sums (RayModelOptions)
  std::string hidden = "extend";             // --hidden extend|stretch
  std::string edge_pixels = "split";         // --edge-pixels split|keep
  bool no_vignetting = false;                // --no-vignetting: every point as bright as on the axis
  bool no_spectral = false;                  // --no-spectral
  bool no_shape_reuse = false;               // --no-shape-reuse (BokehOptions::reuse_shapes)
  bool rays_per_pixel = false;               // --rays-per-pixel (BokehOptions::interpolated_rays)
  bool mesh_footprints = false;              // --mesh-footprints (BokehOptions::light_images)
  bool timings = false;                      // --timings: each stage's wall time on stderr (BokehStatistics::stages)
  int spectral_samples = 16;                 // --spectral-samples
  double highlight_gain = 1.0;               // --highlight-gain (8-bit inputs)
  double highlight_threshold = 0.98;         // --highlight-threshold
  double layer_spacing_px = 2.0;             // --layer-spacing
  int subrows = 4;                           // --subrows
  double max_blur_px = 1000.0;               // --max-blur
  int threads = 0;                           // --threads (0 = all)
  std::string method = "scatter";            // --method scatter|multiview|lightfield|ewa|gather
  int samples = 32;                          // --samples (multiview)
  int layers = 8;                            // --layers (multiview)
  int ray_grid_px = 16;                      // --ray-grid (multiview)
  bool no_cone_tracing = false;              // --no-cone-tracing (multiview)
  int views = 36;                            // --views (lightfield)
  bool no_mip_filter = false;                // --no-mip-filter (lightfield)
  std::vector<std::string> scatter_options;     // scatter-only options given on the command line
  std::vector<std::string> multiview_options;   // multiview-only options given
  std::vector<std::string> lightfield_options;  // lightfield-only options given
  bool circular_splats = false;              // --circular-splats (ewa)
  bool no_level_of_detail = false;           // --no-level-of-detail (ewa)
  std::vector<std::string> ewa_options;         // ewa-only options given
  int rings = 3;                             // --rings (gather): 3 (Jimenez, 48 taps) or 4 (Tan et al., 80)
  bool no_median = false;                    // --no-median (gather)
  std::string scene;                         // --scene FILE (gather --hidden trace): the analytic scene the picture shows
  int trace_rays = 256;                       // --trace-rays (gather --hidden trace)
  std::vector<std::string> gather_options;      // gather-only options given
  // A shot (docs/sequences.md): patterns in --image, --depth and -o, rendered frame by frame.
  std::string frames;                        // --frames LIST: 1001-1100, 1001-1100x2, 1,5,10-20
  std::string chunk;                         // --chunk I/N: only the I-th (0-based) of N contiguous chunks of the frames
  std::string curves;                        // --curves FILE: per-frame focus_m, fstop, focal_length_mm, pinhole_focal_length_mm
  bool skip_existing = false;                // --skip-existing: frames whose output exists are not rendered again
  bool list_frames = false;                  // --list-frames: print the frames (after --chunk) and render nothing
};
// One picture; a sequence when --frames is given (run_bokeh_sequence).
int run_bokeh(const BokehCommandOptions& options, const GlobalOptions& global);
// Every frame of a shot through run_bokeh, each on its own: a failing frame is reported with its
// number and leaves no file, the others go on; a summary at the end; kExitFrames when any failed.
int run_bokeh_sequence(const BokehCommandOptions& options, const GlobalOptions& global);

struct ValidateCommandOptions {
  std::string lens;
  std::optional<double> f_number;                 // --fstop; default the lens's own
  double focus_m = 3.0;                           // --focus, metres
  std::string out = "validation";                 // --out DIR: report.md and psf.png
  std::vector<std::string> models{"paraxial", "seidel"};  // --models
  std::string seidel_coefficients = "fitted";     // --seidel-coefficients fitted|sums
  int width_px = 1920;                            // --width/--height: the frame the fields refer to
  int height_px = 1080;
  int pupil_samples = 96;                         // --pupil-samples per axis
  std::optional<double> min_overlap;              // --min-overlap: fail (exit 6) below it
  std::optional<double> max_centroid_offset_um;   // --max-centroid-offset: fail above it
  std::vector<std::string> scenes;                // --scene FILE (repeatable): image-level validation
  int image_width_px = 320;                       // --image-width/--image-height of those renders
  int image_height_px = 180;
  int image_spp = 64;                             // --image-spp: ground-truth samples per pixel
  int image_layers = 4;                           // --image-layers: the scenes also as layered input (0: flat only)
  std::vector<std::string> image_methods{"scatter", "multiview", "lightfield", "ewa", "gather"};  // --image-methods
  int image_samples = 32;                         // --image-samples: multiview lens rays per pixel
  int image_views = 36;                           // --image-views: lightfield views
  int image_trace_rays = 256;                     // --image-trace-rays: gather's hybrid, rays per half-resolution pixel
  std::optional<double> min_edge_psnr_db;         // --min-edge-psnr: fail when a model's edge-band PSNR is lower
  std::string fit;                                // --fit FILE: the poly model's fit (default: fitted in the run)
};
int run_validate(const ValidateCommandOptions& options, const GlobalOptions& global);

// `lensmith fit`: a polynomial fit of a lens's ray mapping (polynomial optics), its held-out errors
// and its speed against exact tracing, optionally saved as a lensmith-fit JSON file (docs/cli.md).
struct FitCommandOptions {
  std::string lens;                      // LENS: file or shipped name
  int degree = 7;                        // --degree: highest total degree of a term (1-11)
  int terms = 0;                         // --terms: term budget per output (0 = automatic)
  int training_rays = 30000;             // --training-rays
  int test_rays = 10000;                 // --test-rays
  std::uint64_t seed = 2016;             // --seed of the training rays (the test rays use another stream)
  std::optional<double> image_radius_mm; // --image-radius: radius on the sensor plane the fit covers, mm
  std::optional<double> f_number;        // --fstop: widest f-number the fit serves (default: the lens's own)
  std::string output;                    // -o: fit file to write (atomically; never the lens file)
  bool json = false;                     // --json: one JSON object on stdout
};
int run_fit(const FitCommandOptions& options, const GlobalOptions& global);

// The fit for --model poly: read from `fit_file` (and checked against the camera's lens), or made
// now to serve `camera` (lens_fit_options_for: its f-number, a sensor radius covering its frame),
// with a progress bar unless quiet. Null when no model in `models` is poly.
std::shared_ptr<const LensFit> fit_for_models(const std::vector<RayModelKind>& models, const Camera& camera,
                                              const std::string& fit_file, const GlobalOptions& global);

// `lensmith scene render`: an analytic scene through a pinhole (all-in-focus picture and depth) or,
// as ground truth, through a lens (docs/cli.md, docs/scene-format.md).
struct SceneRenderOptions {
  std::string scene;                              // SCENE: a lensmith-scene JSON file
  std::string output;                             // -o: .exr (float + metadata) or .png/.jpg/.tif (sRGB)
  std::string depth;                              // --depth: planar depth EXR (channel Z, metres); --pinhole only
  bool pinhole = false;                           // --pinhole: the all-in-focus picture
  int layers = 0;                                 // --layers N: --pinhole as a deep EXR of N peeled layers (0 = flat)
  std::string lens;                               // --lens: file or shipped name; exact tracing
  bool thin_lens = false;                         // --thin-lens: an ideal thin lens
  std::optional<double> focal_length_mm;          // --focal-length (thin lens), mm
  std::optional<double> f_number;                 // --fstop; default the lens's own (a thin lens needs one)
  std::optional<double> focus_m;                  // --focus, metres from the entrance pupil; required through a lens
  int spp = 64;                                   // --spp: samples per pixel (of the first pass)
  std::optional<double> noise_target;             // --noise-target: double spp until the relative error is below
  std::optional<int> max_spp;                     // --max-spp: bound of --noise-target; default max(4096, spp)
  int width_px = 640;                             // --width
  int height_px = 360;                            // --height
  double sensor_width_mm = 36.0;                  // --sensor-width of the pinhole framing, mm
  std::optional<double> pinhole_focal_length_mm;  // --pinhole-focal-length; default the lens EFL (--pinhole: 50 mm)
  bool no_spectral = false;                       // --no-spectral
  int spectral_samples = 16;                      // --spectral-samples
  std::uint64_t seed = 1;                         // --seed
  bool desqueeze = false;                         // --desqueeze: an anamorphic's picture at --width, not squeezed
  int threads = 0;                                // --threads (0 = all)
};
int run_scene_render(const SceneRenderOptions& options, const GlobalOptions& global);

// Prints the reader's warnings to stderr unless quiet.
void print_diagnostics(const Diagnostics& diagnostics, const GlobalOptions& global);

// Warns on stderr (unless quiet) when the camera's f-number is faster than its lens's design
// aperture: how much of the axial beam the clear apertures then pass, and the fastest f-number they
// pass whole.
void warn_about_aperture(const Camera& camera, const GlobalOptions& global);

// The width (px) an anamorphic lens's picture of `width_px` columns is written at: narrowed by the
// camera's squeeze, as the sensor records it, unless `desqueeze` (then 0: as rendered, the input's
// framing); 0 for a lens that does not squeeze. Notes on stderr (unless quiet) what is written, and where
// the x section focuses when that is not where the sensor focuses y (docs/bokeh.md, "Anamorphic lenses").
int anamorphic_output_width(const Camera& camera, int width_px, bool desqueeze, const GlobalOptions& global);

// "wrote WHAT" on stderr unless quiet: every command reports the files it wrote there, the same
// way (stdout carries the command's results, and its JSON).
void report_written(const std::string& what, const GlobalOptions& global);

// Loads LENS (a file path or a shipped lens name) and prints its warnings.
// Reads a lens file or shipped lens, prints its diagnostics, and (unless `resolve_field` is false, as
// `convert` asks, which writes the file's field as it is) turns a real-image-height field into object
// field points by tracing (resolve_real_image_height_field), with a note saying so.
Prescription load_lens(const std::string& lens, const GlobalOptions& global, bool resolve_field = true);

}  // namespace lensmith::cli
