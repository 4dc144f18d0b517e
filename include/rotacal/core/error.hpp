// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Typed exceptions. Bad input throws one of these with a message that names what was wrong
/// (file, line, column, parameter); numerical outcomes (not converged, unobservable) are data
/// in result structs, never exceptions.

#include <stdexcept>
#include <string>

namespace rotacal {

/// Base of every exception the library throws on purpose.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A function argument is out of its domain (names the parameter).
class InvalidArgument : public Error {
 public:
  using Error::Error;
};

/// Geometry too poor to fit (too few points, collinear/coplanar points, arc too short).
class DegenerateGeometry : public Error {
 public:
  using Error::Error;
};

/// A file breaks its format; carries file, line (1-based, 0 = whole file) and column (0 = none).
class ParseError : public Error {
 public:
  ParseError(std::string file, int line, int column, const std::string& what)
      : Error(format(file, line, column, what)),
        file_(std::move(file)),
        line_(line),
        column_(column) {}
  const std::string& file() const { return file_; }
  int line() const { return line_; }
  int column() const { return column_; }

 private:
  static std::string format(const std::string& file, int line, int column,
                            const std::string& what) {
    std::string s = file;
    if (line > 0) s += ":" + std::to_string(line);
    if (column > 0) s += ":" + std::to_string(column);
    return s + ": " + what;
  }
  std::string file_;
  int line_;
  int column_;
};

/// I/O failure outside the file's content (cannot open, cannot write, device gone).
class IoError : public Error {
 public:
  using Error::Error;
};

}  // namespace rotacal

/// Internal invariant check: a failure is a bug in rotacal, not bad input.
#define ROTACAL_ASSERT(cond)                                                                     \
  do {                                                                                           \
    if (!(cond))                                                                                 \
      throw ::rotacal::Error(std::string("internal error: ") + #cond + " at " + __FILE__ + ":" + \
                             std::to_string(__LINE__));                                          \
  } while (0)
