// The text of OBJ and MTL files, checked before tinyobjloader parses it. tinyobjloader reads a
// coordinate that is not a number ("v 1 abc 0", "v nan 0 0") as 0 without a word, lets 1e39
// overflow to infinity in its floats, and reports out-of-range indices only as a warning at the
// last line: every number and index is checked here, and the first bad one named with its line.
#include <algorithm>
#include <cctype>
#include <cfloat>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <glm/glm.hpp>
#include <map>
#include <set>
#include <sstream>
#include <string_view>
#include <tuple>
#include <utility>

#include "core/text.hpp"
#include "lucent/error.hpp"
#include "scene/obj_internal.hpp"

namespace lucent::scene_detail::obj {

namespace fs = std::filesystem;

namespace {

bool space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// Splits `text` into lines as tinyobjloader does ("\n", "\r\n" or a lone "\r" ends one) and
// calls f(line, number) for each.
template <typename F>
void for_each_line(const std::string& text, F&& f) {
  std::size_t start = 0;
  long number = 1;
  while (start < text.size()) {
    std::size_t end = text.find_first_of("\r\n", start);
    if (end == std::string::npos) end = text.size();
    f(std::string_view(text.data() + start, end - start), number++);
    if (end < text.size() && text[end] == '\r' && end + 1 < text.size() && text[end + 1] == '\n')
      ++end;
    start = end + 1;
  }
}

// The next whitespace-separated token of `rest`, '#' included: tinyobjloader treats '#' as a
// comment only at the start of a line, and parses the numbers after a '#' further on ("vw 0 0 #
// 1e39" converts 1e39 to int, found by fuzz_obj), so its number checks see every token.
std::string_view raw_token(std::string_view& rest) {
  std::size_t i = 0;
  while (i < rest.size() && space(rest[i])) ++i;
  std::size_t j = i;
  while (j < rest.size() && !space(rest[j])) ++j;
  std::string_view t = rest.substr(i, j - i);
  rest.remove_prefix(j);
  return t;
}

// The next whitespace-separated token of `rest` (empty at the end of the line or at a comment).
std::string_view token(std::string_view& rest) {
  std::string_view t = raw_token(rest);
  if (!t.empty() && t[0] == '#') {
    rest = {};
    return {};
  }
  return t;
}

std::string str(std::string_view s) {
  std::string out(s.substr(0, 40));
  if (s.size() > 40) out += "...";
  return out;
}

class LineError {
 public:
  LineError(const std::string& path, long line) : path_(path), line_(line) {}
  [[noreturn]] void operator()(const std::string& what) const {
    throw Error(path_ + ":" + std::to_string(line_) + ": " + what);
  }

 private:
  const std::string& path_;
  long line_;
};

// A token split as tinyobjloader's number parser (tryParseDouble) reads it: [sign] digits [.
// digits] [e|E [sign] digits]. Leading zeros are not counted.
struct NumberParts {
  std::size_t integer_digits = 0;  // before the point
  bool exponent_negative = false;
  std::size_t exponent_digits = 0;  // 0 without an exponent
  long exponent = 0;                // its magnitude, capped at 10^9
};

NumberParts number_parts(std::string_view tok) {
  NumberParts n;
  auto digit = [&](std::size_t i) {
    return i < tok.size() && std::isdigit(static_cast<unsigned char>(tok[i]));
  };
  std::size_t i = 0;
  if (i < tok.size() && (tok[i] == '+' || tok[i] == '-')) ++i;
  while (i < tok.size() && tok[i] == '0') ++i;
  for (; digit(i); ++i) ++n.integer_digits;
  while (digit(i) || (i < tok.size() && tok[i] == '.')) ++i;
  if (i == 0 || i >= tok.size() || (tok[i] != 'e' && tok[i] != 'E')) return n;
  ++i;
  n.exponent_negative = i < tok.size() && tok[i] == '-';
  if (i < tok.size() && (tok[i] == '+' || tok[i] == '-')) ++i;
  while (i < tok.size() && tok[i] == '0') ++i;
  for (; digit(i); ++i, ++n.exponent_digits)
    n.exponent = std::min(10 * n.exponent + (tok[i] - '0'), 1000000000L);
  return n;
}

// tinyobjloader's number parser reads a decimal exponent into an int and guards against overflow
// one digit too late: "1e-2147483648" is undefined behaviour (found by fuzz_obj). It runs on every
// number of v, vt, vn, vw and t lines and of MTL files (texture options too), so every token of
// those lines that reads as a number with an exponent of ten or more significant digits is refused
// (no float has such an exponent).
void check_exponent(std::string_view tok, const NumberParts& n, const LineError& fail) {
  if (n.exponent_digits >= 10) fail("'" + str(tok) + "': the exponent is out of range");
}
void check_exponent(std::string_view tok, const LineError& fail) {
  check_exponent(tok, number_parts(tok), fail);
}

// tinyobjloader computes a number as (its digits, accumulated in a double) x 5^e x 2^e. Where the
// true value is a finite float, that arithmetic still gives NaN or infinity in two cases, which
// fuzz_obj found ("vt 0 0e761": 0 x 5^761 = 0 x inf, read as NaN):
// - a decimal exponent e above 441, where 5^e overflows, so a mantissa of 0 gives NaN; and the
//   mantissa is also 0 when its digits lie more than ~323 places behind the point (each digit's
//   10^-k underflows): "0.<430 zeros>1e432" is 10, read as NaN, and with an exponent below 441
//   it is read as 0;
// - more than 308 significant digits before the point, where the mantissa overflows, so that a
//   negative exponent gives infinity or NaN.
// Such numbers are refused: exponents above 300 and over 308 digits before the point. Neither
// occurs in a real file. What remains read as 0 is below 1e-23 (digits beyond 323 places behind
// the point, times at most 10^300). Negative exponents of any size (up to the nine digits
// check_exponent leaves) underflow to 0, as tinyobjloader reads them too.
void check_tinyobj_arithmetic(std::string_view tok, const NumberParts& n, const LineError& fail,
                              const char* what) {
  if (n.integer_digits > 308)
    fail(std::string(what) + " line: '" + str(tok) +
         "' has more than 308 digits before the point (tinyobjloader cannot read it)");
  if (!n.exponent_negative && n.exponent > 300)
    fail(std::string(what) + " line: '" + str(tok) +
         "' has an exponent above 300 (tinyobjloader cannot read it)");
}

// A number as tinyobjloader stores it (a float): finite and within float range, and read by
// tinyobjloader as the value it is. Underflow to 0 is fine.
double number(std::string_view tok, const LineError& fail, const char* what) {
  const NumberParts parts = number_parts(tok);
  check_exponent(tok, parts, fail);
  std::string_view t = tok;
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  double v = 0;
  auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (ec == std::errc::result_out_of_range && ptr == t.data() + t.size()) {
    {
      io::CNumbers c_numbers;
      v = std::strtod(std::string(t).c_str(), nullptr);  // tells overflow from underflow
    }
    if (std::abs(v) <= 1.0) {
      check_tinyobj_arithmetic(tok, parts, fail, what);
      return 0.0;
    }
    fail(std::string(what) + " line: '" + str(tok) + "' is out of range");
  }
  if (ec != std::errc() || ptr != t.data() + t.size())
    fail(std::string(what) + " line: '" + str(tok) + "' is not a number");
  if (!std::isfinite(v))
    fail(std::string(what) + " line: '" + str(tok) + "' is not a finite number");
  if (std::abs(v) > FLT_MAX)
    fail(std::string(what) + " line: '" + str(tok) + "' is out of range for a float");
  check_tinyobj_arithmetic(tok, parts, fail, what);
  return v;
}

const char* const kKinds[3] = {"vertex", "texture coordinate", "normal"};

// The first character of usemtl_alias's names: a control character, in no exporter's names.
constexpr char kAliasMark = '\x1f';

}  // namespace

std::string trim(const std::string& s) {
  const std::size_t b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

std::string usemtl_alias(std::size_t k) { return kAliasMark + std::to_string(k); }

std::string alias_usemtl(const std::string& text, const std::vector<std::string>& names) {
  std::map<std::string, std::size_t> index;
  for (std::size_t k = 0; k < names.size(); ++k) index.emplace(names[k], k);
  std::string out;
  out.reserve(text.size());
  std::size_t copied = 0;  // text before this offset is in `out`
  for_each_line(text, [&](std::string_view line, long) {
    const std::size_t b = std::min(line.find_first_not_of(" \t"), line.size());
    if (line.substr(b, 6) != "usemtl") return;
    auto it = index.find(trim(std::string(line.substr(b + 6))));
    if (it == index.end()) return;
    const std::size_t at = static_cast<std::size_t>(line.data() - text.data());
    out.append(text, copied, at - copied);
    out += "usemtl " + usemtl_alias(it->second);
    copied = at + line.size();
  });
  out.append(text, copied, std::string::npos);
  return out;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    size_t b = line.find_first_not_of(" \t\r."), e = line.find_last_not_of(" \t\r");
    if (b == std::string::npos) continue;  // tinyobjloader's stray "." lines
    out.push_back(line.substr(b, e - b + 1));
  }
  return out;
}

namespace {

/// Whether the library `name` of the OBJ file `obj_path` exists (named_file).
bool library_exists(const std::string& obj_path, const std::string& name) {
  std::error_code ec;
  return fs::is_regular_file(named_file(fs::path(obj_path).parent_path(), name), ec);
}

/// The OBJ format's statements (Wavefront's specification, and tinyobjloader's t and vw).
bool obj_statement(std::string_view tag) {
  static const char* const kStatements[] = {
      "v",         "vt",    "vn",    "vp",     "f",        "l",        "p",      "g",
      "o",         "s",     "mg",    "usemtl", "mtllib",   "cstype",   "deg",    "bmat",
      "step",      "curv",  "curv2", "surf",   "parm",     "trim",     "hole",   "scrv",
      "sp",        "end",   "con",   "bevel",  "c_interp", "d_interp", "lod",    "shadow_obj",
      "trace_obj", "ctech", "stech", "call",   "csh",      "maplib",   "usemap", "t",
      "vw",        "bsp",   "bzp",   "cdc",    "cdp",      "res"};  // (the last five: the format's
                                                                    // older ones)
  return std::any_of(std::begin(kStatements), std::end(kStatements),
                     [&](const char* s) { return tag == s; });
}

}  // namespace

std::filesystem::path named_file(const std::filesystem::path& dir, const std::string& name) {
  fs::path p(name);
  if (!p.is_absolute()) p = dir / p;
  std::error_code ec;  // names too long for the file system: no such file, no exception
  if (!fs::exists(p, ec) && name.find('\\') != std::string::npos) {  // Windows' separators
    std::string fixed = name;
    std::replace(fixed.begin(), fixed.end(), '\\', '/');
    return named_file(dir, fixed);
  }
  return p;
}

TextCounts check_obj_text(const std::string& path, const std::string& text) {
  std::int64_t count[3] = {0, 0, 0};  // v, vt, vn defined so far
  // the largest positive index of each kind and its line: checked against the final counts
  std::int64_t wanted[3] = {0, 0, 0};
  long wanted_line[3] = {0, 0, 0};
  TextCounts out;
  bool mtllib_seen = false;
  std::set<std::string> libraries, usemtl_names;
  // the text not yet given back (the lines from here on, the window being read and a page) and
  // the arrays of the lines before: the most of it is TextCounts::reading_bytes
  auto reading = [&](std::uint64_t left) {
    const std::uint64_t held =
        kTextGivenBack ? std::min<std::uint64_t>(left + 2 * kTextWindow, text.size()) : text.size();
    const std::uint64_t bytes =
        held + tinyobj_bytes(count[0], count[2], count[1], out.elements, out.corners);
    out.reading_bytes = std::max(out.reading_bytes, bytes);
  };
  for_each_line(text, [&](std::string_view rest, long ln) {
    reading(std::uint64_t(text.size() - std::size_t(rest.data() - text.data())));
    const LineError fail(path, ln);
    // usemtl and mtllib as tinyobjloader tells them: "usemtl" starts the line, "mtllib" and a
    // space or tab start it
    const std::string_view line = rest.substr(std::min(rest.find_first_not_of(" \t"), rest.size()));
    if (line.substr(0, 6) == "usemtl") {
      if (!mtllib_seen) out.usemtl_before_mtllib = true;
      // the name is the rest of the line, as newmtl's; tinyobjloader reads the first word
      const std::string name = trim(std::string(line.substr(6)));
      const std::string word = name.substr(0, name.find_first_of(" \t"));
      if ((name != word || (!word.empty() && word[0] == kAliasMark)) &&
          usemtl_names.insert(name).second)
        out.usemtl_names.push_back(name);
      return;
    }
    if (line.size() > 6 && line.substr(0, 6) == "mtllib" && (line[6] == ' ' || line[6] == '\t')) {
      mtllib_seen = true;
      // names split at spaces and tabs ("a.mtl\t" named 'a.mtl\t'); "\ " escapes a space, and
      // a backslash before anything else stays (a Windows path, "sub\s.mtl", was "subs.mtl")
      std::vector<std::string> names(1);
      for (std::size_t i = 7; i < line.size(); ++i) {
        const char c = line[i];
        if (c == '\\' && i + 1 < line.size() &&
            (line[i + 1] == ' ' || line[i + 1] == '\t' || line[i + 1] == '\\')) {
          names.back() += line[++i];
        } else if (c != ' ' && c != '\t') {
          names.back() += c;
        } else if (!names.back().empty()) {
          names.emplace_back();
        }
      }
      if (names.back().empty()) names.pop_back();
      for (std::size_t k = 0; k < names.size(); ++k)
        if (names[k][0] == '#') names.resize(k);
      // "mtllib my lib.mtl" unescaped, where "my lib.mtl" exists and a name split from it does
      // not: the whole rest of the line, as Blender's importer reads it
      const std::string whole = trim(std::string(line.substr(7)));
      if (names.size() > 1 &&
          !std::all_of(names.begin(), names.end(),
                       [&](const std::string& n) { return library_exists(path, n); }) &&
          library_exists(path, whole))
        names = {whole};
      for (const std::string& n : names)
        if (libraries.insert(n).second) out.libraries.push_back(n);
      return;
    }
    std::string_view tag = token(rest);
    if (tag.empty()) return;
    // the statements of numbers and indices (the token after them was refused as "'\' is not
    // a number"); a name ending with one (g, o, usemtl) is read as it is
    const bool data = tag == "v" || tag == "vt" || tag == "vn" || tag == "vp" || tag == "f" ||
                      tag == "l" || tag == "p";
    if (const std::size_t e = rest.find_last_not_of(" \t\r");
        data && e != std::string_view::npos && rest[e] == '\\' &&
        rest.substr(0, e).find('#') == std::string_view::npos)
      fail(
          "a '\\' at the end of a line continues it on the next, which lucent does not read: "
          "join the two lines");
    if (!obj_statement(tag) && ++out.foreign_lines == 1) {
      out.foreign_line = ln;
      out.foreign_statement = io::one_line(str(tag));
    }
    int need = 0;
    const char* what = nullptr;
    if (tag == "v") {
      need = 3, what = "vertex", ++count[0];
    } else if (tag == "vt") {
      need = 1, what = "texture coordinate", ++count[1];
    } else if (tag == "vn") {
      need = 3, what = "normal", ++count[2];
    }
    if (tag == "t") {  // tinyobjloader's tags: ints, reals and strings, unused by lucent
      for (std::string_view t; !(t = raw_token(rest)).empty();) check_exponent(t, fail);
      return;
    }
    if (tag == "vw") {
      // tinyobjloader's skin weights (vw vertex joint weight joint weight ...), unused by lucent
      // but parsed: it converts each joint to int unchecked (1e11 is undefined behaviour)
      int n = 0;
      for (std::string_view t; !(t = raw_token(rest)).empty(); ++n) {
        const double v = number(t, fail, "skin weight");
        if (n % 2 == 1 && !(v >= 0 && v <= INT_MAX))
          fail("skin weight line: joint '" + str(t) + "' is out of range (0 to " +
               std::to_string(INT_MAX) + ")");
      }
      return;
    }
    if (what) {
      // tinyobjloader reads up to six numbers (a vertex colour), past a '#' too
      for (std::string_view probe = rest, t; !(t = raw_token(probe)).empty();)
        check_exponent(t, fail);
      int n = 0;
      for (std::string_view t; !(t = token(rest)).empty(); ++n) number(t, fail, what);
      if (n < need)
        fail(std::string(what) + " line has " + std::to_string(n) + " number" +
             (n == 1 ? "" : "s") + ", needs " + std::to_string(need));
      return;
    }
    const char* element = tag == "f"   ? "face"
                          : tag == "l" ? "line element"
                          : tag == "p" ? "point element"
                                       : nullptr;
    if (!element) return;
    int corners = 0;
    if (rest.find('#') != std::string_view::npos) {  // a word starting with '#' ends the line
      std::string_view probe = rest;
      for (std::string_view t; !(t = raw_token(probe)).empty();)
        if (t[0] == '#') out.element_comments = true;
    }
    for (std::string_view t; !(t = token(rest)).empty(); ++corners) {
      // v, v/vt, v//vn or v/vt/vn
      std::string_view parts[3];
      int np = 0;
      for (std::size_t start = 0;;) {
        std::size_t slash = t.find('/', start);
        if (np == 3) fail(std::string(element) + ": '" + str(t) + "' has more than 3 indices");
        parts[np++] = t.substr(start, slash == std::string_view::npos ? slash : slash - start);
        if (slash == std::string_view::npos) break;
        start = slash + 1;
      }
      for (int k = 0; k < np; ++k) {
        if (parts[k].empty()) {
          if (k == 0) fail(std::string(element) + ": '" + str(t) + "' has no vertex index");
          // "1//3": no texture coordinate. A slash with nothing after it ("1/", "1//", "1/2/")
          // is no form of the grammar: tinyobjloader's atoi skipped the space after "1/" and
          // took the next corner's vertex index as this corner's texture coordinate
          if (k == np - 1)
            fail(std::string(element) + ": '" + str(t) + "' ends with a slash (the forms are v, " +
                 "v/vt, v//vn and v/vt/vn)");
          continue;
        }
        std::int64_t idx = 0;
        std::string_view p = parts[k];
        if (p[0] == '+') p.remove_prefix(1);
        auto [ptr, ec] = std::from_chars(p.data(), p.data() + p.size(), idx);
        if (ec == std::errc::result_out_of_range)
          fail(std::string(element) + ": " + kKinds[k] + " index " + str(parts[k]) +
               " is out of range");
        if (ec != std::errc() || ptr != p.data() + p.size())
          fail(std::string(element) + ": " + kKinds[k] + " index '" + str(parts[k]) +
               "' is not an integer");
        if (idx == 0)
          fail(std::string(element) + ": " + kKinds[k] + " index 0 (OBJ indices start at 1)");
        if (idx < 0) {
          if (count[k] + idx + 1 < 1)
            fail(std::string(element) + ": " + kKinds[k] + " index " + std::to_string(idx) +
                 " is out of range (" + std::to_string(count[k]) + " defined so far)");
        } else if (idx > count[k] && idx > wanted[k]) {
          wanted[k] = idx;  // may be defined further down: checked at the end
          wanted_line[k] = ln;
        }
      }
    }
    ++out.elements;
    out.corners += corners;
    if (tag != "f") return;
    if (corners > kMaxFaceVertices)
      fail("face has " + std::to_string(corners) + " corners, more than the " +
           std::to_string(kMaxFaceVertices) + " tinyobjloader can hold");
    if (corners >= 3) out.triangles += corners - 2;
    if (static_cast<std::uint64_t>(out.triangles) > kMaxTriangles)
      fail("more than " + std::to_string(kMaxTriangles) + " triangles in one OBJ file");
  });
  reading(0);
  // a PLY, STL or glTF file named as a mesh: an OBJ file of no vertex or face was a warning
  // ("no faces") and an image without the mesh
  if (count[0] == 0 && out.elements == 0 && out.foreign_line > 0)
    LineError(path, out.foreign_line)(
        "'" + out.foreign_statement +
        "' is no OBJ statement, and the file defines no vertex or face: not a Wavefront OBJ "
        "file (lucent reads meshes as OBJ)");
  for (int k = 0; k < 3; ++k)
    if (wanted[k] > count[k])
      LineError(path, wanted_line[k])(
          std::string(kKinds[k]) + " index " + std::to_string(wanted[k]) +
          " is out of range (the file defines " + std::to_string(count[k]) + ")");
  out.vertices = count[0];
  out.texcoords = count[1];
  out.normals = count[2];
  return out;
}

void blank_element_comments(std::string& text) {
  // in place (spaces end no line, so the lines found stay as they are): a copy would hold the
  // text twice while tinyobjloader reads it
  for_each_line(text, [&](std::string_view rest, long) {
    const std::string_view tag = token(rest);
    if (tag != "f" && tag != "l" && tag != "p") return;
    for (std::string_view t; !(t = raw_token(rest)).empty();) {
      if (t[0] != '#') continue;
      const std::size_t from = static_cast<std::size_t>(t.data() - text.data());
      const std::size_t to = static_cast<std::size_t>(rest.data() + rest.size() - text.data());
      std::fill(text.begin() + from, text.begin() + to, ' ');
      return;
    }
  });
}

namespace {

/// The MTL statements that give a colour (three numbers, or the xyz and spectral forms).
constexpr const char* kColourTags[] = {"Ka", "Kd", "Ks", "Ke", "Kt", "Tf"};

bool colour_tag(std::string_view tag) {
  return std::any_of(std::begin(kColourTags), std::end(kColourTags),
                     [&](const char* c) { return tag == c; });
}

/// A colour given as CIE XYZ (one to three numbers; one is x = y = z, the MTL specification) in
/// linear sRGB (D65, IEC 61966-2-1's matrix); its negative channels are left negative.
glm::dvec3 xyz_to_srgb(const double* v, int n) {
  const double x = v[0], y = n == 1 ? v[0] : v[1], z = n == 1 ? v[0] : v[2];
  return {3.2404542 * x - 1.5371385 * y - 0.4985314 * z,
          -0.9692660 * x + 1.8760108 * y + 0.0415560 * z,
          0.0556434 * x - 0.2040259 * y + 1.0572252 * z};
}

}  // namespace

void check_mtl_text(const std::string& path, const std::string& text) {
  for_each_line(text, [&](std::string_view rest, long ln) {
    const LineError fail(path, ln);
    std::string_view tag = token(rest);
    if (tag.empty()) return;
    if (tag != "newmtl")
      for (std::string_view probe = rest, t; !(t = raw_token(probe)).empty();)
        check_exponent(t, fail);
    static const char* const scalars[] = {"Ns", "Ni", "d",   "Tr",    "Pr",    "Pm",
                                          "Ps", "Pc", "Pcr", "aniso", "anisor"};
    std::string name(tag);
    const bool colour = colour_tag(tag);
    bool scalar = false;
    for (const char* s : scalars) scalar = scalar || tag == s;
    if (colour) {
      std::string_view probe = rest;
      std::string_view first = token(probe);
      // the forms tinyobjloader does not read (read_colour_forms): "spectral file [factor]",
      // "xyz x [y z]"
      if (first == "spectral") {
        if (token(probe).empty()) fail(name + " spectral line has no file name");
        std::string_view factor = token(probe);
        if (!factor.empty()) number(factor, fail, name.c_str());
        return;
      }
      const bool xyz = first == "xyz";
      if (xyz) rest = probe;
      int n = 0;
      double given[3] = {0, 0, 0};
      for (std::string_view t; !(t = token(rest)).empty(); ++n) {
        double v = number(t, fail, name.c_str());
        if (v < 0) fail(name + " line: '" + str(t) + "' is negative");
        if (n < 3) given[n] = v;
      }
      if (xyz && n != 1 && n != 3)
        fail(name + " xyz line has " + std::to_string(n) + " number" + (n == 1 ? "" : "s") +
             ", needs 1 or 3");
      // (the matrix multiplies by up to 3.24: "Kd xyz 2e38 0 0" is 6.5e38 in sRGB, which
      // tinyobjloader's float cannot hold)
      if (xyz) {
        const glm::dvec3 rgb = xyz_to_srgb(given, n);
        if (std::max({rgb.x, rgb.y, rgb.z}) > double(FLT_MAX))
          fail(name + " xyz line: the colour is out of range for a float in sRGB");
      }
      // (one number is r = g = b, as the MTL format says: read_colour_forms)
      if (!xyz && n != 1 && n != 3)
        fail(name + " line has " + std::to_string(n) + " numbers, needs 3 (or 1, for grey)");
    } else if (scalar) {
      std::string_view t = token(rest);
      if (t.empty()) fail(name + " line has no number");
      number(t, fail, name.c_str());
    } else if (tag == "illum") {
      std::string_view t = token(rest);
      int v = -1;
      auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
      // "illum 2.0" (some exporters write a decimal; tinyobjloader's atoi reads 2): a point and
      // zeros only, since atoi would read "2.5" as 2 and "1e1" as 1
      if (ec == std::errc() && ptr < t.data() + t.size() && *ptr == '.') {
        ++ptr;
        while (ptr < t.data() + t.size() && *ptr == '0') ++ptr;
      }
      if (ec != std::errc() || ptr != t.data() + t.size() || v < 0 || v > 10)
        fail("illum line: '" + str(t) + "' is not an illumination model (0 to 10)");
    }
  });
}

namespace {

// A token of a texture statement's options, split as tinyobjloader splits them (spaces and tabs).
struct Word {
  std::size_t begin, end;  // offsets in the line
};

bool is_number(std::string_view t) {
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  double v = 0;
  auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  return !t.empty() && ptr == t.data() + t.size() &&
         (ec == std::errc() || ec == std::errc::result_out_of_range);
}

// The texture statements tinyobjloader reads (ParseTextureNameAndOption): the tag, then one space
// or tab.
bool texture_tag(std::string_view tag) {
  static const char* const tags[] = {"map_Ka",   "map_Kd", "map_Ks", "map_Ns",   "map_bump",
                                     "map_Bump", "bump",   "map_d",  "map_disp", "map_Disp",
                                     "disp",     "refl",   "map_Pr", "map_Pm",   "map_Ps",
                                     "map_Ke",   "norm"};
  for (const char* t : tags)
    if (tag == t) return true;
  return false;
}

// The texture options of the MTL specification (and tinyobjloader's -colorspace): how many
// arguments each takes at most, and of which kind.
enum class Arg { Number, OnOff, Word };
struct TextureOption {
  const char* name;
  int most;
  Arg kind;
};
constexpr TextureOption kTextureOptions[] = {
    {"-blendu", 1, Arg::OnOff},  {"-blendv", 1, Arg::OnOff},   {"-cc", 1, Arg::OnOff},
    {"-clamp", 1, Arg::OnOff},   {"-boost", 1, Arg::Number},   {"-bm", 1, Arg::Number},
    {"-texres", 1, Arg::Number}, {"-mm", 2, Arg::Number},      {"-o", 3, Arg::Number},
    {"-s", 3, Arg::Number},      {"-t", 3, Arg::Number},       {"-imfchan", 1, Arg::Word},
    {"-type", 1, Arg::Word},     {"-colorspace", 1, Arg::Word}};

// An option of map_Kd that lucent does not read whose arguments change what the texture looks
// like: lucent reads the image as decoded (docs/obj-mtl.md). (-s, -o and -clamp it reads:
// read_kd_option.)
bool changes_the_look(std::string_view name, const std::vector<std::string_view>& args) {
  io::CNumbers c_numbers;         // "0.5", whatever the process locale
  auto all = [&](double value) {  // every argument the given number (missing ones default)
    for (std::string_view a : args)
      if (std::strtod(std::string(a).c_str(), nullptr) != value) return false;
    return true;
  };
  if (name == "-t") return !all(0);
  if (name == "-mm")  // base 0, gain 1
    return (args.size() > 0 && std::strtod(std::string(args[0]).c_str(), nullptr) != 0) ||
           (args.size() > 1 && std::strtod(std::string(args[1]).c_str(), nullptr) != 1);
  if (name == "-cc") return args.empty() || args[0] != "off";
  if (name == "-colorspace")  // tinyobjloader's: 8-bit images are decoded from sRGB
    return args.empty() || (args[0] != "sRGB" && args[0] != "srgb");
  // -s, -o, -clamp: read; -blendu, -blendv, -boost, -texres, -bm, -imfchan, -type: no effect here
  return false;
}

// A map_Kd option that lucent reads, into `m`: -s and -o (u, and v when given; w ignored) and
// -clamp (on unless its argument is off).
void read_kd_option(std::string_view name, const std::vector<std::string_view>& args, MtlName& m) {
  io::CNumbers c_numbers;  // "0.5", whatever the process locale
  auto number = [&](std::size_t k, double otherwise) {
    return k < args.size() ? std::strtod(std::string(args[k]).c_str(), nullptr) : otherwise;
  };
  if (name == "-s") m.kd_scale = glm::dvec2(number(0, 1), number(1, 1));
  if (name == "-o") m.kd_offset = glm::dvec2(number(0, 0), number(1, 0));
  if (name == "-clamp") m.kd_clamp = args.empty() || args[0] != "off";
}

// Where the file name of a texture statement's `args` (the line after the tag and its space)
// starts: after the options and their arguments. The last word is always (part of) the name.
// `look`, if given, receives the options (with their arguments) that changes_the_look; `kd`, if
// given, the options that read_kd_option reads.
std::size_t texture_name_start(std::string_view args, std::vector<std::string>* look = nullptr,
                               MtlName* kd = nullptr) {
  std::vector<Word> words;
  for (std::size_t i = 0; i < args.size();) {
    std::size_t b = args.find_first_not_of(" \t", i);
    if (b == std::string_view::npos) break;
    std::size_t e = std::min(args.find_first_of(" \t", b), args.size());
    words.push_back({b, e});
    i = e;
  }
  auto word = [&](std::size_t k) {
    return args.substr(words[k].begin, words[k].end - words[k].begin);
  };
  std::size_t k = 0;
  while (k + 1 < words.size()) {
    const TextureOption* option = nullptr;
    for (const TextureOption& o : kTextureOptions)
      if (word(k) == o.name) option = &o;
    if (!option) break;
    ++k;
    std::vector<std::string_view> taken;
    for (int n = 0; n < option->most && k + 1 < words.size(); ++n, ++k) {
      std::string_view a = word(k);
      bool fits = option->kind == Arg::Word ||
                  (option->kind == Arg::OnOff && (a == "on" || a == "off")) ||
                  (option->kind == Arg::Number && is_number(a));
      if (!fits) break;
      taken.push_back(a);
    }
    if (kd) read_kd_option(option->name, taken, *kd);
    if (look && changes_the_look(option->name, taken)) {
      std::string text = option->name;
      for (std::string_view a : taken) (text += ' ') += a;
      look->push_back(text);
    }
  }
  return k < words.size() ? words[k].begin : args.size();
}

}  // namespace

std::string strip_texture_options(const std::string& text, std::vector<IgnoredOption>* ignored) {
  std::string out;
  std::size_t copied = 0;  // text before this offset is in `out`
  for_each_line(text, [&](std::string_view line, long ln) {
    std::size_t b = line.find_first_not_of(" \t");
    if (b == std::string_view::npos) return;
    std::size_t e = line.find_first_of(" \t", b);
    if (e == std::string_view::npos || !texture_tag(line.substr(b, e - b))) return;
    std::string_view args = line.substr(e + 1);
    // map_Kd is the one map lucent reads: its options that would change the look are reported
    std::vector<std::string> look;
    const bool kd = line.substr(b, e - b) == "map_Kd" && ignored;
    std::size_t name = texture_name_start(args, kd ? &look : nullptr);
    for (std::string& o : look) ignored->push_back({ln, std::move(o)});
    if (args.find_first_not_of(" \t") >= name) return;  // no options
    const std::size_t at = static_cast<std::size_t>(args.data() - text.data());
    out.append(text, copied, at - copied);
    copied = at + name;
  });
  if (copied == 0) return text;
  out.append(text, copied, std::string::npos);
  return out;
}

std::string read_colour_forms(const std::string& path, const std::string& text,
                              std::vector<std::string>* warnings) {
  io::CNumbers c_numbers;  // "0.5", whatever the process locale
  std::string out;
  out.reserve(text.size());
  std::size_t copied = 0;  // text before this offset is in `out`
  std::string material;    // the newmtl before the line, for the warnings
  for_each_line(text, [&](std::string_view line, long ln) {
    std::string_view rest = line;
    const std::string_view tag = token(rest);
    if (tag == "newmtl") {
      // ("newmtl" alone is no statement: the lines after it are the previous material's)
      if (std::string name = trim(std::string(rest)); !name.empty()) material = name;
      return;
    }
    if (!colour_tag(tag)) return;
    std::string_view args = rest;
    const std::string_view form = token(args);
    // one number is grey, r = g = b, as the MTL format says: tinyobjloader read "Kd 0.5" as
    // 0.5 0 0 (lucent refused it until 30 Nov 2026)
    const bool grey = !form.empty() && form != "xyz" && form != "spectral" && token(args).empty();
    // Tf spectral stays: a transparent material is warned of it, and clear (MaterialMapper)
    if (!grey && form != "xyz" && (form != "spectral" || tag == "Tf" || tag == "Kt")) return;
    const std::size_t at = static_cast<std::size_t>(line.data() - text.data());
    out.append(text, copied, at - copied);
    copied = at + line.size();
    if (grey) {
      const std::string v(form);
      out += std::string(tag) + " " + v + " " + v + " " + v;
      return;
    }
    const std::string where = path + ":" + std::to_string(ln) + ": material '" + material + "': ";
    if (form == "spectral") {
      // 0 0 0 in its place (as without the statement, but for a map_Kd: tinyobjloader gives one
      // without a Kd 0.6, in a file where no material had a Kd, which a missing image shows)
      out += std::string(tag) + " 0 0 0";
      if (tag != "Ka")  // (not read at all)
        warnings->push_back(where + std::string(tag) + " spectral (a curve in '" +
                            std::string(token(args)) + "') is not read: the material's " +
                            std::string(tag) + " is 0 0 0");
      return;
    }
    double v[3] = {0, 0, 0};
    int n = 0;
    for (std::string_view t; n < 3 && !(t = token(args)).empty(); ++n)
      v[n] = std::strtod(std::string(t).c_str(), nullptr);  // (checked by check_mtl_text)
    const glm::dvec3 srgb = xyz_to_srgb(v, n);
    if (n == 1) v[1] = v[2] = v[0];
    const bool clamped = std::min({srgb.x, srgb.y, srgb.z}) < 0;
    const glm::dvec3 rgb = glm::max(srgb, glm::dvec3(0.0));
    char numbers[96];
    std::snprintf(numbers, sizeof numbers, " %.9g %.9g %.9g", rgb.x, rgb.y, rgb.z);
    out += std::string(tag) + numbers;
    if (clamped && tag != "Ka") {
      char given[96];
      std::snprintf(given, sizeof given, "%.9g %.9g %.9g", v[0], v[1], v[2]);
      warnings->push_back(where + std::string(tag) + " xyz " + given +
                          " is outside the sRGB gamut: its negative channels are taken as 0 (" +
                          std::string(tag) + numbers + ")");
    }
  });
  if (copied == 0) return text;
  out.append(text, copied, std::string::npos);
  return out;
}

std::vector<MtlName> mtl_material_names(const std::string& text) {
  std::vector<MtlName> out;
  for_each_line(text, [&](std::string_view line, long ln) {
    std::size_t b = line.find_first_not_of(" \t");
    if (b == std::string_view::npos) return;
    // Tf and Kt as tinyobjloader tells them (both are its transmittance)
    if ((line.compare(b, 2, "Tf") == 0 || line.compare(b, 2, "Kt") == 0) && b + 2 < line.size() &&
        (line[b + 2] == ' ' || line[b + 2] == '\t')) {
      if (out.empty()) return;  // before any newmtl: tinyobjloader's unnamed material
      std::string_view rest = line.substr(b + 2);
      const std::string_view first = token(rest);
      out.back().tf_line = ln;
      out.back().tf_tag = std::string(line.substr(b, 2));
      out.back().tf_numbers = first != "spectral";  // (the xyz form is numbers by now)
      return;
    }
    // map_Kd: the options lucent reads, of the material's last one (tinyobjloader keeps the
    // last map_Kd's file)
    if (line.compare(b, 6, "map_Kd") == 0 && b + 6 < line.size() &&
        (line[b + 6] == ' ' || line[b + 6] == '\t')) {
      if (out.empty()) return;  // before any newmtl: tinyobjloader's unnamed material
      MtlName& m = out.back();
      m.kd_line = ln;
      m.kd_scale = glm::dvec2(1, 1);
      m.kd_offset = glm::dvec2(0, 0);
      m.kd_clamp = false;
      texture_name_start(line.substr(b + 7), nullptr, &m);
      return;
    }
    if (line.compare(b, 6, "newmtl") != 0 || b + 6 >= line.size() ||
        (line[b + 6] != ' ' && line[b + 6] != '\t'))
      return;
    // tinyobjloader keeps what follows "newmtl" and one space, spaces in front included; the
    // reader trims them (MtlReader::read)
    const std::string name = trim(std::string(line.substr(b + 7)));
    if (name.empty()) return;  // "newmtl" and spaces: no statement
    MtlName m;
    m.name = name;
    m.line = ln;
    out.push_back(std::move(m));
  });
  return out;
}

long line_of_statement(const std::string& text, const char* tag, std::int64_t n) {
  long found = 0;
  std::int64_t seen = 0;
  for_each_line(text, [&](std::string_view rest, long ln) {
    if (found == 0 && token(rest) == tag && seen++ == n) found = ln;
  });
  return found;
}

namespace {

/// The first "line N" or "line: N" of `text` at or after `from`: where N's digits begin and end
/// ({npos, npos} if none). (A scan, not std::regex: <regex> made this file the library's slowest
/// to compile, 6.8 s of CPU at -O3 with GCC against 3.9 s without it.)
std::pair<size_t, size_t> find_line_number(std::string_view text, size_t from) {
  for (size_t at = text.find("line", from); at != std::string_view::npos;
       at = text.find("line", at + 1)) {
    size_t i = at + 4;
    if (i < text.size() && text[i] == ':') ++i;
    if (i >= text.size() || text[i] != ' ') continue;
    const size_t begin = ++i;
    while (i < text.size() && text[i] >= '0' && text[i] <= '9') ++i;
    if (i > begin) return {begin, i};
  }
  return {std::string_view::npos, std::string_view::npos};
}

}  // namespace

std::string shift_line_numbers(const std::string& text, long by) {
  std::string out;
  size_t last = 0;
  for (auto [begin, end] = find_line_number(text, 0); begin != std::string::npos;
       std::tie(begin, end) = find_line_number(text, end)) {
    out.append(text, last, begin - last);
    out += std::to_string(std::strtol(text.substr(begin, end - begin).c_str(), nullptr, 10) - by);
    last = end;
  }
  out.append(text, last, std::string::npos);
  return out;
}

[[noreturn]] void throw_parse_error(const std::string& path, const std::string& err) {
  std::vector<std::string> lines = lines_of(err);
  std::string first = lines.empty() ? "cannot parse the file" : lines.front();
  if (const auto [begin, end] = find_line_number(first, 0); begin != std::string::npos) {
    std::string what = first;
    if (first.find("Failed parse `f'") != std::string::npos)
      what = "malformed face: an index is 0 or not a number";
    else if (first.find("Failed parse `l'") != std::string::npos)
      what = "malformed line element: an index is 0 or not a number";
    else if (first.find("Failed parse `p'") != std::string::npos)
      what = "malformed point element: an index is 0 or not a number";
    throw Error(path + ":" + first.substr(begin, end - begin) + ": " + what);
  }
  throw Error(path + ": " + first);
}

}  // namespace lucent::scene_detail::obj
