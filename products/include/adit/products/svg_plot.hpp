#pragma once
// Small hand-written SVG charts (lines, points, grouped bars, text at data
// coordinates) so that `adit` and the session products can draw the plots
// people look at first (evaluation charts, cross-sections), with no plotting
// library.
// SVG 1.1: https://www.w3.org/TR/SVG11/

#include <filesystem>
#include <string>
#include <vector>

namespace adit::products {

enum class SeriesStyle { line, points, bars };

struct PlotSeries {
  std::string label;
  std::string color;  // any SVG colour, e.g. "#1f77b4"
  SeriesStyle style = SeriesStyle::line;
  std::vector<double> x;  // ignored for bars: bar k sits on category k
  std::vector<double> y;
  double stroke_width = 1.6;  // lines, in pixels
  double point_radius = 3.0;  // points, in pixels
};

// A label placed at data coordinates (dimensions on a cross-section).
struct PlotText {
  double x = 0.0, y = 0.0;
  std::string text;
  std::string color = "#000000";
  std::string anchor = "middle";  // SVG text-anchor: start, middle, end
  double dy_px = 0.0;             // shifted down by this many pixels
};

struct Plot {
  std::string title;
  std::string x_label;
  std::string y_label;
  std::vector<PlotSeries> series;
  std::vector<std::string> categories;  // bar charts: one label per bar group
  bool equal_axes = false;              // plan views: a metre is as long on both axes
  int width = 900;
  int height = 600;
  std::vector<PlotText> texts{};
};

std::string render_svg(const Plot& plot);

// Throws adit::InputError when the file cannot be written.
void write_svg(const std::filesystem::path& path, const Plot& plot);

// The colours used for reference / estimate / extra series.
inline constexpr const char* kColorReference = "#9e9e9e";
inline constexpr const char* kColorEstimate = "#d62728";
inline constexpr const char* kColorSecond = "#1f77b4";

}  // namespace adit::products
