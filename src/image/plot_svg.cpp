#include "image/plot_svg.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

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
  std::string out;
  for (char c : text) {
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

std::string log_log_svg(const LogLogPlot& p) {
  std::vector<const std::vector<double>*> xs, ys;
  for (const Series& s : p.series) {
    xs.push_back(&s.x);
    ys.push_back(&s.y);
  }
  int x0, x1, y0, y1;
  decades(xs, x0, x1);
  decades(ys, y0, y1);

  // legend width from the longest name (about 7 px a character at 12 px)
  std::size_t longest = 0;
  for (const Series& s : p.series) longest = std::max(longest, s.name.size());
  const double legend_w = 40 + 7.0 * static_cast<double>(longest);
  const double left = 80, top = 44, bottom = 62, right = 24 + legend_w;
  const double W = p.width, H = p.height;
  const double pw = std::max(100.0, W - left - right), ph = std::max(100.0, H - top - bottom);
  auto X = [&](double v) { return left + (std::log10(v) - x0) / (x1 - x0) * pw; };
  auto Y = [&](double v) { return top + ph - (std::log10(v) - y0) / (y1 - y0) * ph; };

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
  const double lx = left + pw + 16, ly = top + 8;
  for (std::size_t i = 0; i < p.series.size(); ++i) {
    const char* colour = kColours[i % (sizeof kColours / sizeof kColours[0])];
    double y = ly + 20.0 * static_cast<double>(i);
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

}  // namespace lucent::plot
