#include "articula/geometry/frames.hpp"

#include "articula/core/error.hpp"

namespace articula::geometry {

const char* frameMethodName(FrameMethod m) {
  switch (m) {
    case FrameMethod::Householder: return "Householder";
    case FrameMethod::Duff: return "Duff";
    case FrameMethod::Eberly: return "Eberly";
    case FrameMethod::SquarePlate: return "SquarePlate";
    case FrameMethod::ProjectionMatrix: return "ProjectionMatrix";
  }
  return "unknown";
}

TangentFrame tangentFrame(const Eigen::Vector3d& n, FrameMethod m) {
  const double len = n.norm();
  if (!std::isfinite(len) || !(len > 0.0))
    throw InvalidParameter("normal", "a non-zero finite vector (its length)", len);
  if (m == FrameMethod::Householder) return householderFrame(n);
  const Eigen::Vector3d u = n / len;
  switch (m) {
    case FrameMethod::Duff: return duffFrameUnit(u);
    case FrameMethod::Eberly: return eberlyFrameUnit(u);
    case FrameMethod::SquarePlate: return squarePlateFrameUnit(u);
    case FrameMethod::ProjectionMatrix: return projectionMatrixFrameUnit(u);
    default: return householderFrameUnit(u);
  }
}

}  // namespace articula::geometry
