#include "articula/fit/uncertainty.hpp"

#include <cmath>
#include <limits>

#include <Eigen/QR>
#include <Eigen/SVD>

#include "articula/core/error.hpp"
#include "articula/distance/signed_distance.hpp"
#include "articula/fit/parameter_gradient.hpp"

namespace articula::fit {
namespace {

// A direction of the scaled normal matrix this much weaker than the
// strongest carries no information (double precision leaves ~1e-16 of it).
constexpr double kRelativeSingularValue = 1e-10;

/// Half-widths beyond which an interval says nothing about the head: a
/// radius or position known to only +-10 mm, an angle to +-45 degrees, an
/// exponent to +-1, an ovoid coefficient to +-0.5.
double uselessHalfWidth(geometry::ParameterKind kind) {
  switch (kind) {
    case geometry::ParameterKind::Radius:
    case geometry::ParameterKind::Translation: return 10.0;
    case geometry::ParameterKind::Angle: return M_PI / 4;
    case geometry::ParameterKind::Exponent: return 1.0;
    default: return 0.5;
  }
}

}  // namespace

ParameterUncertainty parameterUncertainty(const geometry::ShapeParameters& fitted, const Eigen::MatrixX3d& points,
                                          const Eigen::MatrixX3d& closest) {
  const auto names = geometry::parameterNames(fitted.model);
  const auto kinds = geometry::parameterKinds(fitted.model);
  const Eigen::Index n = points.rows(), m = static_cast<Eigen::Index>(names.size());
  if (n <= m)
    throw InputError("parameter uncertainty needs more points than the " + std::to_string(m) + " parameters, found " +
                     std::to_string(n));
  Eigen::VectorXd residual;
  Eigen::MatrixX3d feet = closest;
  distance::SignedDistance(fitted).evaluate(points, residual, feet, distance::SignedDistance::Start::WarmExact);
  Eigen::MatrixXd J;
  Eigen::VectorXd gradient_norms;
  parameterGradient(fitted, feet, J, gradient_norms);
  // The derivatives of the signed distances (envelope theorem, parameter_gradient.hpp).
  for (Eigen::Index i = 0; i < n; ++i) J.row(i) /= std::max(gradient_norms[i], 1e-300);
  const double variance = residual.squaredNorm() / static_cast<double>(n - m);
  // Columns scaled to unit norm so that millimetres and radians compare.
  Eigen::VectorXd scale = J.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < m; ++j)
    if (!(scale[j] > 0)) scale[j] = 1;
  J = J * scale.cwiseInverse().asDiagonal();
  // J = QR and R share their singular values and right singular vectors: the
  // SVD of the small R, after a QR in place, keeps the memory of one J
  // (120 MB at 10^6 points) where an SVD of J would hold three.
  Eigen::HouseholderQR<Eigen::Ref<Eigen::MatrixXd>> qr(J);
  const Eigen::MatrixXd R = qr.matrixQR().topRows(m).triangularView<Eigen::Upper>();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(R, Eigen::ComputeThinV);
  const Eigen::VectorXd& sigma = svd.singularValues();
  ParameterUncertainty out;
  out.condition_number = sigma[m - 1] > 0 ? std::pow(sigma[0] / sigma[m - 1], 2) : std::numeric_limits<double>::infinity();
  // (J^T J)^-1 = V diag(1/sigma^2) V^T in scaled units; weak directions make
  // every parameter that loads on them unidentifiable (infinite error).
  Eigen::VectorXd inverse_square = Eigen::VectorXd::Zero(m);
  std::vector<char> weak(static_cast<size_t>(m), 0);
  for (Eigen::Index k = 0; k < m; ++k) {
    if (sigma[k] > kRelativeSingularValue * sigma[0]) inverse_square[k] = 1.0 / (sigma[k] * sigma[k]);
    else weak[static_cast<size_t>(k)] = 1;
  }
  const Eigen::MatrixXd& V = svd.matrixV();
  const Eigen::VectorXd estimate = geometry::toVector(fitted);
  out.standard_error.resize(m);
  out.ci95_lower.resize(m);
  out.ci95_upper.resize(m);
  for (Eigen::Index j = 0; j < m; ++j) {
    double var = 0;
    bool free = false;
    for (Eigen::Index k = 0; k < m; ++k) {
      var += V(j, k) * V(j, k) * inverse_square[k];
      free = free || (weak[static_cast<size_t>(k)] && std::abs(V(j, k)) > 1e-3);
    }
    const double se = free ? std::numeric_limits<double>::infinity() : std::sqrt(variance * var) / scale[j];
    out.standard_error[j] = se;
    out.ci95_lower[j] = estimate[j] - 1.96 * se;
    out.ci95_upper[j] = estimate[j] + 1.96 * se;
    if (!(1.96 * se <= uselessHalfWidth(kinds[static_cast<size_t>(j)]))) out.not_identifiable.push_back(names[static_cast<size_t>(j)]);
  }
  return out;
}

}  // namespace articula::fit
