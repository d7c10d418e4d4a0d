#include "articula/imaging/noise.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <itkDiscreteGaussianImageFilter.h>

#include "itk_bridge.hpp"

namespace articula::imaging {

namespace {

constexpr float kSoftTissueLowHu = -300, kSoftTissueHighHu = 300;
constexpr size_t kMaxSamples = 2'000'000;  // enough for the median; a clinical CT holds 10^8 voxels

double medianOf(std::vector<float>& values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace

// Hand-written: ITK's NoiseImageFilter gives each voxel its neighbourhood's
// spread, which edges and texture swell; one robust figure for the whole CT
// is the median's, over soft tissue only.
double noiseHu(const Volume& volume) {
  const ImageGeometry& g = volume.geometry;
  const auto soft = [](float hu) { return hu >= kSoftTissueLowHu && hu <= kSoftTissueHighHu; };
  // Every slice_step-th slice, so that about kMaxSamples triples are looked at.
  const double voxels = static_cast<double>(g.voxelCount());
  const int slice_step = std::max(1, static_cast<int>(std::floor(voxels / kMaxSamples)));
  std::vector<float> departures;
  for (int k = 0; k < g.size[2]; k += slice_step)
    for (int j = 1; j + 1 < g.size[1]; ++j)
      for (int i = 1; i + 1 < g.size[0]; ++i) {
        const float at = volume.at(i, j, k);
        if (!soft(at)) continue;
        const float x0 = volume.at(i - 1, j, k), x1 = volume.at(i + 1, j, k);
        const float y0 = volume.at(i, j - 1, k), y1 = volume.at(i, j + 1, k);
        if (soft(x0) && soft(x1)) departures.push_back(at - 0.5f * (x0 + x1));
        if (soft(y0) && soft(y1)) departures.push_back(at - 0.5f * (y0 + y1));
      }
  if (departures.size() < 1000) return 0;
  const double centre = medianOf(departures);
  for (float& d : departures) d = static_cast<float>(std::abs(d - centre));
  // A white noise of deviation s gives departures of deviation s sqrt(1 + 1/2).
  return 1.4826 * medianOf(departures) / std::sqrt(1.5);
}

Volume smoothed(const Volume& volume, double sigma_mm) {
  using FloatImage = itk::Image<float, 3>;
  auto filter = itk::DiscreteGaussianImageFilter<FloatImage, FloatImage>::New();
  filter->SetInput(toItk(volume));
  filter->SetVariance(sigma_mm * sigma_mm);  // in physical units (the filter uses the image's spacing)
  filter->SetMaximumKernelWidth(64);
  filter->Update();
  return fromItk<float>(filter->GetOutput());
}

}  // namespace articula::imaging
