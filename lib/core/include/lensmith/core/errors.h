// Typed exceptions thrown at lensmith's API boundary. Every error about user input names where
// (file:line:col, or the surface and field) and what was expected. Hot loops use status values.
#pragma once

#include <ostream>
#include <stdexcept>
#include <string>

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

// A lens file (native JSON, Zemax, pbrt, lentil) could not be read: the message is prefixed with
// the location and says what was expected.
class LensFileError : public Error {
 public:
  LensFileError(SourceLocation where, const std::string& what);
  const SourceLocation& where() const { return where_; }
  const std::string& what_without_location() const { return detail_; }

 private:
  SourceLocation where_;
  std::string detail_;
};

// A glass could not be found or evaluated (unknown name, bad formula, wavelength out of range).
class GlassError : public Error {
 public:
  using Error::Error;
};

// A prescription is not a valid optical system ("surface 3: semi_diameter_mm = -2: must be > 0").
class PrescriptionError : public Error {
 public:
  using Error::Error;
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
