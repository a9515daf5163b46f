#include "core/text.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

namespace lucent::io {

std::string one_line(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size();) {
    unsigned char c = static_cast<unsigned char>(s[i]);
    int n = c < 0x80 ? 1 : (c >> 5) == 6 ? 2 : (c >> 4) == 14 ? 3 : (c >> 3) == 30 ? 4 : 0;
    bool ok = n > 0 && i + n <= s.size() && !(n == 2 && c < 0xC2);
    for (int k = 1; ok && k < n; ++k) ok = (static_cast<unsigned char>(s[i + k]) >> 6) == 2;
    if (ok && n > 1) {
      unsigned char d = static_cast<unsigned char>(s[i + 1]);
      // Overlong forms, UTF-16 surrogates, code points above U+10FFFF and the C1 controls
      // (U+0080..U+009F: 0x9B starts a terminal control sequence) are escaped byte by byte.
      ok = !(c == 0xE0 && d < 0xA0) && !(c == 0xED && d >= 0xA0) && !(c == 0xF0 && d < 0x90) &&
           !(c == 0xF4 && d >= 0x90) && c <= 0xF4 && !(c == 0xC2 && d < 0xA0);
    }
    if (ok && n == 1 && (c < 0x20 || c == 0x7F)) {
      char buf[8];
      const char* named = c == '\n' ? "\\n" : c == '\r' ? "\\r" : c == '\t' ? "\\t" : nullptr;
      if (!named) std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += named ? named : buf;
      ++i;
    } else if (ok) {
      out.append(s, i, static_cast<size_t>(n));
      i += static_cast<size_t>(n);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
      ++i;
    }
  }
  return out;
}

CNumbers::CNumbers() {
  static const locale_t c = ::newlocale(LC_ALL_MASK, "C", static_cast<locale_t>(nullptr));
  if (c) previous_ = ::uselocale(c);
}

CNumbers::~CNumbers() {
  if (previous_) ::uselocale(previous_);
}

bool plain_decimal_integer(const std::string& text) {
  const size_t start = !text.empty() && text[0] == '-' ? 1 : 0;
  if (text.size() == start || text.find_first_not_of("0123456789", start) != std::string::npos)
    return false;
  return text[start] != '0' || text.size() == start + 1;
}

bool plain_decimal_real(const std::string& text) {
  const auto digit = [&](size_t i) { return i < text.size() && text[i] >= '0' && text[i] <= '9'; };
  size_t i = 0, digits = 0;
  if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
  for (; digit(i); ++i) ++digits;
  if (i < text.size() && text[i] == '.')
    for (++i; digit(i); ++i) ++digits;
  if (digits == 0) return false;
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
    if (!digit(i)) return false;
    while (digit(i)) ++i;
  }
  return i == text.size();
}

std::string shortest_real(double v, int min_digits) {
  char text[64];
  for (int digits = std::min(min_digits, 17); digits <= 17; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, v);
    if (std::strtod(text, nullptr) == v) break;
  }
  return text;
}

}  // namespace lucent::io
