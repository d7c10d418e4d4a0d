#pragma once
// Tangent frames from a normal (thesis ch. 4 and appendix C): given n, return
// unit t and b with n, t, b mutually orthogonal and right-handed, t x b = n/|n|.
//
// The thesis's Householder formula (table C.1) mirrors its branch for n_x < 0,
// which gives t x b = -n there (the Householder matrix has determinant -1, so
// the frame (h1, t, b) is left-handed and only one of h1 = +-n keeps (t, b, n)
// right-handed). We negate b on that branch; with s = sign(n_x) the unit
// formula becomes branchless:
//   k = 1 / (1 + |n_x|),  t = (-s n_y, 1 - k n_y^2, -k n_y n_z),
//   b = (-n_z, -s k n_y n_z, s (1 - k n_z^2)).
// This right-handed Householder frame is exactly Duff et al.'s (2017) frame
// with the axes cycled so that x is the pivot, and costs the same.
// The "Unit" functions assume |n| = 1 (the benchmark's setting); the others
// take any non-zero n.
#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace articula::geometry {

struct TangentFrame {
  Eigen::Vector3d t;  // tangent
  Eigen::Vector3d b;  // binormal
};

enum class FrameMethod { Householder, Duff, Eberly, SquarePlate, ProjectionMatrix };

/// "Householder", "Duff", "Eberly", "SquarePlate", "ProjectionMatrix".
const char* frameMethodName(FrameMethod method);

/// Householder (table 4.2 / C.1, right-handed), unit n.
inline TangentFrame householderFrameUnit(const Eigen::Vector3d& n) {
  // With a = -1 / (s + n_x) = -s k this is Duff et al.'s listing 3 with the
  // axes cycled (x as the pivot): one division and nine products.
  const double s = std::copysign(1.0, n.x());
  const double a = -1.0 / (s + n.x());
  const double c = n.y() * n.z() * a;
  return {{-s * n.y(), 1.0 + s * n.y() * n.y() * a, s * c}, {-n.z(), c, s + n.z() * n.z() * a}};
}

/// Householder for any non-zero n: the 2nd and 3rd columns of H = I - 2 h h^T / h^T h
/// with h = n + s |n| e1 (eq. 4.19); unit by construction, no normalisation of n.
inline TangentFrame householderFrame(const Eigen::Vector3d& n) {
  const double len = n.norm();
  const double s = std::copysign(1.0, n.x());
  const double mu = n.x() + s * len;                // h1, never cancels
  const double k = 1.0 / (len * (len + std::fabs(n.x())));  // 2 / h^T h
  const double kyz = k * n.y() * n.z();
  return {{-k * mu * n.y(), 1.0 - k * n.y() * n.y(), -kyz},
          {-s * k * mu * n.z(), -s * kyz, s * (1.0 - k * n.z() * n.z())}};
}

/// Duff, Burgess, Christensen, Hery, Kensler, Liani, Villemin (2017),
/// "Building an Orthonormal Basis, Revisited", listing 3; unit n.
inline TangentFrame duffFrameUnit(const Eigen::Vector3d& n) {
  const double s = std::copysign(1.0, n.z());
  const double a = -1.0 / (s + n.z());
  const double b = n.x() * n.y() * a;
  return {{1.0 + s * n.x() * n.x() * a, s * b, -s * n.x()}, {b, s + n.y() * n.y() * a, -n.y()}};
}

/// Eberly's cross-product method (table C.2): t = n x e_k / |.| with e_k the
/// axis of n's smaller x/y component, b = n x t; unit n.
inline TangentFrame eberlyFrameUnit(const Eigen::Vector3d& n) {
  if (std::fabs(n.x()) >= std::fabs(n.y())) {
    const double inv = 1.0 / std::sqrt(n.x() * n.x() + n.z() * n.z());
    return {{-n.z() * inv, 0.0, n.x() * inv},
            {n.x() * n.y() * inv, -(n.x() * n.x() + n.z() * n.z()) * inv, n.y() * n.z() * inv}};
  }
  const double inv = 1.0 / std::sqrt(n.y() * n.y() + n.z() * n.z());
  return {{0.0, n.z() * inv, -n.y() * inv},
          {-(n.y() * n.y() + n.z() * n.z()) * inv, n.x() * n.y() * inv, n.x() * n.z() * inv}};
}

/// Square plate (section 5.4.4, table 5.1 / C.3): t = n x v / |.| with an
/// auxiliary vector v never collinear with n, b = n x t; unit n.
inline TangentFrame squarePlateFrameUnit(const Eigen::Vector3d& n) {
  // Table 5.1: v2 = (nx - 1, ny + 1, nz) when nx, ny have the same sign (or
  // one is 0), else v1 = (nx + 1, ny + 1, nz); either is non-collinear there.
  const Eigen::Vector3d v = n.x() * n.y() >= 0.0 ? Eigen::Vector3d(n.x() - 1.0, n.y() + 1.0, n.z())
                                                 : Eigen::Vector3d(n.x() + 1.0, n.y() + 1.0, n.z());
  const Eigen::Vector3d t = n.cross(v).normalized();
  return {t, n.cross(t).normalized()};
}

/// Projection matrix (after Zhao et al. 2006, table C.4): the columns of the
/// tangent-plane projector P = I - n n^T all lie in the tangent plane; t is
/// its longest column normalised, and b the Rodrigues rotation of t by +90
/// degrees about n (which for t perpendicular to n is n x t); unit n.
inline TangentFrame projectionMatrixFrameUnit(const Eigen::Vector3d& n) {
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - n * n.transpose();
  Eigen::Index k;
  P.colwise().squaredNorm().maxCoeff(&k);
  const Eigen::Vector3d t = P.col(k).normalized();
  // Rodrigues: R(n, pi/2) t = t cos + (n x t) sin + n (n.t)(1 - cos).
  const double c = 0.0, s = 1.0;
  const Eigen::Vector3d b = t * c + n.cross(t) * s + n * (n.dot(t) * (1.0 - c));
  return {t, b};
}

/// Any method, any non-zero n (normalised first where the method needs it).
TangentFrame tangentFrame(const Eigen::Vector3d& n, FrameMethod method = FrameMethod::Householder);

}  // namespace articula::geometry
