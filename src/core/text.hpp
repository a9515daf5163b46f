#pragma once
// Text for the terminal: messages carry file names and file contents, which may hold control
// characters or bytes that are not UTF-8.
#include <string>

namespace lucent::io {

/// `s` as one printable line: control characters shown as \n, \r, \t or \xNN, bytes that are not
/// UTF-8 as \xNN; valid UTF-8 is kept. Errors, warnings and summary lines go through it, so that
/// a file name with a newline cannot break the one-line contract or drive the terminal.
std::string one_line(const std::string& s);

}  // namespace lucent::io
