#include "articula/geometry/curvature.hpp"

#include <cmath>

#include "articula/core/error.hpp"

namespace articula::geometry {

namespace {
double gradientNorm(const Eigen::Vector3d& g) {
  const double len = g.norm();
  if (!(len > 0.0) || !std::isfinite(len))
    throw ProcessingError("the surface normal is undefined here: |grad F| = " + std::to_string(len));
  return len;
}
}  // namespace

SurfaceFrame surfaceFrame(const ImplicitSurface& surface, const Eigen::Vector3d& x, FrameMethod method) {
  const Eigen::Vector3d g = surface.gradient(x);
  const double len = gradientNorm(g);
  const TangentFrame f = tangentFrame(g, method);
  return {g / len, f.t, f.b};
}

double normalCurvature(const ImplicitSurface& surface, const Eigen::Vector3d& x, const Eigen::Vector3d& w) {
  const Evaluation e = surface.evaluate(x, 2);
  return w.dot(e.hessian * w) / gradientNorm(e.gradient);
}

PrincipalCurvatures principalCurvatures(const ImplicitSurface& surface, const Eigen::Vector3d& x) {
  const Evaluation e = surface.evaluate(x, 2);
  const double len = gradientNorm(e.gradient);
  const TangentFrame f = householderFrame(e.gradient);
  const double htt = f.t.dot(e.hessian * f.t) / len;
  const double hbb = f.b.dot(e.hessian * f.b) / len;
  const double htb = f.t.dot(e.hessian * f.b) / len;
  const double theta = 0.5 * std::atan2(2.0 * htb, htt - hbb);  // eq. 4.23, all quadrants
  const double c = std::cos(theta), s = std::sin(theta);
  PrincipalCurvatures pc;
  // k(theta) = c^2 htt + 2 c s htb + s^2 hbb; theta from atan2 picks the maximum.
  pc.k1 = c * c * htt + 2.0 * c * s * htb + s * s * hbb;
  pc.k2 = s * s * htt - 2.0 * c * s * htb + c * c * hbb;
  pc.d1 = c * f.t + s * f.b;
  pc.d2 = -s * f.t + c * f.b;
  if (pc.k2 > pc.k1) {
    std::swap(pc.k1, pc.k2);
    std::swap(pc.d1, pc.d2);
  }
  return pc;
}

}  // namespace articula::geometry
