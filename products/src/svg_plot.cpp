#include "adit/products/svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>

#include <fmt/format.h>

#include "adit/common/error.hpp"

namespace adit::products {
namespace {

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool empty() const { return lo > hi; }
  double span() const { return hi - lo; }
};

std::string escape(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

// A "nice" tick step (1, 2 or 5 times a power of ten) giving about `count` ticks.
double nice_step(double span, int count) {
  const double raw = span / count;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 5.0})
    if (raw <= m * power) return m * power;
  return 10.0 * power;
}

// Widens a degenerate or empty range and pads it by 5 %.
Range padded(Range r) {
  if (r.empty()) return {0.0, 1.0};
  if (r.span() <= 0.0) return {r.lo - 0.5 * std::max(1.0, std::abs(r.lo)), r.hi + 0.5 * std::max(1.0, std::abs(r.hi))};
  const double pad = 0.05 * r.span();
  return {r.lo - pad, r.hi + pad};
}

std::string number(double v) { return fmt::format("{:g}", std::abs(v) < 1e-12 ? 0.0 : v); }

// Tick values: multiples of `step` within [lo, hi]. Counted by index, not by
// adding step to y, which stalls when step is below y's resolution.
std::vector<double> ticks(double lo, double hi, double step) {
  std::vector<double> out;
  const double first = std::ceil(lo / step);
  for (int k = 0; k < 64; ++k) {
    const double v = (first + k) * step;
    if (v > hi) break;
    out.push_back(v);
  }
  return out;
}

}  // namespace

std::string render_svg(const Plot& plot) {
  const bool bars = std::any_of(plot.series.begin(), plot.series.end(),
                                [](const PlotSeries& s) { return s.style == SeriesStyle::bars; });
  Range xr, yr;
  for (const PlotSeries& s : plot.series) {
    for (const double y : s.y) yr.add(y);
    if (s.style != SeriesStyle::bars)
      for (const double x : s.x) xr.add(x);
  }
  if (bars) {
    xr = {-0.5, static_cast<double>(plot.categories.size()) - 0.5};
    yr.add(0.0);  // bars grow from zero
  }
  xr = bars ? xr : padded(xr);
  yr = padded(yr);

  const double left = 80, right = 20, top = 62, bottom = bars ? 90 : 60;
  const double pw = plot.width - left - right, ph = plot.height - top - bottom;
  if (plot.equal_axes) {  // grow the tighter axis so both have the same metres per pixel
    const double scale = std::max(xr.span() / pw, yr.span() / ph);
    const double cx = 0.5 * (xr.lo + xr.hi), cy = 0.5 * (yr.lo + yr.hi);
    xr = {cx - 0.5 * scale * pw, cx + 0.5 * scale * pw};
    yr = {cy - 0.5 * scale * ph, cy + 0.5 * scale * ph};
  }
  const auto px = [&](double x) { return left + (x - xr.lo) / xr.span() * pw; };
  const auto py = [&](double y) { return top + (yr.hi - y) / yr.span() * ph; };

  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\" "
      "font-family=\"DejaVu Sans, Arial, sans-serif\" font-size=\"13\">\n"
      "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
      "<text x=\"{2}\" y=\"26\" text-anchor=\"middle\" font-size=\"17\" font-weight=\"bold\">{3}</text>\n",
      plot.width, plot.height, left + pw / 2, escape(plot.title));

  // Grid and tick labels.
  const double ystep = nice_step(yr.span(), 6);
  for (const double y : ticks(yr.lo, yr.hi, ystep)) {
    svg += fmt::format("<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#e0e0e0\"/>\n", left,
                       py(y), left + pw, py(y));
    svg +=
        fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"end\">{}</text>\n", left - 6, py(y) + 4, number(y));
  }
  if (bars) {
    for (std::size_t k = 0; k < plot.categories.size(); ++k)
      svg += fmt::format(
          "<text x=\"{0:.1f}\" y=\"{1:.1f}\" text-anchor=\"end\" transform=\"rotate(-45 {0:.1f} "
          "{1:.1f})\">{2}</text>\n",
          px(static_cast<double>(k)) + 4, top + ph + 16, escape(plot.categories[k]));
  } else {
    const double xstep = nice_step(xr.span(), 8);
    for (const double x : ticks(xr.lo, xr.hi, xstep)) {
      svg += fmt::format("<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#e0e0e0\"/>\n", px(x),
                         top, px(x), top + ph);
      svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\">{}</text>\n", px(x), top + ph + 18,
                         number(x));
    }
  }
  svg += fmt::format("<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#333\"/>\n", left, top,
                     pw, ph);
  if (bars && yr.lo < 0.0)
    svg += fmt::format("<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#333\"/>\n", left, py(0),
                       left + pw, py(0));
  svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\">{}</text>\n", left + pw / 2,
                     plot.height - 12.0, escape(plot.x_label));
  svg += fmt::format(
      "<text x=\"18\" y=\"{0:.1f}\" text-anchor=\"middle\" transform=\"rotate(-90 18 {0:.1f})\">{1}</text>\n",
      top + ph / 2, escape(plot.y_label));

  // Data, clipped to the plot area.
  svg += fmt::format(
      "<clipPath id=\"area\"><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/></clipPath>\n<g "
      "clip-path=\"url(#area)\">\n",
      left, top, pw, ph);
  std::size_t bar_series = 0;
  const auto bar_count = static_cast<std::size_t>(std::count_if(
      plot.series.begin(), plot.series.end(), [](const PlotSeries& s) { return s.style == SeriesStyle::bars; }));
  for (const PlotSeries& s : plot.series) {
    if (s.style == SeriesStyle::line) {
      std::string points;
      for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i)
        if (std::isfinite(s.x[i]) && std::isfinite(s.y[i]))
          points += fmt::format("{:.1f},{:.1f} ", px(s.x[i]), py(s.y[i]));
      svg += fmt::format(
          "<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"{}\" stroke-linejoin=\"round\" points=\"{}\"/>\n",
          s.color, s.stroke_width, points);
    } else if (s.style == SeriesStyle::points) {
      for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i)
        svg +=
            fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"{}\" fill=\"{}\"/>\n", px(s.x[i]), py(s.y[i]),
                        s.point_radius, s.color);
    } else {
      const double group = 0.8 / static_cast<double>(bar_count);
      for (std::size_t k = 0; k < s.y.size(); ++k) {
        if (!std::isfinite(s.y[k])) continue;
        const double x0 = static_cast<double>(k) - 0.4 + group * static_cast<double>(bar_series);
        const double y0 = py(std::max(0.0, s.y[k])), y1 = py(std::min(0.0, s.y[k]));
        svg += fmt::format("<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" height=\"{:.1f}\" fill=\"{}\"/>\n", px(x0),
                           y0, px(x0 + group) - px(x0), y1 - y0, s.color);
      }
      ++bar_series;
    }
  }
  svg += "</g>\n";
  for (const PlotText& t : plot.texts)
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"{}\" fill=\"{}\" font-weight=\"bold\">{}</text>\n",
                       px(t.x), py(t.y) + t.dy_px, t.anchor, t.color, escape(t.text));

  // Legend in one row above the plot, right-aligned, so it never hides data.
  double lx = left + pw;
  for (auto it = plot.series.rbegin(); it != plot.series.rend(); ++it) {
    if (it->label.empty()) continue;
    lx -= 30.0 + 7.5 * static_cast<double>(it->label.size());
    svg += fmt::format("<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"14\" height=\"10\" fill=\"{}\"/>\n", lx, top - 19,
                       it->color);
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\">{}</text>\n", lx + 19, top - 9, escape(it->label));
  }
  svg += "</svg>\n";
  return svg;
}

void write_svg(const std::filesystem::path& path, const Plot& plot) {
  std::ofstream out(path);
  out << render_svg(plot);
  if (!out) throw InputError(path.string(), "", "cannot write the plot");
}

}  // namespace adit::products
