#pragma once
// A minimal hand-written SVG line plot on log-log axes (used by `lucent converge`).
#include <string>
#include <vector>

#include "lucent/image.hpp"

namespace lucent::plot {

struct Series {
  std::string name;
  std::vector<double> x, y;  ///< points; those not finite and > 0 are left out
};

struct LogLogPlot {
  std::string title, x_label, y_label;
  int width = 900, height = 500;
  std::vector<Series> series;
};

/// The plot as a standalone SVG document: decade gridlines and labels (10^k), minor ticks, axis
/// labels, a legend, and exactly one <path> element per series (axes, ticks and the frame are
/// <line>/<rect> elements), with a <circle> marker at each point.
std::string log_log_svg(const LogLogPlot& plot);

/// The same plot as a linear RGB image (for write_image(), e.g. a PNG): lines, markers and
/// text (stb_easy_font) drawn at 3x the size and box-filtered down.
Image log_log_image(const LogLogPlot& plot);

/// Text with &, <, >, " and ' escaped for XML, and valid XML 1.0 whatever its bytes: what is not
/// UTF-8, the C0 controls, DEL, U+FFFE and U+FFFF are written as \xNN (tab, newline and CR as \t,
/// \n, \r), as io::one_line shows names.
std::string xml_escape(const std::string& text);

}  // namespace lucent::plot
