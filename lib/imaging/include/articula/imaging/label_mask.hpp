#pragma once
// An outside segmentation as the way to the head where the search cannot
// go alone: a label map in the CT's grid (TotalSegmentator's femur or
// humerus, a 3D Slicer segmentation exported as a label map) keeps only its
// bone in the CT, and the head is then cut from that bone by the usual
// search. The surface is still moved onto the unmasked CT's edges later.
#include <filesystem>
#include <optional>

#include "articula/imaging/image.hpp"

namespace articula::imaging {

/// The CT with every voxel outside the label set to air (-1000 HU): outside
/// `value` when given, else outside every non-zero voxel. Throws InputError
/// naming both grids when the label's size, spacing, origin or orientation
/// differs from the CT's (beyond a hundredth of a voxel and 1e-4 in
/// direction), and when no voxel holds the label.
Volume keepLabelledBone(const Volume& ct, const std::filesystem::path& label_file, std::optional<int> value);

}  // namespace articula::imaging
