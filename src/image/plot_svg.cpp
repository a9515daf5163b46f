#include "image/plot_svg.hpp"

#include <stb/stb_easy_font.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "core/text.hpp"

namespace lucent::plot {

namespace {

// Tableau 10: distinguishable, and readable on white.
const char* const kColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                                "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};

bool usable(double v) { return std::isfinite(v) && v > 0; }

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}

/// Decade range [lo, hi] (integers, hi > lo) covering the positive values in `v`.
void decades(const std::vector<const std::vector<double>*>& lists, int& lo, int& hi) {
  double mn = std::numeric_limits<double>::infinity(), mx = -mn;
  for (const auto* l : lists)
    for (double v : *l)
      if (usable(v)) {
        mn = std::min(mn, v);
        mx = std::max(mx, v);
      }
  if (!(mn <= mx)) {
    lo = 0;
    hi = 1;
    return;
  }
  lo = static_cast<int>(std::floor(std::log10(mn) + 1e-9));
  hi = static_cast<int>(std::ceil(std::log10(mx) - 1e-9));
  if (hi <= lo) hi = lo + 1;
}

/// "10<sup>k</sup>" as SVG text content.
std::string power_label(int k) {
  return "10<tspan dy=\"-7\" font-size=\"10\">" + std::to_string(k) + "</tspan>";
}

}  // namespace

std::string xml_escape(const std::string& text) {
  // Only XML 1.0 characters, in UTF-8 (the prolog's encoding): a byte that is not UTF-8, a C0
  // control (a scene file named "a\x01b\xff.json" made the plot ill-formed XML, which browsers
  // refuse to show) and DEL are written as \xNN, tab, newline and CR as \t, \n, \r
  // (io::one_line, as the command line shows names), and the non-characters U+FFFE and U+FFFF,
  // which XML forbids too, as the \xNN of their bytes.
  const std::string clean = io::one_line(text);
  std::string out;
  for (size_t i = 0; i < clean.size(); ++i) {
    const char c = clean[i];
    // (0xEF is always a lead byte in UTF-8: this is the start of a character)
    if (c == '\xEF' && i + 2 < clean.size() && clean[i + 1] == '\xBF' &&
        (clean[i + 2] == '\xBE' || clean[i + 2] == '\xBF')) {
      out += clean[i + 2] == '\xBE' ? "\\xef\\xbf\\xbe" : "\\xef\\xbf\\xbf";
      i += 2;
      continue;
    }
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

namespace {

/// Where everything goes; shared by the SVG and the raster renderings.
struct Layout {
  int x0 = 0, x1 = 1, y0 = 0, y1 = 1;  ///< decade ranges
  double left = 80, top = 44, bottom = 62, pw = 100, ph = 100, W = 0, H = 0;
  double X(double v) const { return left + (std::log10(v) - x0) / (x1 - x0) * pw; }
  double Y(double v) const { return top + ph - (std::log10(v) - y0) / (y1 - y0) * ph; }
  double legend_x() const { return left + pw + 16; }
  double legend_y(std::size_t i) const { return top + 8 + 20.0 * static_cast<double>(i); }
};

Layout layout(const LogLogPlot& p) {
  std::vector<const std::vector<double>*> xs, ys;
  for (const Series& s : p.series) {
    xs.push_back(&s.x);
    ys.push_back(&s.y);
  }
  Layout L;
  decades(xs, L.x0, L.x1);
  decades(ys, L.y0, L.y1);
  // legend width from the longest name (about 7 px a character at 12 px)
  std::size_t longest = 0;
  for (const Series& s : p.series) longest = std::max(longest, s.name.size());
  const double legend_w = 40 + 7.0 * static_cast<double>(longest);
  const double right = 24 + legend_w;
  L.W = p.width;
  L.H = p.height;
  L.pw = std::max(100.0, L.W - L.left - right);
  L.ph = std::max(100.0, L.H - L.top - L.bottom);
  return L;
}

}  // namespace

std::string log_log_svg(const LogLogPlot& p) {
  const Layout L = layout(p);
  const int x0 = L.x0, x1 = L.x1, y0 = L.y0, y1 = L.y1;
  const double left = L.left, top = L.top, pw = L.pw, ph = L.ph, H = L.H;
  auto X = [&](double v) { return L.X(v); };
  auto Y = [&](double v) { return L.Y(v); };

  std::ostringstream o;
  o << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << p.width << "\" height=\"" << p.height
    << "\" viewBox=\"0 0 " << p.width << " " << p.height
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  o << "<rect x=\"0\" y=\"0\" width=\"" << p.width << "\" height=\"" << p.height
    << "\" fill=\"white\"/>\n";
  if (!p.title.empty())
    o << "<text x=\"" << num(left + pw / 2)
      << "\" y=\"24\" text-anchor=\"middle\" font-size=\"15\">" << xml_escape(p.title)
      << "</text>\n";

  // grid and ticks
  o << "<g stroke-width=\"1\">\n";
  for (int k = x0; k <= x1; ++k) {
    double x = X(std::pow(10.0, k));
    o << "<line x1=\"" << num(x) << "\" y1=\"" << num(top) << "\" x2=\"" << num(x) << "\" y2=\""
      << num(top + ph) << "\" stroke=\"#dddddd\"/>\n";
    o << "<text x=\"" << num(x) << "\" y=\"" << num(top + ph + 20)
      << "\" text-anchor=\"middle\" stroke=\"none\">" << power_label(k) << "</text>\n";
    for (int m = 2; m <= 9 && k < x1; ++m) {
      double xm = X(m * std::pow(10.0, k));
      o << "<line x1=\"" << num(xm) << "\" y1=\"" << num(top + ph) << "\" x2=\"" << num(xm)
        << "\" y2=\"" << num(top + ph - 5) << "\" stroke=\"#555555\"/>\n";
    }
  }
  for (int k = y0; k <= y1; ++k) {
    double y = Y(std::pow(10.0, k));
    o << "<line x1=\"" << num(left) << "\" y1=\"" << num(y) << "\" x2=\"" << num(left + pw)
      << "\" y2=\"" << num(y) << "\" stroke=\"#dddddd\"/>\n";
    o << "<text x=\"" << num(left - 8) << "\" y=\"" << num(y + 4)
      << "\" text-anchor=\"end\" stroke=\"none\">" << power_label(k) << "</text>\n";
    for (int m = 2; m <= 9 && k < y1; ++m) {
      double ym = Y(m * std::pow(10.0, k));
      o << "<line x1=\"" << num(left) << "\" y1=\"" << num(ym) << "\" x2=\"" << num(left + 5)
        << "\" y2=\"" << num(ym) << "\" stroke=\"#555555\"/>\n";
    }
  }
  o << "</g>\n";
  o << "<rect x=\"" << num(left) << "\" y=\"" << num(top) << "\" width=\"" << num(pw)
    << "\" height=\"" << num(ph) << "\" fill=\"none\" stroke=\"black\"/>\n";
  o << "<text x=\"" << num(left + pw / 2) << "\" y=\"" << num(H - 14)
    << "\" text-anchor=\"middle\">" << xml_escape(p.x_label) << "</text>\n";
  o << "<text x=\"18\" y=\"" << num(top + ph / 2)
    << "\" text-anchor=\"middle\" transform=\"rotate(-90 18 " << num(top + ph / 2) << ")\">"
    << xml_escape(p.y_label) << "</text>\n";

  // series: one path each, then the markers
  for (std::size_t i = 0; i < p.series.size(); ++i) {
    const Series& s = p.series[i];
    const char* colour = kColours[i % (sizeof kColours / sizeof kColours[0])];
    std::string d;
    std::size_t n = std::min(s.x.size(), s.y.size());
    for (std::size_t j = 0; j < n; ++j) {
      if (!usable(s.x[j]) || !usable(s.y[j])) continue;
      d += (d.empty() ? "M" : " L") + num(X(s.x[j])) + " " + num(Y(s.y[j]));
    }
    o << "<g class=\"series\" stroke=\"" << colour << "\" fill=\"" << colour << "\">\n";
    o << "<title>" << xml_escape(s.name) << "</title>\n";
    o << "<path d=\"" << (d.empty() ? "M0 0" : d) << "\" fill=\"none\" stroke-width=\"2\"/>\n";
    for (std::size_t j = 0; j < n; ++j)
      if (usable(s.x[j]) && usable(s.y[j]))
        o << "<circle cx=\"" << num(X(s.x[j])) << "\" cy=\"" << num(Y(s.y[j]))
          << "\" r=\"3\" stroke=\"none\"/>\n";
    o << "</g>\n";
  }

  // legend
  const double lx = L.legend_x();
  for (std::size_t i = 0; i < p.series.size(); ++i) {
    const char* colour = kColours[i % (sizeof kColours / sizeof kColours[0])];
    double y = L.legend_y(i);
    o << "<line x1=\"" << num(lx) << "\" y1=\"" << num(y) << "\" x2=\"" << num(lx + 24)
      << "\" y2=\"" << num(y) << "\" stroke=\"" << colour << "\" stroke-width=\"2\"/>\n";
    o << "<circle cx=\"" << num(lx + 12) << "\" cy=\"" << num(y) << "\" r=\"3\" fill=\"" << colour
      << "\"/>\n";
    o << "<text x=\"" << num(lx + 30) << "\" y=\"" << num(y + 4) << "\">"
      << xml_escape(p.series[i].name) << "</text>\n";
  }
  o << "</svg>\n";
  return o.str();
}

// ---------------------------------------------------------------------------------------------
// Raster rendering (the same layout), for a PNG through lucent's own image writer. Drawn at
// kSuper times the size and box-filtered down; text from stb_easy_font's segment font.

namespace {

constexpr int kSuper = 3;

struct Rgb {
  float r, g, b;
};

double srgb_to_linear(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

Rgb parse_colour(const char* hex) {
  auto byte = [&](int i) {
    auto nib = [](char c) { return c <= '9' ? c - '0' : (c | 0x20) - 'a' + 10; };
    return static_cast<double>(nib(hex[1 + 2 * i]) * 16 + nib(hex[2 + 2 * i])) / 255.0;
  };
  return {static_cast<float>(srgb_to_linear(byte(0))), static_cast<float>(srgb_to_linear(byte(1))),
          static_cast<float>(srgb_to_linear(byte(2)))};
}

/// A linear RGB canvas in plot units (the SVG's pixels), kSuper samples per unit.
struct Canvas {
  int w, h;  // in samples
  std::vector<float> rgb;
  Canvas(int width, int height)
      : w(width * kSuper), h(height * kSuper), rgb(static_cast<std::size_t>(w) * h * 3, 1.0f) {}

  void set(int x, int y, Rgb c) {
    if (x < 0 || y < 0 || x >= w || y >= h) return;
    float* p = &rgb[(static_cast<std::size_t>(y) * w + x) * 3];
    p[0] = c.r;
    p[1] = c.g;
    p[2] = c.b;
  }
  /// Axis-aligned rectangle [x0, x1] x [y0, y1] in plot units.
  void rect(double x0, double y0, double x1, double y1, Rgb c) {
    if (x1 < x0) std::swap(x0, x1);
    if (y1 < y0) std::swap(y0, y1);
    int a = static_cast<int>(std::floor(x0 * kSuper)), b = static_cast<int>(std::ceil(x1 * kSuper));
    int d = static_cast<int>(std::floor(y0 * kSuper)), e = static_cast<int>(std::ceil(y1 * kSuper));
    for (int y = std::max(0, d); y < std::min(h, e); ++y)
      for (int x = std::max(0, a); x < std::min(w, b); ++x) set(x, y, c);
  }
  /// Segment of the given width (plot units), round ends.
  void line(double x0, double y0, double x1, double y1, double width, Rgb c) {
    const double r = 0.5 * width * kSuper;
    x0 *= kSuper, y0 *= kSuper, x1 *= kSuper, y1 *= kSuper;
    int a = static_cast<int>(std::floor(std::min(x0, x1) - r));
    int b = static_cast<int>(std::ceil(std::max(x0, x1) + r));
    int d = static_cast<int>(std::floor(std::min(y0, y1) - r));
    int e = static_cast<int>(std::ceil(std::max(y0, y1) + r));
    const double dx = x1 - x0, dy = y1 - y0, len2 = dx * dx + dy * dy;
    for (int y = std::max(0, d); y <= std::min(h - 1, e); ++y)
      for (int x = std::max(0, a); x <= std::min(w - 1, b); ++x) {
        double px = x + 0.5 - x0, py = y + 0.5 - y0;
        double t = len2 > 0 ? std::clamp((px * dx + py * dy) / len2, 0.0, 1.0) : 0.0;
        double qx = px - t * dx, qy = py - t * dy;
        if (qx * qx + qy * qy <= r * r) set(x, y, c);
      }
  }
  void disk(double cx, double cy, double radius, Rgb c) { line(cx, cy, cx, cy, 2 * radius, c); }

  /// Text with its baseline at y; anchor 0 left, 0.5 middle, 1 end; `size` about the SVG
  /// font-size. rotate: turned 90 degrees anticlockwise about (x, y) (a y-axis label).
  void text(double x, double y, const std::string& s, double size, double anchor, Rgb c,
            bool rotate = false) {
    std::string t;
    for (char ch : s) t += (ch >= 32 && ch < 127) ? ch : '?';
    const double k = size / 12.0 * 1.2;  // stb_easy_font capitals are 7 units tall
    std::vector<char> buf(t.size() * 300 + 64);
    int quads =
        stb_easy_font_print(0, 0, t.data(), nullptr, buf.data(), static_cast<int>(buf.size()));
    double width = stb_easy_font_width(t.data()) * k;
    double ox = -anchor * width, oy = -7 * k;  // text origin relative to the anchor point
    for (int q = 0; q < quads; ++q) {
      const float* v0 = reinterpret_cast<const float*>(buf.data() + q * 64);
      const float* v2 = reinterpret_cast<const float*>(buf.data() + q * 64 + 32);
      double u0 = ox + v0[0] * k, w0 = oy + v0[1] * k, u1 = ox + v2[0] * k, w1 = oy + v2[1] * k;
      if (rotate)
        rect(x + w0, y - u0, x + w1, y - u1, c);
      else
        rect(x + u0, y + w0, x + u1, y + w1, c);
    }
  }
  /// "10" with a raised exponent, like the SVG's labels.
  void power(double x, double y, int k, double anchor, Rgb c) {
    std::string e = std::to_string(k);
    const double kk = 1.2;
    double wb = stb_easy_font_width(const_cast<char*>("10")) * kk;
    double we = stb_easy_font_width(e.data()) * kk * 10.0 / 12.0;
    double start = x - anchor * (wb + we);
    text(start, y, "10", 12, 0, c);
    text(start + wb, y - 6, e, 10, 0, c);
  }

  Image downsample() const {
    Image img;
    img.width = w / kSuper;
    img.height = h / kSuper;
    img.rgb.assign(static_cast<std::size_t>(img.width) * img.height * 3, 0.0f);
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x)
        for (int c = 0; c < 3; ++c) {
          double sum = 0;
          for (int j = 0; j < kSuper; ++j)
            for (int i = 0; i < kSuper; ++i)
              sum += rgb[((static_cast<std::size_t>(y) * kSuper + j) * w + x * kSuper + i) * 3 + c];
          img.pixel(x, y)[c] = static_cast<float>(sum / (kSuper * kSuper));
        }
    return img;
  }
};

}  // namespace

Image log_log_image(const LogLogPlot& p) {
  const Layout L = layout(p);
  Canvas cv(p.width, p.height);
  const Rgb black = parse_colour("#000000"), grid = parse_colour("#dddddd"),
            tick = parse_colour("#555555");
  for (int k = L.x0; k <= L.x1; ++k) {
    double x = L.X(std::pow(10.0, k));
    cv.line(x, L.top, x, L.top + L.ph, 1, grid);
    cv.power(x, L.top + L.ph + 20, k, 0.5, black);
    for (int m = 2; m <= 9 && k < L.x1; ++m) {
      double xm = L.X(m * std::pow(10.0, k));
      cv.line(xm, L.top + L.ph, xm, L.top + L.ph - 5, 1, tick);
    }
  }
  for (int k = L.y0; k <= L.y1; ++k) {
    double y = L.Y(std::pow(10.0, k));
    cv.line(L.left, y, L.left + L.pw, y, 1, grid);
    cv.power(L.left - 8, y + 4, k, 1.0, black);
    for (int m = 2; m <= 9 && k < L.y1; ++m) {
      double ym = L.Y(m * std::pow(10.0, k));
      cv.line(L.left, ym, L.left + 5, ym, 1, tick);
    }
  }
  const double r = L.left + L.pw, b = L.top + L.ph;
  cv.line(L.left, L.top, r, L.top, 1, black);
  cv.line(L.left, b, r, b, 1, black);
  cv.line(L.left, L.top, L.left, b, 1, black);
  cv.line(r, L.top, r, b, 1, black);
  if (!p.title.empty()) cv.text(L.left + L.pw / 2, 24, p.title, 15, 0.5, black);
  cv.text(L.left + L.pw / 2, L.H - 14, p.x_label, 12, 0.5, black);
  cv.text(22, L.top + L.ph / 2, p.y_label, 12, 0.5, black, true);

  const std::size_t ncol = sizeof kColours / sizeof kColours[0];
  for (std::size_t i = 0; i < p.series.size(); ++i) {
    const Series& s = p.series[i];
    const Rgb c = parse_colour(kColours[i % ncol]);
    std::size_t n = std::min(s.x.size(), s.y.size());
    bool have = false;
    double px = 0, py = 0;
    for (std::size_t j = 0; j < n; ++j) {
      if (!usable(s.x[j]) || !usable(s.y[j])) continue;
      double x = L.X(s.x[j]), y = L.Y(s.y[j]);
      if (have) cv.line(px, py, x, y, 2, c);
      cv.disk(x, y, 3, c);
      px = x, py = y, have = true;
    }
    double y = L.legend_y(i), lx = L.legend_x();
    cv.line(lx, y, lx + 24, y, 2, c);
    cv.disk(lx + 12, y, 3, c);
    cv.text(lx + 30, y + 4, s.name, 12, 0, black);
  }
  return cv.downsample();
}

}  // namespace lucent::plot
