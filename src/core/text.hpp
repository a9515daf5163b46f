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

/// Whether `text` is an integer in plain decimal: an optional '-', then 0 or digits that do not
/// start with 0. Option values and settings are read so (strtol and CLI11 took leading spaces, a
/// '+', and CLI11 read a leading zero as octal: `--spp 010` rendered 8 samples per pixel).
bool plain_decimal_integer(const std::string& text);

/// Whether `text` is a real in plain decimal: an optional sign, digits with at most one '.' (at
/// least one digit), then an optional exponent (e or E, an optional sign, digits). strtod also
/// takes hex floats (`--time 0x10` ran 16 s), leading spaces, "inf" and "nan".
bool plain_decimal_real(const std::string& text);

/// `v` in the fewest significant digits (`min_digits`, 15 by default, to 17, "%g") that read
/// back as `v`: "2.2", where "%.17g" wrote "2.2000000000000002" into a part file's header. Call
/// it in the "C" locale (CNumbers).
std::string shortest_real(double v, int min_digits = 15);

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
