// Bulk exact tracing from Python: numpy arrays in, the batch tracer (multi-threaded, no per-ray
// allocation) with the GIL released, numpy arrays out (docs/python.md, "Tracing rays").
#include <cstdint>
#include <string>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "lensmith/core/errors.h"
#include "lensmith/trace/sequential_tracer.h"

namespace lensmith::python {

namespace {

// `array` as (N, 3) float64, or a TypeError / ValueError that names the argument and what it got.
void check_rays(const py::array& array, const char* name) {
  if (!array.dtype().is(py::dtype::of<double>())) {
    throw py::type_error(std::string(name) + ": expected a float64 array of shape (N, 3), got dtype " +
                         py::str(array.dtype()).cast<std::string>() + " (convert with .astype(numpy.float64))");
  }
  if (array.ndim() != 2 || array.shape(1) != 3) {
    std::string shape = "(";
    for (py::ssize_t i = 0; i < array.ndim(); ++i) {
      // Appended piece by piece: GCC 12's LTO flags `const char* + std::string` here with a spurious
      // -Wstringop-overflow, which the warnings-as-errors build would turn into a failure.
      if (i > 0) shape += ", ";
      shape += std::to_string(array.shape(i));
    }
    throw py::value_error(std::string(name) + ": expected shape (N, 3), got " + shape + ")");
  }
}

}  // namespace

void bind_trace(py::module_& m) {
  m.def("ray_status_names", [] {
    std::vector<std::string> names;
    for (int s = 0; s <= static_cast<int>(RayStatus::InvalidInput); ++s) names.emplace_back(to_string(static_cast<RayStatus>(s)));
    return names;
  }, "The --json spelling of each ray status code (index = code).");

  m.def("trace", [](const LensHandle& lens, const py::array& origins, const py::array& directions, const py::object& wavelengths,
                    const std::string& direction, const std::string& image, std::optional<double> image_distance_mm, bool clip_apertures,
                    const py::object& out) {
    check_rays(origins, "origins_mm");
    check_rays(directions, "directions");
    const py::ssize_t n = origins.shape(0);
    if (directions.shape(0) != n) {
      throw py::value_error("directions: " + std::to_string(directions.shape(0)) + " rows, but origins_mm has " + std::to_string(n));
    }
    // One wavelength for every ray, or one per ray.
    double single_nm = 0.0;
    bool one_per_ray = false;
    py::array_t<double, py::array::c_style> per_ray;  // (a default array_t is an empty array, not None)
    if (py::isinstance<py::float_>(wavelengths) || py::isinstance<py::int_>(wavelengths)) {
      single_nm = wavelengths.cast<double>();
    } else {
      const py::array w = py::array::ensure(wavelengths);
      if (!w || !w.dtype().is(py::dtype::of<double>()) || w.ndim() != 1 || w.shape(0) != n) {
        throw py::type_error("wavelengths_nm: expected a number or a float64 array of shape (" + std::to_string(n) + ",)");
      }
      per_ray = py::array_t<double, py::array::c_style>::ensure(w);
      one_per_ray = true;
    }
    const TraceDirection way = direction == "forward"    ? TraceDirection::Forward
                               : direction == "backward" ? TraceDirection::Backward
                                                         : throw OptionsError("direction = '" + direction + "': must be 'forward' or 'backward'");
    TracerOptions options;
    if (image == "paraxial") {
      options.image_plane = TracerOptions::ImagePlane::ParaxialFocus;
    } else if (image != "prescribed") {
      throw OptionsError("image = '" + image + "': must be 'prescribed' or 'paraxial'");
    }
    options.image_distance_mm = image_distance_mm;
    options.clip_apertures = clip_apertures;
    const Prescription p = lens.checked();

    // The tracer reads the rows of the (C-contiguous) inputs and writes the outputs' rows directly:
    // no copy in or out.
    const auto in_o = py::array_t<double, py::array::c_style>::ensure(origins);
    const auto in_d = py::array_t<double, py::array::c_style>::ensure(directions);
    // New arrays, or the caller's from an earlier call (`out`): reusing them saves allocating and
    // first touching 50 MB per million rays, which is a sixth of the tracing time (docs/performance.md).
    py::array_t<double> positions, out_directions;
    py::array_t<std::uint8_t> status;
    py::array_t<std::int32_t> surface;
    if (out.is_none()) {
      positions = py::array_t<double>({n, py::ssize_t{3}});
      out_directions = py::array_t<double>({n, py::ssize_t{3}});
      status = py::array_t<std::uint8_t>(n);
      surface = py::array_t<std::int32_t>(n);
    } else {
      const auto tuple = out.cast<py::tuple>();
      const auto reusable = [n](const py::handle& h, const py::dtype& dtype, int ndim, const char* name) {
        const py::array a = py::reinterpret_borrow<py::array>(h);
        if (!py::isinstance<py::array>(h) || !a.dtype().is(dtype) || a.ndim() != ndim || a.shape(0) != n || (ndim == 2 && a.shape(1) != 3) ||
            !(a.flags() & py::array::c_style) || !a.writeable()) {
          throw py::value_error(std::string("out: its ") + name + " is not a writeable C-contiguous array for " + std::to_string(n) +
                                " rays of the dtype trace() returns (pass the result of a trace of as many rays)");
        }
        return a;
      };
      positions = reusable(tuple[0], py::dtype::of<double>(), 2, "positions_mm");
      out_directions = reusable(tuple[1], py::dtype::of<double>(), 2, "directions");
      status = reusable(tuple[2], py::dtype::of<std::uint8_t>(), 1, "status");
      surface = reusable(tuple[3], py::dtype::of<std::int32_t>(), 1, "surface");
    }
    static_assert(sizeof(RayStatus) == sizeof(std::uint8_t) && sizeof(int) == sizeof(std::int32_t));
    RayBatchView view;
    view.count = static_cast<std::size_t>(n);
    view.x_mm = in_o.data();
    view.y_mm = view.x_mm + 1;
    view.z_mm = view.x_mm + 2;
    view.l = in_d.data();
    view.m = view.l + 1;
    view.n = view.l + 2;
    view.stride = 3;
    view.wavelength_nm = one_per_ray ? per_ray.data() : &single_nm;
    view.wavelength_stride = one_per_ray ? 1 : 0;
    view.x_out_mm = positions.mutable_data();
    view.y_out_mm = view.x_out_mm + 1;
    view.z_out_mm = view.x_out_mm + 2;
    view.l_out = out_directions.mutable_data();
    view.m_out = view.l_out + 1;
    view.n_out = view.l_out + 2;
    view.out_stride = 3;
    view.status = reinterpret_cast<RayStatus*>(status.mutable_data());
    view.surface = surface.mutable_data();
    {
      py::gil_scoped_release release;
      SequentialTracer(p, options).trace_batch(view, way);
    }
    return py::make_tuple(positions, out_directions, status, surface);
  }, py::arg("lens"), py::arg("origins_mm"), py::arg("directions"), py::arg("wavelengths_nm"), py::arg("direction") = "forward",
     py::arg("image") = "prescribed", py::arg("image_distance_mm") = py::none(), py::arg("clip_apertures") = true,
     py::arg("out") = py::none());
}

}  // namespace lensmith::python
