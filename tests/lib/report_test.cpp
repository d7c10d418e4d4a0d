// Error statistics against hand-computed values and a large normal sample;
// histogram counts; the equal-area map against its closed form; the SVG and
// PLY outputs' content.
#include <cmath>
#include <random>
#include <map>
#include <regex>
#include <sstream>

#include <gtest/gtest.h>
#include <zlib.h>

#include "articula/core/error.hpp"
#include "articula/report/azimuthal_map.hpp"
#include "articula/report/diverging_colour.hpp"
#include "articula/report/error_map_svg.hpp"
#include "articula/report/error_statistics.hpp"
#include "articula/report/line_chart_svg.hpp"
#include "articula/report/histogram_svg.hpp"
#include "articula/report/ply_writers.hpp"
#include "articula/report/slice_image.hpp"
#include "articula/report/study_svg.hpp"

namespace {

using namespace articula::report;

TEST(ErrorStatistics, HandComputedValues) {
  Eigen::VectorXd d(4);
  d << -1.0, 0.5, 2.0, -0.5;
  const ErrorStatistics s = errorStatistics("sphere", d);
  EXPECT_EQ(s.n_points, 4);
  EXPECT_DOUBLE_EQ(s.min_mm, -1.0);
  EXPECT_DOUBLE_EQ(s.max_mm, 2.0);
  EXPECT_DOUBLE_EQ(s.mean_abs_mm, 1.0);
  EXPECT_DOUBLE_EQ(s.sse_mm2, 5.5);
  EXPECT_DOUBLE_EQ(s.rms_mm, std::sqrt(5.5 / 4));
  EXPECT_DOUBLE_EQ(s.gauss_mu_mm, 0.25);
  // |d| = 1, .5, 2, .5: deviations 0, -.5, 1, -.5 -> 1.5 / 3.
  EXPECT_DOUBLE_EQ(s.std_abs_mm, std::sqrt(0.5));
  EXPECT_DOUBLE_EQ(s.gauss_sigma_mm, std::sqrt((1.5625 + 0.0625 + 3.0625 + 0.5625) / 3.0));
  EXPECT_THROW(errorStatistics("x", Eigen::VectorXd()), articula::InputError);
}

TEST(ErrorStatistics, GaussianRecoversANormalSample) {
  std::mt19937 rng(1);
  std::normal_distribution<double> normal(-0.03, 0.6);
  Eigen::VectorXd d(200000);
  for (Eigen::Index i = 0; i < d.size(); ++i) d[i] = normal(rng);
  const ErrorStatistics s = errorStatistics("ovoid", d);
  EXPECT_NEAR(s.gauss_mu_mm, -0.03, 0.005);
  EXPECT_NEAR(s.gauss_sigma_mm, 0.6, 0.005);
  // E|d| of a normal with small mean: sigma sqrt(2/pi).
  EXPECT_NEAR(s.mean_abs_mm, 0.6 * std::sqrt(2.0 / M_PI), 0.005);
}

TEST(Histogram, CountsAndClamping) {
  Eigen::VectorXd d(6);
  d << 0.0, 0.1, 0.9, 1.0, -5.0, 5.0;
  const Histogram h = histogram(d, 0.0, 1.0, 2);
  ASSERT_EQ(h.counts.size(), 2u);
  EXPECT_EQ(h.counts[0], 3);  // 0, 0.1, -5 (clamped)
  EXPECT_EQ(h.counts[1], 3);  // 0.9, 1.0, 5 (clamped)
  EXPECT_DOUBLE_EQ(h.bin_width, 0.5);
}

TEST(HistogramSvg, HasAxesUnitsLegendAndCurves) {
  Eigen::VectorXd a = Eigen::VectorXd::LinSpaced(100, -1.0, 1.0), b = 0.5 * a;
  const std::string svg = histogramSvg({{"sphere", a, 0.0, 0.58}, {"superovoid", b, -1e-5, 0.29}}, "femoral head");
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  EXPECT_NE(svg.find("signed Euclidean distance (mm)"), std::string::npos);
  EXPECT_NE(svg.find("number of points per bin"), std::string::npos);
  // A mean that rounds to zero reads 0.000, not -0.000.
  EXPECT_NE(svg.find("superovoid (\u03bc 0.000, \u03c3 0.290 mm)"), std::string::npos) << svg;
  size_t curves = 0;
  for (size_t p = svg.find("<polyline"); p != std::string::npos; p = svg.find("<polyline", p + 1)) ++curves;
  EXPECT_EQ(curves, 2u);
}

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

// Dots per colour over the whole document: stroke colour -> number of "M x y h0".
std::map<std::string, size_t> dotsByColour(const std::string& svg) {
  std::map<std::string, size_t> dots;
  const std::regex path("<path class=\"pts\" stroke=\"(#[0-9a-f]{6})\" d=\"([^\"]*)\"");
  for (std::sregex_iterator it(svg.begin(), svg.end(), path), end; it != end; ++it)
    dots[(*it)[1]] += count((*it)[2], "h0");
  return dots;
}

// A cap of a sphere (radius 20 about c) around +L: the apex and rings at 60
// and 90 degrees, symmetric so that the mean direction is +L.
Eigen::MatrixX3d capAboutLeft(const Eigen::Vector3d& c) {
  Eigen::MatrixX3d p(17, 3);
  p.row(0) = (c + Eigen::Vector3d(20, 0, 0)).transpose();
  for (int k = 0; k < 8; ++k) {
    const double phi = k * M_PI / 4;
    for (int ring = 0; ring < 2; ++ring) {
      const double theta = ring ? M_PI / 2 : M_PI / 3;
      const Eigen::Vector3d u(std::cos(theta), std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi));
      p.row(1 + 2 * k + ring) = (c + 20 * u).transpose();
    }
  }
  return p;
}

TEST(AzimuthalMap, EqualAreaRadiiAndOrientation) {
  const Eigen::Vector3d c(-80, 12, 30);
  const AzimuthalMap map = azimuthalEqualArea(capAboutLeft(c), c);
  EXPECT_NEAR((map.axis - Eigen::Vector3d::UnitX()).norm(), 0.0, 1e-12);
  EXPECT_NEAR((map.up - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-12);     // S up
  EXPECT_NEAR((map.right - Eigen::Vector3d::UnitY()).norm(), 0.0, 1e-12);  // P right, seen from the left
  EXPECT_NEAR(map.radius_mm, 20.0, 1e-12);
  EXPECT_NEAR(map.xy.row(0).norm(), 0.0, 1e-12);
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector2d at60 = map.xy.row(1 + 2 * k), at90 = map.xy.row(2 + 2 * k);
    EXPECT_NEAR(at60.norm(), 2 * 20 * std::sin(M_PI / 6), 1e-9);  // 2 R sin(theta/2)
    EXPECT_NEAR(at90.norm(), 20 * std::sqrt(2.0), 1e-9);
    EXPECT_NEAR(std::atan2(at90.y(), at90.x()), std::remainder(k * M_PI / 4, 2 * M_PI), 1e-9);
  }
  // Points all round the centre: no main direction; the axis is S and up is P.
  Eigen::MatrixX3d round(6, 3);
  round << 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1;
  const AzimuthalMap all = azimuthalEqualArea(round, Eigen::Vector3d::Zero());
  EXPECT_EQ(all.axis, Eigen::Vector3d::UnitZ());
  EXPECT_NEAR((all.up - Eigen::Vector3d::UnitY()).norm(), 0.0, 1e-12);
  EXPECT_NEAR(all.xy.row(5).norm(), 2.0, 1e-12);  // opposite the axis: 2R
}

TEST(DivergingColour, StopsMidpointsAndClamping) {
  EXPECT_EQ(divergingColour(-1.0), "#b2182b");
  EXPECT_EQ(divergingColour(-5.0), "#b2182b");
  EXPECT_EQ(divergingColour(0.0), "#dddddd");
  EXPECT_EQ(divergingColour(0.5), "#67a9cf");
  EXPECT_EQ(divergingColour(1.0), "#2166ac");
  EXPECT_EQ(divergingColour(0.25), "#a2c3d6");  // halfway between #dddddd and #67a9cf
}

TEST(ErrorMapSvg, OneDotPerPointColouredByDistance) {
  const Eigen::Vector3d c(10, -20, 5);
  const AzimuthalMap map = azimuthalEqualArea(capAboutLeft(c), c);
  Eigen::VectorXd inside_out(17), small(17);
  for (int i = 0; i < 17; ++i) {
    inside_out[i] = i < 5 ? -0.5 : i < 11 ? 0.0 : 0.7;  // 0.7 is beyond the limit: the end colour
    small[i] = 0.05;
  }
  ErrorMapOptions options;
  options.limit_mm = 0.5;
  options.highlight = "superovoid";
  const std::string svg = errorMapSvg(map, {{"sphere", inside_out}, {"superovoid", small}}, options, "head & neck");
  EXPECT_EQ(count(svg, "<g class=\"panel\">"), 2u);
  EXPECT_EQ(count(svg, "h0"), 34u);  // every point of both panels
  const auto dots = dotsByColour(svg);
  EXPECT_EQ(dots.at("#b2182b"), 5u);
  EXPECT_EQ(dots.at("#dddddd"), 6u);
  EXPECT_EQ(dots.at("#2166ac"), 6u);
  EXPECT_EQ(dots.at(divergingColour(0.1)), 17u);  // 0.05 mm = one step of limit / 10
  EXPECT_NE(svg.find("data-limit-mm=\"0.5\""), std::string::npos);
  EXPECT_NE(svg.find(">-0.5</text>"), std::string::npos);
  EXPECT_NE(svg.find(">0.5</text>"), std::string::npos);
  EXPECT_NE(svg.find("signed distance (mm)"), std::string::npos);
  EXPECT_NE(svg.find("superovoid: RMS 0.05 mm (least RMS)"), std::string::npos);
  EXPECT_NE(svg.find("x (mm) \u2192 P"), std::string::npos);
  EXPECT_NE(svg.find("y (mm) \u2192 S"), std::string::npos);
  EXPECT_NE(svg.find("LPS"), std::string::npos);
  EXPECT_NE(svg.find("head &amp; neck"), std::string::npos);

  // Automatic limit: the 98th percentile of |d| (0.98 of 0.01 .. 1.00) rounded up.
  Eigen::VectorXd ramp = Eigen::VectorXd::LinSpaced(100, 0.01, 1.0);
  Eigen::MatrixX3d line(100, 3);
  for (int i = 0; i < 100; ++i) line.row(i) << 20, i * 0.1, 0;
  const AzimuthalMap line_map = azimuthalEqualArea(line, Eigen::Vector3d::Zero());
  const std::string auto_svg = errorMapSvg(line_map, {{"sphere", -ramp}}, ErrorMapOptions(), "");
  EXPECT_NE(auto_svg.find("data-limit-mm=\"1\""), std::string::npos);
  // Subsampling: every 4th of 100 points when at most 30 are drawn.
  ErrorMapOptions sparse;
  sparse.max_points = 30;
  EXPECT_EQ(count(errorMapSvg(line_map, {{"sphere", ramp}}, sparse, ""), "h0"), 25u);

  EXPECT_THROW(errorMapSvg(map, {{"sphere", ramp}}, options, ""), articula::InputError);
  EXPECT_THROW(errorMapSvg(map, {}, options, ""), articula::InputError);
  sparse.max_points = 0;
  EXPECT_THROW(errorMapSvg(line_map, {{"sphere", ramp}}, sparse, ""), articula::InvalidParameter);
}

TEST(StudySvg, PairedLinesDotsAndMeans) {
  StudyRms study;
  study.subjects = {"s01", "s02", "s03"};
  study.models = {"sphere", "ellipsoid", "superovoid"};
  study.rms_mm.resize(3, 3);
  study.rms_mm << 0.4, 0.2, 0.1,  //
      0.3, 0.25, 0.2,             //
      0.2, 0.1, NAN;
  const std::string svg = studyRmsSvg(study, "study");
  EXPECT_EQ(count(svg, "<g class=\"subject\">"), 3u);
  EXPECT_EQ(count(svg, "</circle>"), 8u);  // one dot per finite value
  EXPECT_EQ(count(svg, "fill=\"#555555\"><title>"), 3u);  // each subject's least RMS
  EXPECT_NE(svg.find("<title>s01 superovoid: 0.1 mm</title>"), std::string::npos);
  EXPECT_NE(svg.find("<title>s03 ellipsoid: 0.1 mm</title>"), std::string::npos);
  EXPECT_NE(svg.find("<title>mean sphere: 0.3 mm (3 subjects)</title>"), std::string::npos);
  EXPECT_NE(svg.find("<title>mean ellipsoid: 0.183 mm (3 subjects)</title>"), std::string::npos);
  EXPECT_NE(svg.find("<title>mean superovoid: 0.15 mm (2 subjects)</title>"), std::string::npos);
  EXPECT_NE(svg.find("RMS of the signed distances (mm)"), std::string::npos);
  EXPECT_EQ(count(svg, "class=\"mean\""), 3u);
  // s03 has no superovoid: its line ends at the ellipsoid (one M, one L).
  const std::regex line("<g class=\"subject\">\n<path fill=\"none\" stroke=\"#9a9a9a\" d=\"([^\"]*)\"");
  std::vector<std::string> d;
  for (std::sregex_iterator it(svg.begin(), svg.end(), line), end; it != end; ++it) d.push_back((*it)[1]);
  ASSERT_EQ(d.size(), 3u);
  EXPECT_EQ(count(d[0], "L"), 2u);
  EXPECT_EQ(count(d[2], "L"), 1u);
  study.rms_mm.resize(2, 3);
  EXPECT_THROW(studyRmsSvg(study, ""), articula::InputError);
}

TEST(PlyWriters, ColoursFollowTheBand) {
  Eigen::MatrixX3d p = Eigen::MatrixX3d::Zero(3, 3);
  Eigen::VectorXd d(3);
  d << -0.5, 0.05, 0.5;
  const std::string ply = colouredPointsPly(p, d, 0.1, "test");
  EXPECT_NE(ply.find("element vertex 3"), std::string::npos);
  EXPECT_NE(ply.find("0 0 0 255 0 0 -0.5"), std::string::npos);
  EXPECT_NE(ply.find("0 0 0 0 200 0 0.05"), std::string::npos);
  EXPECT_NE(ply.find("0 0 0 0 0 255 0.5"), std::string::npos);
}

TEST(SummaryCsv, HeaderMatchesTheContract) {
  const std::string csv = summaryCsv({});
  EXPECT_EQ(csv, "model,n_points,min_mm,max_mm,mean_abs_mm,std_abs_mm,rms_mm,gauss_mu_mm,gauss_sigma_mm,sse_mm2\n");
}

// Line charts: the points land where the axes put them (linear and log),
// a NaN breaks a line in two, and mismatched series are refused.
TEST(LineChart, PointsFollowTheAxesAndNaNBreaksTheLine) {
  const auto polylines = [](const std::string& svg) {
    std::vector<std::vector<std::pair<double, double>>> lines;
    const std::regex polyline("points=\"([^\"]*)\"");
    for (auto it = std::sregex_iterator(svg.begin(), svg.end(), polyline); it != std::sregex_iterator(); ++it) {
      std::vector<std::pair<double, double>> line;
      std::istringstream in((*it)[1].str());
      std::string pair;
      while (in >> pair) {
        const auto comma = pair.find(',');
        line.emplace_back(std::stod(pair.substr(0, comma)), std::stod(pair.substr(comma + 1)));
      }
      lines.push_back(line);
    }
    return lines;
  };
  const std::string linear = articula::report::lineChartSvg({{"z", {0, 1, 2, 3}, {0, 1, NAN, 3}}}, {"t", "time (s)", "z (m)"});
  const auto lines = polylines(linear);
  ASSERT_EQ(lines.size(), 2u);
  ASSERT_EQ(lines[0].size(), 2u);
  ASSERT_EQ(lines[1].size(), 1u);
  // Equal steps in x and y are equal steps on the page (y grows upwards).
  const double dx = lines[0][1].first - lines[0][0].first, dy = lines[0][0].second - lines[0][1].second;
  EXPECT_NEAR(lines[1][0].first - lines[0][0].first, 3 * dx, 0.01);  // page units, 6 digits
  EXPECT_NEAR(lines[0][0].second - lines[1][0].second, 3 * dy, 0.01);
  EXPECT_GT(dy, 0);
  EXPECT_NE(linear.find("time (s)"), std::string::npos);
  // Log scale: 1e-4, 1e-3, 1e-2 are equally spaced.
  articula::report::LineChart log_chart{"steps", "time (s)", "step (s)", true};
  const auto log_lines = polylines(articula::report::lineChartSvg({{"h", {0, 1, 2}, {1e-4, 1e-3, 1e-2}}}, log_chart));
  ASSERT_EQ(log_lines.size(), 1u);
  EXPECT_NEAR(log_lines[0][0].second - log_lines[0][1].second, log_lines[0][1].second - log_lines[0][2].second, 0.01);
  EXPECT_THROW(articula::report::lineChartSvg({{"bad", {0, 1}, {0}}}, {}), articula::InvalidParameter);
}

}  // namespace

// The report's slice images: the PNG's rows come back from its deflate
// stream byte for byte, base64 matches RFC 4648's examples, and the contour
// of a sampled circle lies on the circle.
TEST(SliceImage, PngBase64AndContours) {
  const int w = 7, h = 5;
  std::vector<std::uint8_t> pixels(w * h);
  for (int i = 0; i < w * h; ++i) pixels[static_cast<size_t>(i)] = static_cast<std::uint8_t>(37 * i);
  const std::string png = articula::report::greyPng(pixels, w, h);
  ASSERT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  const auto u32 = [&](size_t at) {
    return static_cast<uint32_t>(static_cast<unsigned char>(png[at])) << 24 |
           static_cast<uint32_t>(static_cast<unsigned char>(png[at + 1])) << 16 |
           static_cast<uint32_t>(static_cast<unsigned char>(png[at + 2])) << 8 | static_cast<unsigned char>(png[at + 3]);
  };
  EXPECT_EQ(png.substr(12, 4), "IHDR");
  EXPECT_EQ(u32(16), static_cast<uint32_t>(w));
  EXPECT_EQ(u32(20), static_cast<uint32_t>(h));
  const size_t idat = png.find("IDAT");
  ASSERT_NE(idat, std::string::npos);
  std::string raw(static_cast<size_t>((w + 1) * h), '\0');
  uLongf raw_size = static_cast<uLongf>(raw.size());
  ASSERT_EQ(uncompress(reinterpret_cast<Bytef*>(raw.data()), &raw_size,
                       reinterpret_cast<const Bytef*>(png.data() + idat + 4), u32(idat - 4)),
            Z_OK);
  for (int r = 0; r < h; ++r) {
    EXPECT_EQ(raw[static_cast<size_t>(r * (w + 1))], '\0');  // filter type none
    for (int c = 0; c < w; ++c)
      EXPECT_EQ(static_cast<std::uint8_t>(raw[static_cast<size_t>(r * (w + 1) + 1 + c)]), pixels[static_cast<size_t>(r * w + c)]);
  }
  EXPECT_EQ(articula::report::base64("Man"), "TWFu");
  EXPECT_EQ(articula::report::base64("Ma"), "TWE=");
  EXPECT_EQ(articula::report::base64("M"), "TQ==");
  EXPECT_EQ(articula::report::base64("foobar"), "Zm9vYmFy");

  const int n = 41;
  const double radius = 12.3;
  Eigen::MatrixXd field(n, n);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) field(r, c) = std::hypot(c - 20.0, r - 20.0) - radius;
  const auto segments = articula::report::contourSegments(field, 0.0);
  EXPECT_GT(segments.size(), 60u);
  for (const auto& s : segments)
    for (const Eigen::Vector2d& p : {s.a, s.b}) EXPECT_NEAR((p - Eigen::Vector2d(20, 20)).norm(), radius, 0.05);
}
