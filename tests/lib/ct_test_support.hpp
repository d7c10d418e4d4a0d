#pragma once
// Helpers shared by the CT-chain tests (imaging, mesh, sampling): the shared
// data folder and distances to the phantom's true head surface.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "articula/geometry/surface.hpp"
#include "articula/phantom/phantom.hpp"
#include "articula/testsupport/scratch_dir.hpp"

namespace articula::testing {

/// ../shared/data, or $ARTICULA_SHARED_DATA when set.
inline std::filesystem::path sharedData() {
  if (const char* env = std::getenv("ARTICULA_SHARED_DATA")) return env;
  return ARTICULA_SHARED_DATA_DEFAULT;
}

/// A fresh scratch folder, removed when the test program ends.
inline std::filesystem::path scratch(const std::string& name) { return testsupport::scratchDir(name); }

/// Signed distance (mm, > 0 outside) to the head surface, to first order:
/// F / |grad F|, refined by one Newton step along the gradient.
inline double headDistance(const geometry::ImplicitSurface& head, const Eigen::Vector3d& x) {
  geometry::Evaluation e = head.evaluate(x, 1);
  double d = e.value / e.gradient.norm();
  const Eigen::Vector3d y = x - d * e.gradient.normalized();
  e = head.evaluate(y, 1);
  return d + e.value / e.gradient.norm();
}

}  // namespace articula::testing
