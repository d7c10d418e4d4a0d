#include "articula/contact/proximity.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Eigenvalues>

#include "articula/core/error.hpp"

namespace articula::contact {

bool boundingSpheresOverlap(const ConvexShape& a, const ConvexShape& b) {
  return (b.center - a.center).norm() <= boundingRadius(a) + boundingRadius(b);
}

const char* relationName(EllipsoidRelation relation) {
  switch (relation) {
    case EllipsoidRelation::Separated: return "separated";
    case EllipsoidRelation::Touching: return "touching";
    default: return "overlapping";
  }
}

Eigen::Matrix4d homogeneousMatrix(const ConvexShape& s) {
  const Eigen::Matrix3d M = s.rotation * s.radii.cwiseAbs2().cwiseInverse().asDiagonal() * s.rotation.transpose();
  Eigen::Matrix4d A;
  A.topLeftCorner<3, 3>() = M;
  A.topRightCorner<3, 1>() = -M * s.center;
  A.bottomLeftCorner<1, 3>() = (-M * s.center).transpose();
  A(3, 3) = s.center.dot(M * s.center) - 1.0;
  return A;
}

EllipsoidRelation ellipsoidRelation(const ConvexShape& a, const ConvexShape& b, double relative_tolerance) {
  if (!a.quadric || !b.quadric)
    throw UsageError("ellipsoidRelation: both shapes must be ellipsoids (exponents 2); the algebraic "
                     "separation condition has no superellipsoid counterpart (thesis section 5.2.4)");
  // Roots of det(lambda A + B) = eigenvalues of -A^-1 B.
  const Eigen::Matrix4d A = homogeneousMatrix(a), B = homogeneousMatrix(b);
  const Eigen::EigenSolver<Eigen::Matrix4d> solver(-A.inverse() * B, false);
  const Eigen::Vector4cd roots = solver.eigenvalues();
  std::vector<double> positive;
  double scale = 0.0;
  for (int i = 0; i < 4; ++i) scale = std::max(scale, std::abs(roots[i]));
  int complex_positive = 0;
  for (int i = 0; i < 4; ++i) {
    const double re = roots[i].real(), im = roots[i].imag();
    if (re <= 0.0) continue;
    if (std::fabs(im) <= relative_tolerance * std::max(scale, 1.0) * 1e3) positive.push_back(re);
    else ++complex_positive;
  }
  if (positive.size() >= 2) {
    std::sort(positive.begin(), positive.end());
    const double gap = positive.back() - positive.front();
    return gap > relative_tolerance * std::max(positive.back(), 1e-300) * 1e3 ? EllipsoidRelation::Separated
                                                                              : EllipsoidRelation::Touching;
  }
  // A double root split by rounding into a complex pair with tiny imaginary parts.
  if (complex_positive == 2) {
    for (int i = 0; i < 4; ++i)
      if (roots[i].real() > 0.0 && std::fabs(roots[i].imag()) <= 1e-6 * roots[i].real()) return EllipsoidRelation::Touching;
  }
  return EllipsoidRelation::Overlapping;
}

}  // namespace articula::contact
