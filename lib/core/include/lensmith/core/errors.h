// Typed exceptions thrown at lensmith's API boundary. Every error about user input names where
// (file:line:col, or the surface and field) and what was expected. Hot loops use status values.
#pragma once

#include <ostream>
#include <stdexcept>
#include <string>
#include <utility>

namespace lensmith {

// A place in a user's text file. line and column count from 1; 0 means "unknown".
struct SourceLocation {
  std::string file;
  int line = 0;
  int column = 0;

  // "file:line:col", "file:line" or "file" depending on what is known.
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const SourceLocation& loc) {
    return os << loc.to_string();
  }
};

// Base of all lensmith errors.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

// What an error inside a model is about, so that a reader can point at the line that set it without
// parsing the message: a surface (1-based; 0: none), a field ("semi_diameter_mm", "wavelengths_nm",
// "aperture", "field.vignetting", "object", "primary", a scene object's key) and, for a list, the
// entry's index (-1: none).
struct ErrorSubject {
  int surface = 0;
  std::string field;
  int index = -1;

  bool empty() const { return surface == 0 && field.empty(); }
  // The field's first dotted part: "aperture" for "aperture.f_number".
  std::string field_root() const { return field.substr(0, field.find_first_of(".[")); }
  // "surface 3, semi_diameter_mm", "wavelengths_nm[2]", "aperture", "(none)".
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const ErrorSubject& s) { return os << s.to_string(); }
};

// A user's file (a lens in any format, a glass catalogue, a fit, a scene) could not be read: the
// message is prefixed with the location and says what was expected. One type for every file the
// readers take, so callers and the Python module handle them alike.
class FileError : public Error {
 public:
  FileError(SourceLocation where, const std::string& what);
  const SourceLocation& where() const { return where_; }
  const std::string& what_without_location() const { return detail_; }

 private:
  SourceLocation where_;
  std::string detail_;
};

// An error about one part of a model (a surface, a field), carrying that part as its subject.
class SubjectError : public Error {
 public:
  explicit SubjectError(const std::string& message) : Error(message) {}
  SubjectError(ErrorSubject subject, const std::string& message) : Error(message), subject_(std::move(subject)) {}
  const ErrorSubject& subject() const { return subject_; }

 private:
  ErrorSubject subject_;
};

// A glass could not be found or evaluated (unknown name, bad formula, wavelength out of range).
class GlassError : public SubjectError {
 public:
  using SubjectError::SubjectError;
};

// A prescription is not a valid optical system ("surface 3: semi_diameter_mm = -2: must be > 0").
class PrescriptionError : public SubjectError {
 public:
  using SubjectError::SubjectError;
};

// An options struct failed its own validation ("FitOptions::degree = 0: must be >= 1").
class OptionsError : public Error {
 public:
  using Error::Error;
};

// A request that contradicts itself or lacks a part it needs (an output naming one of the inputs;
// an option the call requires): the command line's fault, exit 2 in the CLI.
class UsageError : public OptionsError {
 public:
  using OptionsError::OptionsError;
};

// A computation has no answer for this input (e.g. an afocal system has no focal points).
class ComputationError : public Error {
 public:
  using Error::Error;
};

// Reading or writing a file failed at the operating-system level.
class IoError : public Error {
 public:
  using Error::Error;
};

}  // namespace lensmith
