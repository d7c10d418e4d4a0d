#pragma once
// A synthetic hip CT with a known femoral head, the embedded default input of
// the pipeline and its tests. The head is an exact shape model of
// lib/geometry (sphere ... superovoid, varied by seed), on a neck and a shaft,
// with a cortical rim and cancellous interior, facing an acetabular shell
// across a joint gap of chosen width; partial volume (supersampled voxels),
// Gaussian blur and Gaussian noise. All coordinates LPS mm.
#include <optional>

#include <nlohmann/json.hpp>

#include "articula/geometry/shape.hpp"
#include "articula/imaging/image.hpp"

namespace articula::phantom {

struct PhantomOptions {
  unsigned long long seed = 1;
  std::optional<geometry::ShapeModel> model;                // default: chosen by seed
  Eigen::Vector3d spacing = Eigen::Vector3d(0.7, 0.7, 1.5); // mm
  double gap_mm = 3.0;                                      // joint gap, head to socket
  bool right = true;                                        // patient side (right hip: x < 0)
  bool ras_storage = false;  // store with direction diag(-1,-1,1), like a NIfTI saved RAS
  double noise_hu = 20.0;    // standard deviation of the Gaussian noise
  double blur_mm = 0.5;      // standard deviation of the Gaussian point-spread
  double cortical_hu = 1300, cancellous_hu = 350, soft_tissue_hu = 40;
  double cortical_mm = 1.5;  // cortical thickness
  /// Throws UsageError naming the first invalid option.
  void validate() const;
};

struct Phantom {
  imaging::Volume ct;                 // HU
  imaging::Label femur;               // truth: head, neck and shaft (voxel centre inside)
  geometry::ShapeParameters head;     // the head's outer (periosteal) surface
  Eigen::Vector3d neck_axis;          // unit, from the head centre along the neck
  nlohmann::json truth;               // everything above, for truth.json
};

/// Builds the phantom; deterministic for a given options.seed.
Phantom makePhantom(const PhantomOptions& options);

}  // namespace articula::phantom
