#pragma once
// Text for the terminal: messages carry file names and file contents, which may hold control
// characters or bytes that are not UTF-8.
#include <locale.h>

#include <string>

namespace lucent::io {

/// `s` as one printable line: control characters shown as \n, \r, \t or \xNN, bytes that are not
/// UTF-8 as \xNN; valid UTF-8 is kept. Errors, warnings and summary lines go through it, so that
/// a file name with a newline cannot break the one-line contract or drive the terminal.
std::string one_line(const std::string& s);

/// While alive, this thread formats and parses numbers (printf, strtod) in the "C" locale,
/// whatever setlocale() chose for the process: a Python program that called
/// locale.setlocale(locale.LC_ALL, "") on a German system wrote "0,5" into CSV files and SVG
/// coordinates, and refused the setting "clamp=0.5". File formats and option values are not
/// the user's language. (uselocale: the other threads keep theirs.)
class CNumbers {
 public:
  CNumbers();
  ~CNumbers();
  CNumbers(const CNumbers&) = delete;
  CNumbers& operator=(const CNumbers&) = delete;

 private:
  locale_t previous_ = nullptr;
};

}  // namespace lucent::io
