#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "adit/products/svg_plot.hpp"

namespace adit::products {
namespace {

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(SvgPlot, LinesEscapedTextAndEqualAxes) {
  Plot plot{"A < B & C", "x (m)", "y (m)", {}, {}, true};
  plot.series.push_back({"ref", "#000", SeriesStyle::line, {0, 10, 10}, {0, 0, 1}});
  const std::string svg = render_svg(plot);
  EXPECT_EQ(svg.rfind("<svg ", 0), 0u);
  EXPECT_NE(svg.find("A &lt; B &amp; C"), std::string::npos);
  EXPECT_EQ(count(svg, "<polyline"), 1u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
}

TEST(SvgPlot, BarsSkipMissingValuesAndHandleFlatData) {
  Plot plot{"t", "target", "mm", {}, {"A", "B", "C"}};
  plot.series.push_back({"fit", "#00f", SeriesStyle::bars, {}, {1.0, std::numeric_limits<double>::quiet_NaN(), 3.0}});
  const std::string svg = render_svg(plot);
  // Background, frame, legend swatch and the two finite bars.
  EXPECT_EQ(count(svg, "<rect"), 3u + 2u + 1u);  // + the clip rectangle
  EXPECT_EQ(svg.find("nan"), std::string::npos);
  Plot flat{"flat", "x", "y", {}, {}};
  flat.series.push_back({"", "#000", SeriesStyle::points, {1, 1}, {2, 2}});
  EXPECT_EQ(render_svg(flat).find("nan"), std::string::npos);
}

TEST(SvgPlot, TinySpanFarFromZeroStillEnds) {
  // Survey coordinates (1e9 m) moving by micrometres: ticks are bounded.
  Plot plot{"t", "x", "y", {}, {}, true};
  plot.series.push_back({"", "#000", SeriesStyle::line, {1e9, 1e9 + 1e-6}, {2e9, 2e9 + 2e-6}});
  const std::string svg = render_svg(plot);
  EXPECT_LT(count(svg, "<line"), 200u);
}

}  // namespace
}  // namespace adit::products
