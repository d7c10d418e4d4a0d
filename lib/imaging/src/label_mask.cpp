#include "articula/imaging/label_mask.hpp"

#include <cmath>
#include <sstream>

#include "articula/core/error.hpp"
#include "itk_bridge.hpp"

namespace articula::imaging {

namespace {

std::string describe(const ImageGeometry& g) {
  std::ostringstream text;
  text.precision(6);
  text << g.size[0] << "x" << g.size[1] << "x" << g.size[2] << " voxels of " << g.spacing[0] << " x " << g.spacing[1]
       << " x " << g.spacing[2] << " mm, origin (" << g.origin[0] << ", " << g.origin[1] << ", " << g.origin[2]
       << ") mm, direction columns (" << g.direction(0, 0) << " " << g.direction(1, 0) << " " << g.direction(2, 0)
       << "), (" << g.direction(0, 1) << " " << g.direction(1, 1) << " " << g.direction(2, 1) << "), ("
       << g.direction(0, 2) << " " << g.direction(1, 2) << " " << g.direction(2, 2) << ")";
  return text.str();
}

bool sameGrid(const ImageGeometry& a, const ImageGeometry& b) {
  const double voxel = a.spacing.minCoeff();
  return a.size == b.size && ((a.spacing - b.spacing).cwiseAbs().array() <= 0.01 * a.spacing.array()).all() &&
         (a.origin - b.origin).norm() <= 0.01 * voxel && (a.direction - b.direction).cwiseAbs().maxCoeff() <= 1e-4;
}

}  // namespace

Volume keepLabelledBone(const Volume& ct, const std::filesystem::path& label_file, std::optional<int> value) {
  if (!std::filesystem::is_regular_file(label_file)) throw InputError("--label: no file at " + label_file.string());
  // Read as stored values (a multi-label map holds several structures).
  const Image<float> label = readImageFile<float>(label_file);
  if (!sameGrid(ct.geometry, label.geometry))
    throw InputError("--label " + label_file.string() + ": expected a label map in the CT's grid (" +
                     describe(ct.geometry) + "), found " + describe(label.geometry) +
                     "; resample it onto the CT (3D Slicer: export the segmentation with the CT as its reference "
                     "volume)");
  Volume kept = ct;
  long long inside = 0;
  for (size_t n = 0; n < kept.voxels.size(); ++n) {
    const float v = label.voxels[n];
    const bool keep = value ? std::lround(v) == *value && std::fabs(v - *value) < 0.01f : v != 0;
    inside += keep;
    if (!keep) kept.voxels[n] = -1000.0f;
  }
  if (inside == 0)
    throw InputError("--label " + label_file.string() + ": no voxel holds " +
                     (value ? "the value " + std::to_string(*value) : std::string("a non-zero label")) +
                     "; expected the bone of the joint (--label-value chooses one structure of a multi-label map)");
  return kept;
}

}  // namespace articula::imaging
