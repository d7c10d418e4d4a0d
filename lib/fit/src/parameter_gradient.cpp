#include "articula/fit/parameter_gradient.hpp"

#include <algorithm>
#include <cmath>

#include "articula/core/parallel.hpp"
#include "articula/geometry/pose.hpp"

namespace articula::fit {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using geometry::ShapeModel;

namespace {
// |u|^g, its u-derivative and log|u| |u|^g (the g-derivative), 0 at u = 0.
struct PowerTerm {
  double value, du, dg;
};
PowerTerm powerTerm(double u, double g) {
  const double a = std::fabs(u);
  if (a == 0.0) return {0.0, 0.0, 0.0};
  const double v = std::pow(a, g);
  return {v, g * v / u, v * std::log(a)};
}
}  // namespace

void parameterGradient(const geometry::ShapeParameters& p, const Eigen::MatrixX3d& at, Eigen::MatrixXd& J,
                       Eigen::VectorXd& gradient_norms, int threads) {
  const ShapeModel model = p.model;
  const bool sphere = model == ShapeModel::Sphere;
  const bool ovoidal = model == ShapeModel::Ovoid || model == ShapeModel::Superovoid;
  const bool free_exponents = model == ShapeModel::Superellipsoid || model == ShapeModel::Superovoid;
  const Vector3d radii = sphere ? Vector3d::Constant(p.radii[0]) : p.radii;
  const Vector3d g = free_exponents ? p.exponents : Vector3d::Constant(2.0);
  const Matrix3d R = sphere ? Matrix3d::Identity() : geometry::rotationFromAngles(p.angles);
  Matrix3d dR[3];
  if (!sphere)
    for (int j = 0; j < 3; ++j) {
      const double h = 1e-6;
      Vector3d plus = p.angles, minus = p.angles;
      plus[j] += h;
      minus[j] -= h;
      dR[j] = (geometry::rotationFromAngles(plus) - geometry::rotationFromAngles(minus)) / (2.0 * h);
    }
  const int M = geometry::parameterCount(model);
  J.resize(at.rows(), M);
  gradient_norms.resize(at.rows());
  const Vector3d inv_r = radii.cwiseInverse();
  // Rows are independent: split over threads (10^6 points in a fit).
  parallelFor(at.rows(), 4096, threads, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
    for (Eigen::Index i = begin; i < end; ++i) {
      const Vector3d v = at.row(i).transpose() - p.center;
      const Vector3d u = (R.transpose() * v).cwiseProduct(inv_r);
      Vector3d gu;                      // dF/du
      Vector3d dgamma = Vector3d::Zero();  // dF/dgamma
      Eigen::Vector4d dcx = Eigen::Vector4d::Zero(), dcy = Eigen::Vector4d::Zero();
      if (!ovoidal) {
        for (int k = 0; k < 3; ++k) {
          const PowerTerm t = powerTerm(u[k], g[k]);
          gu[k] = t.du;
          dgamma[k] = t.dg;
        }
      } else {
        // Superovoid (geometry/surfaces.hpp): denominators at z clamped to [-1, 1].
        const double z = u[2];
        const double zc = std::clamp(z, -1.0, 1.0);
        const bool inside_slab = z > -1.0 && z < 1.0;
        const Eigen::Vector4d powers(1.0, zc, zc * zc, zc * zc * zc);
        const PowerTerm tz = powerTerm(z, g[2]);
        gu[2] = tz.du;
        dgamma[2] = tz.dg;
        const Eigen::Vector4d* c[2] = {&p.cx, &p.cy};
        Eigen::Vector4d* dc[2] = {&dcx, &dcy};
        for (int k = 0; k < 2; ++k) {
          const Eigen::Vector4d& ck = *c[k];
          const double den = ck.dot(powers);
          const double dden = inside_slab ? ck[1] + zc * (2.0 * ck[2] + 3.0 * zc * ck[3]) : 0.0;
          const double q = u[k] / den;
          const PowerTerm t = powerTerm(q, g[k]);
          gu[k] = t.du / den;
          gu[2] += t.du * (-q * dden / den);
          dgamma[k] = t.dg;
          *dc[k] = -t.du * q / den * powers;  // d|q|^g/dc_j = g|q|^g (-z^j/den)
        }
      }
      const Vector3d grad_x = R * gu.cwiseProduct(inv_r);
      gradient_norms[i] = grad_x.norm();
      const Vector3d dradii = -gu.cwiseProduct(u).cwiseProduct(inv_r);
      int col = 0;
      if (sphere) {
        J(i, col++) = dradii.sum();
      } else {
        for (int k = 0; k < 3; ++k) J(i, col++) = dradii[k];
      }
      if (free_exponents)
        for (int k = 0; k < 3; ++k) J(i, col++) = dgamma[k];
      if (ovoidal) {
        for (int k = 0; k < 4; ++k) J(i, col++) = dcx[k];
        for (int k = 0; k < 4; ++k) J(i, col++) = dcy[k];
      }
      for (int k = 0; k < 3; ++k) J(i, col++) = -grad_x[k];
      if (!sphere)
        for (int j = 0; j < 3; ++j) J(i, col++) = gu.cwiseProduct(inv_r).dot(dR[j].transpose() * v);
    }
  });
}

}  // namespace articula::fit
