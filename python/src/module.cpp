// The extension module `lensmith._lensmith`: lensmith's typed errors as Python exceptions, and the
// bindings of each part of the library (docs/python.md).
#include <pybind11/pybind11.h>

#include "bindings.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/json_text.h"
#include "lensmith/imageio/raster.h"
#include "lensmith/polyfit/polynomial.h"
#include "lensmith/scene/scene_error.h"

namespace lensmith::python {

std::string dump(const ojson& o) { return json_text(o); }

namespace {

// Raises `type` with the message, and, for errors about a place in a file, the attributes
// `file`, `line` and `column` (0 when unknown) and `detail` (the message without the place); for
// errors about a part of a model, `surface` (1-based, 0: none), `field` and `index` (-1: none).
void raise(PyObject* type, const char* message, const SourceLocation* where = nullptr, const std::string* detail = nullptr,
           const ErrorSubject* subject = nullptr) {
  py::object exception = py::reinterpret_borrow<py::object>(type)(message);
  if (where) {
    exception.attr("file") = where->file;
    exception.attr("line") = where->line;
    exception.attr("column") = where->column;
    exception.attr("detail") = *detail;
  }
  if (subject) {
    exception.attr("surface") = subject->surface;
    exception.attr("field") = subject->field;
    exception.attr("index") = subject->index;
  }
  PyErr_SetObject(type, exception.ptr());
}

}  // namespace

}  // namespace lensmith::python

PYBIND11_MODULE(_lensmith, m) {
  namespace py = pybind11;
  using namespace lensmith;
  using namespace lensmith::python;
  m.doc() = "lensmith's C++ libraries (docs/python.md); use the `lensmith` package, which wraps this module.";
  m.attr("__version__") = LENSMITH_VERSION;

  // The hierarchy of errors.h: every lensmith error is a lensmith.Error; those about the caller's
  // values are also ValueError, those of the operating system also OSError.
  static py::exception<Error> error(m, "Error", PyExc_RuntimeError);
  // One class for every unreadable file; LensFileError and SceneFileError, its earlier names, stay.
  static py::exception<FileError> file_error(m, "FileError", error.ptr());
  m.attr("LensFileError") = file_error;
  m.attr("SceneFileError") = file_error;
  static py::exception<GlassError> glass_error(m, "GlassError", error.ptr());
  static py::exception<PrescriptionError> prescription_error(m, "PrescriptionError", error.ptr());
  static py::object options_error_type = py::reinterpret_steal<py::object>(
      PyErr_NewException("_lensmith.OptionsError", py::make_tuple(error, py::handle(PyExc_ValueError)).ptr(), nullptr));
  m.attr("OptionsError") = options_error_type;
  static py::object usage_error_type =
      py::reinterpret_steal<py::object>(PyErr_NewException("_lensmith.UsageError", options_error_type.ptr(), nullptr));
  m.attr("UsageError") = usage_error_type;
  static py::exception<ComputationError> computation_error(m, "ComputationError", error.ptr());
  static py::object io_error_type = py::reinterpret_steal<py::object>(
      PyErr_NewException("_lensmith.IoError", py::make_tuple(error, py::handle(PyExc_OSError)).ptr(), nullptr));
  m.attr("IoError") = io_error_type;
  static py::exception<ImageFileError> image_file_error(m, "ImageFileError", error.ptr());
  static py::exception<FitError> fit_error(m, "FitError", error.ptr());
  static py::exception<SceneError> scene_error(m, "SceneError", error.ptr());
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const FileError& e) {
      raise(file_error.ptr(), e.what(), &e.where(), &e.what_without_location());
    } catch (const GlassError& e) {
      raise(glass_error.ptr(), e.what(), nullptr, nullptr, &e.subject());
    } catch (const PrescriptionError& e) {
      raise(prescription_error.ptr(), e.what(), nullptr, nullptr, &e.subject());
    } catch (const UsageError& e) {
      raise(usage_error_type.ptr(), e.what());
    } catch (const OptionsError& e) {
      raise(options_error_type.ptr(), e.what());
    } catch (const ComputationError& e) {
      raise(computation_error.ptr(), e.what());
    } catch (const IoError& e) {
      raise(io_error_type.ptr(), e.what());
    } catch (const ImageFileError& e) {
      raise(image_file_error.ptr(), e.what());
    } catch (const FitError& e) {
      raise(fit_error.ptr(), e.what());
    } catch (const SceneError& e) {
      raise(scene_error.ptr(), e.what(), nullptr, nullptr, &e.subject());
    } catch (const Error& e) {
      raise(error.ptr(), e.what());
    }
  });

  bind_lens(m);
  bind_analysis(m);
  bind_trace(m);
  bind_render(m);
}
