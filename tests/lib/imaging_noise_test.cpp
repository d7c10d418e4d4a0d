// The CT's noise measured voxel to voxel, and the smoothed copy a noisy CT
// is segmented on: against volumes of known noise.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "articula/imaging/noise.hpp"

namespace articula {
namespace {

// Soft tissue (40 HU), a bone slab (1200 HU) and air (-1000 HU) side by
// side along x, with white Gaussian noise of `noise_hu`.
imaging::Volume tissuesWithNoise(double noise_hu, unsigned seed) {
  imaging::Volume v;
  v.geometry.size = Eigen::Vector3i(90, 70, 24);
  v.geometry.spacing = Eigen::Vector3d(0.7, 0.7, 1.5);
  v.geometry.origin = Eigen::Vector3d(-30, 12, 80);
  v.voxels.resize(static_cast<size_t>(v.geometry.voxelCount()));
  std::mt19937 random(seed);
  std::normal_distribution<float> noise(0.0f, static_cast<float>(noise_hu));
  for (int k = 0; k < v.geometry.size[2]; ++k)
    for (int j = 0; j < v.geometry.size[1]; ++j)
      for (int i = 0; i < v.geometry.size[0]; ++i) {
        const float tissue = i < 40 ? 40.0f : i < 60 ? 1200.0f : -1000.0f;
        v.at(i, j, k) = tissue + (noise_hu > 0 ? noise(random) : 0.0f);
      }
  return v;
}

TEST(ImagingNoise, MeasuresWhiteNoiseInSoftTissueNotTheEdges) {
  for (const double sigma : {20.0, 60.0, 100.0}) {
    SCOPED_TRACE(sigma);
    EXPECT_NEAR(imaging::noiseHu(tissuesWithNoise(sigma, 3)), sigma, 0.06 * sigma);
  }
  // Without noise the edges alone: none.
  EXPECT_LT(imaging::noiseHu(tissuesWithNoise(0, 3)), 1e-6);
  // No soft tissue at all: nothing to measure.
  imaging::Volume bone = tissuesWithNoise(0, 3);
  for (float& hu : bone.voxels) hu = 1500;
  EXPECT_EQ(imaging::noiseHu(bone), 0.0);
}

TEST(ImagingNoise, TheSmoothedCopyKeepsTheGridAndTheLevels) {
  const imaging::Volume noisy = tissuesWithNoise(100, 5);
  const imaging::Volume calm = imaging::smoothed(noisy, 0.7);
  EXPECT_EQ(calm.geometry.size, noisy.geometry.size);
  EXPECT_LT((calm.geometry.spacing - noisy.geometry.spacing).norm(), 1e-6);
  EXPECT_LT((calm.geometry.origin - noisy.geometry.origin).norm(), 1e-6);
  EXPECT_LT((calm.geometry.direction - noisy.geometry.direction).norm(), 1e-9);
  // A Gaussian of one in-plane voxel leaves under a third of white noise
  // (about a fifth across slices twice as long), and the soft tissue's level.
  EXPECT_LT(imaging::noiseHu(calm), 100.0 / 3);
  double sum = 0;
  int n = 0;
  for (int k = 0; k < 24; ++k)
    for (int j = 0; j < 70; ++j)
      for (int i = 5; i < 35; ++i) sum += calm.at(i, j, k), ++n;
  EXPECT_NEAR(sum / n, 40.0, 2.0);
}

}  // namespace
}  // namespace articula
