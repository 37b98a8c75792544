// The pieces of the `lensmith._lensmith` extension (docs/python.md), one file per part of the
// library it exposes. The extension returns JSON text where the command line's --json has a schema
// (lensmith/report/json_report.h), and the pure-Python package turns it into records and arrays.
#pragma once

#include <memory>
#include <string>

#include <pybind11/pybind11.h>

#include "lensmith/prescription/prescription.h"
#include "lensmith/report/json_report.h"

namespace lensmith::plot {
class Canvas;
}  // namespace lensmith::plot

namespace lensmith::python {

namespace py = pybind11;

// A lens as Python holds it: the prescription a script reads and changes. Surfaces are views into
// it (SurfaceView), so that `lens.surfaces[2].radius_mm = 40` changes the lens itself.
struct LensHandle {
  Prescription prescription;
  std::string origin;  // the path or shipped name it came from ("" when built in Python)
  // The prescription with its materials resolved and validated: what every analysis takes.
  // Throws PrescriptionError / GlassError naming the surface.
  Prescription checked() const;
};
using LensPtr = std::shared_ptr<LensHandle>;

// Writes a picture of the plot library where the command writes it; never over the lens's own file.
void write_picture(const plot::Canvas& canvas, const std::string& png, const LensHandle& lens);
// The command's rule (ensure_not_an_input): UsageError when `output` is the file the lens was read from.
void ensure_not_the_lens_file(const std::string& output, const LensHandle& lens);

// JSON text of a report (compact; Python's json module reads it).
std::string dump(const ojson& o);

void bind_lens(py::module_& m);
void bind_analysis(py::module_& m);
void bind_trace(py::module_& m);
void bind_render(py::module_& m);

}  // namespace lensmith::python
