// Bokeh on numpy arrays and polynomial fits from Python (docs/python.md, "Bokeh" and "Fits"): the
// camera and ray model are assembled as `lensmith bokeh` assembles them, and the same renderers run
// with the GIL released. Options come as a dict from the package's keyword arguments; an option of
// another method, or one the module does not know, is an error, as on the command line.
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "lensmith/camera/aperture.h"
#include "lensmith/camera/camera.h"
#include "lensmith/camera/camera_spec.h"
#include "lensmith/camera/ray_model.h"
#include "lensmith/core/errors.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "lensmith/polyfit/lens_fit.h"
#include "lensmith/prescription/lens_library.h"
#include "lensmith/color/color_management.h"
#include "lensmith/render/bokeh_renderer.h"
#include "lensmith/render/ewa_renderer.h"
#include "lensmith/render/gather_renderer.h"
#include "lensmith/render/image_io.h"
#include "lensmith/render/lightfield_renderer.h"
#include "lensmith/render/multiview_renderer.h"
#include "lensmith/scene/lens_render.h"
#include "lensmith/scene/scene_json.h"
#include "lensmith/trace/ray_aiming.h"

namespace lensmith::python {

namespace {

using FitPtr = std::shared_ptr<LensFit>;  // pybind11 holders are of non-const types; the fit is never changed

std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

// `array` as float32 of `ndim` dimensions (the last of size `channels` when ndim is 3).
void check_float32(const py::array& array, const char* name, int ndim, const char* expected) {
  if (!array.dtype().is(py::dtype::of<float>())) {
    throw py::type_error(std::string(name) + ": expected a float32 array of shape " + expected + ", got dtype " +
                         py::str(array.dtype()).cast<std::string>() + " (convert with .astype(numpy.float32))");
  }
  if (array.ndim() != ndim || (ndim == 3 && array.shape(2) != 3)) {
    throw py::value_error(std::string(name) + ": expected shape " + expected + ", got " + shape_text(array));
  }
}

// The options dict: typed reads, and at the end every key read, so that a misspelt one is an error.
class OptionReader {
 public:
  explicit OptionReader(py::dict options) : options_(std::move(options)) {}
  bool given(const char* key) const { return options_.contains(key) && !options_[key].is_none(); }
  template <typename T>
  std::optional<T> get(const char* key) {
    read_.insert(key);
    if (!given(key)) return std::nullopt;
    try {
      return options_[key].cast<T>();
    } catch (const py::cast_error&) {
      throw py::type_error(std::string(key) + ": cannot take " + py::str(py::type::of(options_[key])).cast<std::string>());
    }
  }
  template <typename T>
  T get(const char* key, T fallback) {
    return get<T>(key).value_or(fallback);
  }
  py::object object(const char* key) {
    read_.insert(key);
    return given(key) ? py::reinterpret_borrow<py::object>(options_[key]) : py::none();
  }
  void finish() const {
    for (const auto& item : options_) {
      const std::string key = py::str(item.first).cast<std::string>();
      if (!read_.count(key)) throw OptionsError("unknown option '" + key + "' (docs/python.md lists bokeh's options)");
    }
  }

 private:
  py::dict options_;
  std::set<std::string> read_;
};

Aperture make_aperture(OptionReader& r) {
  const py::object mask = r.object("aperture_mask");
  if (!mask.is_none()) {
    const py::array a = py::array::ensure(mask);
    if (!a || !a.dtype().is(py::dtype::of<float>()) || a.ndim() != 2) {
      throw py::type_error("aperture_mask: expected a float32 array (H, W) of transmission in [0, 1], top row = top");
    }
    const auto v = a.unchecked<float, 2>();
    std::vector<float> transmission(static_cast<std::size_t>(a.shape(0) * a.shape(1)));
    for (py::ssize_t y = 0; y < a.shape(0); ++y) {
      for (py::ssize_t x = 0; x < a.shape(1); ++x) transmission[static_cast<std::size_t>(y * a.shape(1) + x)] = v(y, x);
    }
    return Aperture::mask(static_cast<int>(a.shape(1)), static_cast<int>(a.shape(0)), std::move(transmission));
  }
  const std::optional<int> blades = r.get<int>("blades");
  const double rotation = r.get<double>("blade_rotation_deg", 0.0);
  if (blades) return Aperture::blades(*blades, rotation);
  return Aperture::circular();
}

// Options of one method only, as `lensmith bokeh` has them.
void reject_other_methods(const OptionReader& r, const std::string& method) {
  const std::vector<std::pair<const char*, std::vector<const char*>>> only = {
      {"scatter", {"hidden", "edge_pixels", "layer_spacing_px", "subrows", "max_blur_px"}},
      {"multiview", {"samples", "layers", "ray_grid_px", "cone_tracing"}},
      {"lightfield", {"views", "mip_filter"}},
      {"ewa", {"circular_splats", "level_of_detail"}},
      {"gather", {"rings", "median", "scene", "trace_rays"}},
  };
  for (const auto& [owner, keys] : only) {
    if (owner == method) continue;
    for (const char* key : keys) {
      // --hidden is scatter's extend/stretch and gather's trace.
      if (std::string(key) == "hidden" && method == "gather") continue;
      if (r.given(key)) throw UsageError(std::string(key) + " is an option of method='" + owner + "', not of method='" + method + "'");
    }
  }
}

py::array_t<float> render(const py::array& image, const py::array& depth, py::dict options_dict) {
  check_float32(image, "image", 3, "(H, W, 3)");
  check_float32(depth, "depth", 2, "(H, W)");
  if (depth.shape(0) != image.shape(0) || depth.shape(1) != image.shape(1)) {
    throw py::value_error("depth: shape " + shape_text(depth) + " but image is " + shape_text(image) + ": the depth map must have the picture's size");
  }
  const int height = static_cast<int>(image.shape(0)), width = static_cast<int>(image.shape(1));
  OptionReader r(std::move(options_dict));
  const std::string method = r.get<std::string>("method", "scatter");
  if (method != "scatter" && method != "multiview" && method != "lightfield" && method != "ewa" && method != "gather") {
    throw OptionsError("method = '" + method + "': must be scatter, multiview, lightfield, ewa or gather");
  }
  reject_other_methods(r, method);

  // The lens (a Lens, a path or a shipped name) or an ideal thin lens.
  const py::object lens_object = r.object("lens");
  const std::optional<double> thin_focal_mm = r.get<double>("thin_lens_focal_length_mm");
  std::optional<Prescription> lens;
  if (!lens_object.is_none() && thin_focal_mm) throw UsageError("give lens or thin_lens_focal_length_mm, not both");
  if (lens_object.is_none() && !thin_focal_mm) throw UsageError("give lens (a Lens, a file or a shipped lens name) or thin_lens_focal_length_mm");
  if (!lens_object.is_none()) {
    if (py::isinstance<py::str>(lens_object)) {
      lens = resolve_real_image_height_field(LensLibrary::load_path_or_name(lens_object.cast<std::string>()).prescription);
    } else {
      lens = lens_object.cast<const LensHandle&>().checked();
    }
  }
  const std::string model_name = r.get<std::string>("model", thin_focal_mm ? "thin" : "seidel");
  const RayModelKind kind = parse_ray_model_kind(model_name);

  CameraOptions camera;
  camera.f_number = r.get<double>("fstop");
  camera.framing.sensor_width_mm = r.get<double>("sensor_width_mm", 36.0);
  camera.framing.focal_length_mm = r.get<double>("pinhole_focal_length_mm");
  camera.framing.horizontal_fov_deg = r.get<double>("hfov_deg");
  const double default_focal_mm = thin_focal_mm ? *thin_focal_mm : ParaxialSystem(*lens).efl_mm();
  const PinholeFrame frame = PinholeFrame::from_options(width, height, camera.framing, default_focal_mm);

  DepthReadOptions depth_options;
  depth_options.kind = parse_depth_kind(r.get<std::string>("depth_kind", "z"));
  depth_options.unit = parse_depth_unit(r.get<std::string>("depth_unit", "m"));
  depth_options.invalid = parse_invalid_depth(r.get<std::string>("invalid_depth", "error"));
  std::vector<float> depth_values(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  Image picture(width, height, 3);
  {
    const auto d = depth.unchecked<float, 2>();
    const auto c = image.unchecked<float, 3>();
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
        depth_values[i] = d(y, x);
        for (int k = 0; k < 3; ++k) picture.data[3 * i + static_cast<std::size_t>(k)] = c(y, x, k);
      }
    }
  }
  const DepthMap depth_map = depth_map_from_values(depth_values, depth_options, frame, "depth array");

  const std::optional<double> focus_m = r.get<double>("focus_m");
  const std::optional<std::pair<int, int>> focus_pixel = r.get<std::pair<int, int>>("focus_pixel");
  if (focus_m && focus_pixel) throw UsageError("give focus_m or focus_pixel, not both");
  if (focus_pixel) {
    const auto [x, y] = *focus_pixel;
    if (x < 0 || y < 0 || x >= width || y >= height) {
      throw UsageError("focus_pixel (" + std::to_string(x) + ", " + std::to_string(y) + "): outside the " + std::to_string(width) + " x " +
                       std::to_string(height) + " image ((0, 0) = top left; x, y)");
    }
    camera.focus_distance_m = depth_map.at(x, y);
  } else if (focus_m) {
    camera.focus_distance_m = *focus_m;
  } else {
    throw UsageError("give focus_m (metres from the entrance pupil) or focus_pixel (x, y)");
  }
  const std::optional<Camera> cam = CameraSpec{thin_focal_mm, camera, width, height}.camera(kind, lens ? &*lens : nullptr);
  float nearest_m = std::numeric_limits<float>::infinity();
  for (float z : depth_map.z_m) nearest_m = std::min(nearest_m, z);
  RayModelOptions model_options;
  model_options.nearest_depth_m = std::isfinite(nearest_m) ? std::max(0.01, static_cast<double>(nearest_m)) : 1.0;
  model_options.seidel_coefficients = parse_seidel_coefficients(r.get<std::string>("seidel_coefficients", "fitted"));
  const py::object fit_object = r.object("fit");
  if (!fit_object.is_none()) {
    if (kind != RayModelKind::Poly) throw UsageError("fit is for model='poly'");
    std::shared_ptr<const LensFit> fit = py::isinstance<py::str>(fit_object) ? std::make_shared<const LensFit>(LensFit::read(fit_object.cast<std::string>()))
                                                                             : fit_object.cast<FitPtr>();
    fit->check_matches(*cam->lens());
    model_options.fit = std::move(fit);
  }
  if (kind == RayModelKind::Poly) require_poly_model_lens(*cam);
  if (kind == RayModelKind::Poly && !model_options.fit) {
    // A fit made for this render, as the command makes it: the camera's f-number and a sensor radius
    // covering its frame.
    py::gil_scoped_release release;
    model_options.fit = std::make_shared<const LensFit>(LensFit::fit(*cam->lens(), lens_fit_options_for(*cam)));
  }
  const Aperture aperture = make_aperture(r);
  const int threads = r.get<int>("threads", 0);
  const bool vignetting = r.get<bool>("vignetting", true);
  const bool spectral = r.get<bool>("spectral", true);
  const int spectral_samples = r.get<int>("spectral_samples", 16);

  // Every method's options are read (and so known) before any work starts.
  BokehOptions scatter;
  scatter.threads = threads;
  scatter.vignetting = vignetting;
  scatter.spectral = spectral;
  scatter.spectral_samples = spectral_samples;
  const std::string hidden = r.get<std::string>("hidden", method == "gather" ? "none" : "extend");
  if (method == "scatter") scatter.hidden = parse_hidden_surfaces(hidden);
  const std::string edge_pixels = r.get<std::string>("edge_pixels", "split");
  if (edge_pixels != "split" && edge_pixels != "keep") throw OptionsError("edge_pixels = '" + edge_pixels + "': must be 'split' or 'keep'");
  scatter.split_edge_pixels = edge_pixels == "split";
  scatter.layer_spacing_px = r.get<double>("layer_spacing_px", scatter.layer_spacing_px);
  scatter.splat.subrows = r.get<int>("subrows", scatter.splat.subrows);
  scatter.max_blur_px = r.get<double>("max_blur_px", scatter.max_blur_px);
  MultiviewOptions multiview;
  multiview.threads = threads;
  multiview.vignetting = vignetting;
  multiview.spectral = spectral;
  multiview.spectral_samples = spectral_samples;
  multiview.samples = r.get<int>("samples", multiview.samples);
  multiview.layers = r.get<int>("layers", multiview.layers);
  multiview.ray_grid_px = r.get<int>("ray_grid_px", multiview.ray_grid_px);
  multiview.cone_tracing = r.get<bool>("cone_tracing", multiview.cone_tracing);
  LightfieldOptions lightfield;
  lightfield.threads = threads;
  lightfield.vignetting = vignetting;
  lightfield.spectral = spectral;
  lightfield.views = r.get<int>("views", lightfield.views);
  lightfield.mip_filter = r.get<bool>("mip_filter", lightfield.mip_filter);
  EwaOptions ewa;
  ewa.threads = threads;
  ewa.vignetting = vignetting;
  ewa.lens_psf = !r.get<bool>("circular_splats", false);
  ewa.level_of_detail = r.get<bool>("level_of_detail", ewa.level_of_detail);
  GatherOptions gather;
  gather.threads = threads;
  gather.vignetting = vignetting;
  gather.rings = r.get<int>("rings", gather.rings);
  gather.median = r.get<bool>("median", gather.median);
  gather.trace_rays = r.get<int>("trace_rays", gather.trace_rays);
  const std::optional<std::string> scene_path = r.get<std::string>("scene");
  r.finish();
  if (method == "gather" && hidden != "none" && hidden != "trace") {
    throw OptionsError("hidden = '" + hidden + "': method='gather' takes hidden='trace' (with scene=FILE) or none");
  }
  if (method == "gather" && (hidden == "trace") != scene_path.has_value()) {
    throw UsageError("method='gather': hidden='trace' and scene=FILE go together (Tan et al.'s hybrid traces into the analytic scene)");
  }
  std::optional<Scene> scene;
  if (scene_path) scene = load_scene(*scene_path);

  Image out;
  {
    py::gil_scoped_release release;
    const auto model = make_ray_model(kind, *cam, model_options);
    if (method == "scatter") {
      out = render_bokeh(picture, depth_map, *model, aperture, scatter);
    } else if (method == "multiview") {
      out = render_multiview(deep_image_from_flat(picture, depth_map), *model, aperture, multiview).leading_channels(3);
    } else if (method == "lightfield") {
      out = render_lightfield(picture, depth_map, *model, aperture, lightfield);
    } else if (method == "ewa") {
      out = render_ewa(picture, depth_map, *model, aperture, ewa);
    } else {
      if (scene) {
        gather.trace = [&](std::vector<GatherTraceRequest>& requests) {
          LensRenderOptions rays;
          rays.threads = threads;
          rays.spectral = spectral;
          rays.spectral_samples = spectral_samples;
          trace_regions(*scene, *cam, requests, rays);
        };
      }
      out = render_gather(picture, depth_map, *model, aperture, gather);
    }
  }
  py::array_t<float> result({static_cast<py::ssize_t>(height), static_cast<py::ssize_t>(width), py::ssize_t{3}});
  std::copy_n(out.data.data(), static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3, result.mutable_data());
  return result;
}

py::array_t<float> to_array(const Image& image) {
  py::array_t<float> out({static_cast<py::ssize_t>(image.height), static_cast<py::ssize_t>(image.width), static_cast<py::ssize_t>(image.channels)});
  std::copy(image.data.begin(), image.data.end(), out.mutable_data());
  return out;
}

}  // namespace

void bind_render(py::module_& m) {
  m.def("bokeh", &render, py::arg("image"), py::arg("depth"), py::arg("options"));

  m.def("read_image", [](const std::string& path) {
    Image image;
    {
      py::gil_scoped_release release;
      image = read_radiance_image(path);
    }
    return to_array(image);
  }, py::arg("path"));

  m.def("read_depth", [](const std::string& path_and_channel) {
    const DepthSource source = DepthSource::parse(path_and_channel);
    const RasterInfo info = read_raster_info(source.file);
    // Planar Z as stored (metres); the frame only matters for other depth kinds.
    const PinholeFrame frame = PinholeFrame::from_options(info.width, info.height, {}, 50.0);
    DepthMap depth;
    {
      py::gil_scoped_release release;
      depth = read_depth(source, {}, frame);
    }
    py::array_t<float> out({static_cast<py::ssize_t>(depth.height), static_cast<py::ssize_t>(depth.width)});
    std::copy(depth.z_m.begin(), depth.z_m.end(), out.mutable_data());
    return out;
  }, py::arg("path"));

  m.def("read_metadata", [](const std::string& path) {
    py::dict out;
    for (const auto& [key, value] : read_image_metadata(path)) out[py::str(key)] = value;
    return out;
  }, py::arg("path"));

  m.def("write_image", [](const std::string& path, const py::array& rgb) {
    check_float32(rgb, "image", 3, "(H, W, 3)");
    const int height = static_cast<int>(rgb.shape(0)), width = static_cast<int>(rgb.shape(1));
    Image image(width, height, 3);
    const auto c = rgb.unchecked<float, 3>();
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        for (int k = 0; k < 3; ++k) image.data[(static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 3 + static_cast<std::size_t>(k)] = c(y, x, k);
      }
    }
    OutputMetadata meta;
    meta.lensmith_version = LENSMITH_VERSION;
    py::gil_scoped_release release;
    write_output_image(path, image, meta);
  }, py::arg("path"), py::arg("image"));

  m.def("convert_colorspace", [](const py::array& rgb, const std::string& from_space, const std::string& to_space, const std::string& config,
                                 const std::string& working_space) {
    check_float32(rgb, "image", 3, "(H, W, 3)");
    ColorManagementOptions o;
    o.config = config;
    o.input_colorspace = from_space;
    o.output_colorspace = to_space;
    o.working_colorspace = working_space;
    const ColorManagement color(o);
    py::array_t<float> out({rgb.shape(0), rgb.shape(1), static_cast<py::ssize_t>(3)});
    const auto c = rgb.unchecked<float, 3>();
    float* data = out.mutable_data();
    for (py::ssize_t y = 0; y < rgb.shape(0); ++y) {
      for (py::ssize_t x = 0; x < rgb.shape(1); ++x) {
        for (py::ssize_t k = 0; k < 3; ++k) *data++ = c(y, x, k);
      }
    }
    const std::span<float> pixels(out.mutable_data(), static_cast<std::size_t>(out.size()));
    py::gil_scoped_release release;
    color.input_to_working(pixels, 3);
    color.working_to_output(pixels, 3);
    return out;
  }, py::arg("image"), py::arg("from_space"), py::arg("to_space"), py::arg("config"), py::arg("working_space"));

  py::class_<LensFit, FitPtr>(m, "Fit", "A polynomial fit of a lens's ray mapping (lensmith fit).")
      .def_static("fit", [](const LensHandle& lens, int degree, int terms, int training_rays, int test_rays, std::uint64_t seed,
                            std::optional<double> image_radius_mm, std::optional<double> f_number) {
             LensFitOptions o;
             o.degree = degree;
             o.terms = terms;
             o.training_rays = training_rays;
             o.test_rays = test_rays;
             o.seed = seed;
             o.image_radius_mm = image_radius_mm;
             o.f_number = f_number;
             o.validate();
             const Prescription p = lens.checked();
             py::gil_scoped_release release;
             // As `lensmith fit`: a fit asked for by name reports its speed (a render's own fit does not).
             auto fit = std::make_shared<LensFit>(LensFit::fit(p, o));
             fit->measure_speed(p);
             return fit;
           }, py::arg("lens"), py::arg("degree") = 7, py::arg("terms") = 0, py::arg("training_rays") = 30000, py::arg("test_rays") = 10000,
           py::arg("seed") = 2016, py::arg("image_radius_mm") = py::none(), py::arg("f_number") = py::none())
      .def_static("load", [](const std::string& path) { return std::make_shared<LensFit>(LensFit::read(path)); }, py::arg("path"))
      .def("save", [](const LensFit& f, const std::string& path) { f.write(path); }, py::arg("path"))
      .def("report_json", [](const LensFit& f) { return dump(fit_json(f)); })
      .def("check_matches", [](const LensFit& f, const LensHandle& lens) { f.check_matches(lens.checked()); }, py::arg("lens"))
      .def_property_readonly("lens_name", &LensFit::lens_name)
      .def_property_readonly("lens_hash", &LensFit::lens_hash)
      .def_property_readonly("image_radius_mm", &LensFit::image_radius_mm)
      .def_property_readonly("symmetry", [](const LensFit& f) { return std::string(to_string(f.symmetry())); },
                             "'rotational' (the invariant form) or 'section mirrors' (an anamorphic lens, fitted in x and y components)")
      .def("__repr__", [](const LensFit& f) { return f.to_string(); });
}

}  // namespace lensmith::python
