// Error statistics against hand-computed values and a large normal sample;
// histogram counts; the SVG and PLY outputs' content.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "articula/core/error.hpp"
#include "articula/report/error_statistics.hpp"
#include "articula/report/histogram_svg.hpp"
#include "articula/report/ply_writers.hpp"

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
  const std::string svg = histogramSvg({{"sphere", a, 0.0, 0.58}, {"superovoid", b, 0.0, 0.29}}, "femoral head");
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  EXPECT_NE(svg.find("signed Euclidean distance (mm)"), std::string::npos);
  EXPECT_NE(svg.find("number of points per bin"), std::string::npos);
  EXPECT_NE(svg.find("superovoid (mu"), std::string::npos);
  size_t curves = 0;
  for (size_t p = svg.find("<polyline"); p != std::string::npos; p = svg.find("<polyline", p + 1)) ++curves;
  EXPECT_EQ(curves, 2u);
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

}  // namespace
