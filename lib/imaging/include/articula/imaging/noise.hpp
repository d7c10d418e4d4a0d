#pragma once
// How noisy a CT is, and the smoothed copy a noisy one is segmented on.
//
// At low dose, and more so with a sharp (bone) reconstruction kernel, the
// noise in soft tissue reaches 80-150 HU: falls of an edge's size then lie
// everywhere inside the cancellous bone, the head search's rays stop on them
// and the HU window's mask is speckled. The segment stage works on a copy
// smoothed by about a voxel; the mesh stage still places the surface on the
// CT's own voxels.
#include "articula/imaging/image.hpp"

namespace articula::imaging {

/// Above this noise (HU, noiseHu) the head is segmented on a smoothed copy.
/// Phantoms at 20 HU measure 20 HU (38-40 under a sharp kernel), the real
/// CTs of the shared data 9-21 HU, low-dose phantoms at 60 and 100 HU 60 and 99.
constexpr double kSmoothSegmentationAboveNoiseHu = 45.0;

/// The noise's standard deviation (HU) as seen voxel to voxel: each soft-
/// tissue voxel (it and its two neighbours along x, or along y, within -300
/// to 300 HU) against their mean, 1.4826 x the median absolute departure /
/// sqrt(1.5) (white noise's scale). Edges are too few to move the median;
/// noise correlated over voxels measures lower. 0 with no soft tissue.
double noiseHu(const Volume& volume);

/// The volume smoothed by a Gaussian of `sigma_mm` (standard deviation, the
/// same in millimetres along every axis).
Volume smoothed(const Volume& volume, double sigma_mm);

}  // namespace articula::imaging
