// The blurred-cortex model: on a flat cortex of known thickness, blurred by a
// known Gaussian and averaged over each voxel (closed form), with CT noise,
// the point-spread is estimated from the CT alone and the model puts the
// surface where it is, also where the cortex is thin enough for the steepest
// fall to lie a fifth of a millimetre outside.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "articula/imaging/cortex_edge.hpp"
#include "articula/imaging/edges.hpp"

namespace articula {
namespace {

double Phi(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }

/// A flat cortex whose outer surface is the plane n . x = surface (the bone
/// on its negative side), tilted against the grid so that the lines across
/// it meet the voxels at every phase.
struct FlatCortex {
  double soft = 40, cortical = 700, cancellous = 190, thickness = 0.8, sigma = 0.5, spacing = 0.7, noise = 20;
  double surface = 0.23;
  Eigen::Vector3d n = Eigen::Vector3d(1, 0.21, -0.13).normalized();

  /// The blurred profile at signed distance d beyond the surface (closed form).
  double blurred(double d) const {
    return soft + (cortical - soft) * Phi(-d / sigma) - (cortical - cancellous) * Phi(-(d + thickness) / sigma);
  }
  /// A voxel: the blurred profile averaged over 5 x 5 x 5 points of it (partial volume).
  double voxel(const Eigen::Vector3d& centre) const {
    constexpr int kSub = 5;
    double sum = 0;
    for (int c = 0; c < kSub * kSub * kSub; ++c) {
      const Eigen::Vector3d offset((c % kSub + 0.5) / kSub - 0.5, (c / kSub % kSub + 0.5) / kSub - 0.5,
                                   (c / (kSub * kSub) + 0.5) / kSub - 0.5);
      sum += blurred(n.dot(centre + spacing * offset) - surface);
    }
    return sum / (kSub * kSub * kSub);
  }
  imaging::Volume volume(unsigned seed) const {
    imaging::Volume v;
    v.geometry.size = Eigen::Vector3i(24, 40, 40);
    v.geometry.spacing = Eigen::Vector3d::Constant(spacing);
    v.geometry.origin = Eigen::Vector3d(-11.5 * spacing, -19.5 * spacing, -19.5 * spacing);
    v.voxels.resize(static_cast<size_t>(v.geometry.voxelCount()));
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise_hu(0.0, noise);
    for (int k = 0; k < 40; ++k)
      for (int j = 0; j < 40; ++j)
        for (int i = 0; i < 24; ++i)
          v.at(i, j, k) = static_cast<float>(voxel(v.geometry.toPhysical(Eigen::Vector3d(i, j, k))) + noise_hu(rng));
    return v;
  }
};

struct Estimate {
  imaging::PointSpread spread;
  double mean_steepest = 0, mean_model = 0;
  int found = 0;
};

/// Lines across the plane at many places, started on the steepest fall as
/// the mesh stage starts them; the point-spread estimated over them; each
/// line's surface by the model with it.
Estimate measure(const FlatCortex& c, unsigned seed) {
  const imaging::Volume v = c.volume(seed);
  const Eigen::Vector3d u = c.n;
  std::vector<imaging::LineVoxels> lines;
  std::vector<double> starts;
  Estimate e;
  for (double y = -8; y <= 8; y += 1.0)
    for (double z = -8; z <= 8; z += 1.0) {
      const Eigen::Vector3d p(0, y + 0.13, z - 0.29);
      const Eigen::Vector3d x0 = p - (c.n.dot(p) - c.surface) * c.n;  // on the surface
      const imaging::Edge edge = imaging::locateEdge(v, x0, u, {});
      if (!edge.found) continue;
      starts.push_back(edge.offset_mm);
      lines.push_back(imaging::voxelsAboutLine(v, x0 + edge.offset_mm * u, u, -imaging::kCortexInwardMm,
                                               imaging::kCortexOutwardMm, imaging::lineRadiusFor(v.geometry)));
    }
  e.spread = imaging::estimatePointSpread(lines);
  for (size_t i = 0; i < lines.size(); ++i) {
    e.mean_steepest += starts[i] / static_cast<double>(lines.size());
    const imaging::CortexFit f = imaging::fitCortex(lines[i], 0.0, e.spread.sigma_mm);
    if (!f.found) continue;
    e.mean_model += starts[i] + f.offset_mm;
    ++e.found;
  }
  e.mean_model /= std::max(e.found, 1);
  return e;
}

TEST(CortexEdge, PointSpreadAndSurfaceOfAThinCortexFromTheCtAlone) {
  FlatCortex thin;
  const Estimate e = measure(thin, 7);
  ASSERT_TRUE(e.spread.found);
  EXPECT_NEAR(e.spread.sigma_mm, thin.sigma, 0.03);
  EXPECT_GT(e.found, 250);
  EXPECT_GT(e.mean_steepest - 0.0, 0.12);  // the steepest fall's outward pull ...
  EXPECT_NEAR(e.mean_model, 0.0, 0.05);    // ... which the model does not have
}

TEST(CortexEdge, ThickCortexAndCoarseVoxels) {
  FlatCortex thick;
  thick.cortical = 1300;
  thick.cancellous = 350;
  thick.thickness = 2.0;
  thick.spacing = 1.0;
  thick.sigma = 0.7;
  const Estimate e = measure(thick, 8);
  ASSERT_TRUE(e.spread.found);
  EXPECT_NEAR(e.spread.sigma_mm, thick.sigma, 0.05);
  EXPECT_NEAR(e.mean_model, 0.0, 0.05);
}

TEST(CortexEdge, NothingFoundWithoutABrightLayerOrVoxels) {
  FlatCortex flat;
  flat.cortical = flat.soft + 50;
  flat.cancellous = flat.soft + 50;
  const imaging::Volume v = flat.volume(3);
  const auto line = imaging::voxelsAboutLine(v, flat.surface * flat.n, flat.n, -3.5, 2.5, 0.8);
  EXPECT_FALSE(imaging::fitCortex(line, 0.0, 0.5).found);
  EXPECT_FALSE(imaging::fitCortex(imaging::LineVoxels{}, 0.0, 0.5).found);
  EXPECT_FALSE(imaging::estimatePointSpread({line}).found);  // one line is not enough
}

}  // namespace
}  // namespace articula
