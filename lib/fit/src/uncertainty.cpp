#include "articula/fit/uncertainty.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/QR>
#include <Eigen/SVD>

#include "articula/core/error.hpp"
#include "articula/distance/signed_distance.hpp"
#include "articula/fit/parameter_gradient.hpp"

namespace articula::fit {
namespace {

using geometry::ShapeModel;

// A direction of the scaled normal matrix this much weaker than the
// strongest carries no information (double precision leaves ~1e-16 of it).
constexpr double kRelativeSingularValue = 1e-10;

// edgeOffsetField's sizes, from the phantom benches of three generators
// (docs/benchmarks.md, "Intervals with correlated residuals"): the linear
// field's standard deviation kLinearPerMm2 h^2 for the largest voxel side h
// (a head's centre moved by 0.01-0.05 mm at 1 x 1 x 2 mm, towards its neck);
// the across-slice field's kAcrossBaseMm + kAcrossPerMm4 s^4 for slices of s
// (the surface's offset across slices less that within them: 0.02-0.06 mm up
// to 2 mm slices, 0.11-0.17 mm at 3 mm); the odd term across slices as
// large (a dome's offset unlike its far side's: egg terms found on
// superellipsoids at 2-3 mm slices).
constexpr double kLinearPerMm2 = 0.01, kAcrossBaseMm = 0.03, kAcrossPerMm4 = 0.0025, kOddToEven = 1.0;

bool isOvoid(ShapeModel m) { return m == ShapeModel::Ovoid || m == ShapeModel::Superovoid; }
// The meat J^T Sigma J of the sandwich (#k x #k) in the scaled columns of
// `J`, for the chosen method (SpatialModel's before its level is set).
Eigen::MatrixXd meat(UncertaintyMethod method, const Eigen::MatrixX3d& points, const Eigen::Ref<const Eigen::MatrixXd>& J,
                     const Eigen::VectorXd& residual, const ResidualCorrelation& c) {
  const Eigen::Index n = J.rows();
  switch (method) {
    case UncertaintyMethod::Independent: return (residual.squaredNorm() / static_cast<double>(n - J.cols())) * (J.transpose() * J);
    case UncertaintyMethod::SpatialModel: return covarianceGram(points, J, c);
    case UncertaintyMethod::SpatialHac: {
      const Eigen::MatrixXd scores = residual.asDiagonal() * J;
      if (!(c.length_mm[0] > 0)) return scores.transpose() * scores;  // White's: no correlation found
      const double reach = 3.0 * c.length_mm.maxCoeff();
      return kernelGram(points, scores, [reach](double h) { return std::max(0.0, 1.0 - h / reach); }, reach,
                        reach / 3.0);
    }
    case UncertaintyMethod::PatchBootstrap: {
      // Patches: cubes of 3 L, at least a sixth and at most half of the cap's extent.
      const Eigen::Vector3d lo = points.colwise().minCoeff().transpose();
      const double extent = (points.colwise().maxCoeff().transpose() - lo).maxCoeff();
      const double side = std::clamp(3.0 * c.length_mm.maxCoeff(), extent / 6.0, extent / 2.0);
      std::vector<std::pair<long long, Eigen::Index>> keyed(static_cast<size_t>(n));
      for (Eigen::Index i = 0; i < n; ++i) {
        const Eigen::Vector3i q = ((points.row(i).transpose() - lo) / side).array().floor().cast<int>();
        keyed[static_cast<size_t>(i)] = {(static_cast<long long>(q[0]) << 42) ^ (static_cast<long long>(q[1]) << 21) ^ q[2], i};
      }
      std::sort(keyed.begin(), keyed.end());
      Eigen::MatrixXd m = Eigen::MatrixXd::Zero(J.cols(), J.cols());
      Eigen::VectorXd u = Eigen::VectorXd::Zero(J.cols());
      int patches = 0;
      for (size_t s = 0; s < keyed.size(); ++s) {
        u += residual[keyed[s].second] * J.row(keyed[s].second).transpose();
        if (s + 1 == keyed.size() || keyed[s + 1].first != keyed[s].first) {
          m += u * u.transpose();
          u.setZero();
          ++patches;
        }
      }
      // A bootstrap over P patches resamples their score sums: its covariance, P / (P - 1) of theirs.
      return patches > 1 ? m * (static_cast<double>(patches) / (patches - 1)) : m;
    }
  }
  return {};
}

}  // namespace

double uselessHalfWidth(geometry::ParameterKind kind) {
  switch (kind) {
    case geometry::ParameterKind::Radius:
    case geometry::ParameterKind::Translation: return 10.0;
    case geometry::ParameterKind::Angle: return M_PI / 4;
    case geometry::ParameterKind::Exponent: return 1.0;
    default: return 0.5;
  }
}

EdgeOffsetField edgeOffsetField(const Eigen::Vector3d& spacing_mm, const Eigen::Vector3d& slice_axis) {
  EdgeOffsetField f;
  f.slice_axis = (slice_axis.normalized().array() + 0.0).matrix();  // no -0 in fits.json
  f.spacing_mm = spacing_mm;
  f.linear_sd_mm = kLinearPerMm2 * spacing_mm.maxCoeff() * spacing_mm.maxCoeff();
  f.across_slices_sd_mm = kAcrossBaseMm + kAcrossPerMm4 * std::pow(spacing_mm[2], 4);
  f.odd_across_slices_sd_mm = kOddToEven * f.across_slices_sd_mm;
  return f;
}

std::string uncertaintyMethodName(UncertaintyMethod m) {
  switch (m) {
    case UncertaintyMethod::SpatialModel: return "spatial-model";
    case UncertaintyMethod::Independent: return "independent";
    case UncertaintyMethod::SpatialHac: return "spatial-hac";
    case UncertaintyMethod::PatchBootstrap: return "patch-bootstrap";
  }
  return "?";
}

UncertaintyMethod uncertaintyMethodFromName(const std::string& name) {
  for (auto m : {UncertaintyMethod::SpatialModel, UncertaintyMethod::Independent, UncertaintyMethod::SpatialHac,
                 UncertaintyMethod::PatchBootstrap})
    if (uncertaintyMethodName(m) == name) return m;
  throw UsageError("unknown uncertainty method '" + name +
                   "': expected spatial-model, independent, spatial-hac or patch-bootstrap");
}

ParameterUncertainty parameterUncertainty(const geometry::ShapeParameters& fitted, const Eigen::MatrixX3d& points,
                                          const Eigen::MatrixX3d& closest, UncertaintyMethod method,
                                          const EdgeOffsetField& edge_offset, int threads) {
  const auto names = geometry::parameterNames(fitted.model);
  const auto kinds = geometry::parameterKinds(fitted.model);
  const Eigen::Index n = points.rows(), m = static_cast<Eigen::Index>(names.size());
  if (n <= m)
    throw InputError("parameter uncertainty needs more points than the " + std::to_string(m) + " parameters, found " +
                     std::to_string(n));
  Eigen::VectorXd residual;
  Eigen::MatrixX3d feet = closest;
  distance::SignedDistance(fitted, threads).evaluate(points, residual, feet, distance::SignedDistance::Start::WarmExact);
  // An ovoid in its gauge c0x = c0y = 1 (the same surface): a and b are then its semi-axes.
  geometry::ShapeParameters shape = fitted;
  Eigen::VectorXd to_raw = Eigen::VectorXd::Ones(m);  // raw standard error = canonical one x this
  std::vector<char> held(static_cast<size_t>(m), 0);
  if (isOvoid(fitted.model) && fitted.cx[0] > 0 && fitted.cy[0] > 0) {
    shape.radii[0] *= fitted.cx[0];
    shape.radii[1] *= fitted.cy[0];
    shape.cx /= fitted.cx[0];
    shape.cy /= fitted.cy[0];
    const auto gauge = geometry::gaugeParameterNames(fitted.model);
    for (Eigen::Index j = 0; j < m; ++j) {
      const std::string& name = names[static_cast<size_t>(j)];
      if (std::find(gauge.begin(), gauge.end(), name) != gauge.end()) held[static_cast<size_t>(j)] = 1;
      else if (name == "a") to_raw[j] = 1.0 / fitted.cx[0];
      else if (name == "b") to_raw[j] = 1.0 / fitted.cy[0];
      else if (name.size() == 3 && name[0] == 'c') to_raw[j] = name[2] == 'x' ? fitted.cx[0] : fitted.cy[0];
    }
  }
  Eigen::MatrixXd full;
  Eigen::VectorXd gradient_norms;
  parameterGradient(shape, feet, full, gradient_norms, threads);
  // The derivatives of the signed distances (envelope theorem, parameter_gradient.hpp).
  for (Eigen::Index i = 0; i < n; ++i) full.row(i) /= std::max(gradient_norms[i], 1e-300);
  // The edge offset's fields n_x, n_y, n_z, (n . s)^2, (n . s)^3, each less its mean
  // and times its standard deviation; n, the fitted surface's normal at each
  // foot, is minus the distances' derivatives along t1..t3.
  Eigen::MatrixXd fields;
  if (edge_offset.active()) {
    const auto t = std::find(names.begin(), names.end(), "t1") - names.begin();
    fields.resize(n, 5);
    fields.leftCols(3) = -full.middleCols(t, 3);
    const Eigen::VectorXd across = fields.leftCols(3) * edge_offset.slice_axis;
    fields.col(3) = across.array().square().matrix();
    fields.col(4) = across.array().cube().matrix();
    fields.rowwise() -= fields.colwise().mean();
    fields.leftCols(3) *= edge_offset.linear_sd_mm;
    fields.col(3) *= edge_offset.across_slices_sd_mm;
    fields.col(4) *= edge_offset.odd_across_slices_sd_mm;
  }
  std::vector<Eigen::Index> active;
  for (Eigen::Index j = 0; j < m; ++j)
    if (!held[static_cast<size_t>(j)]) active.push_back(j);
  const auto k = static_cast<Eigen::Index>(active.size());
  // The held columns dropped in place: one Jacobian in memory (160 MB at 10^6 points).
  for (Eigen::Index j = 0; j < k; ++j)
    if (active[static_cast<size_t>(j)] != j) full.col(j) = full.col(active[static_cast<size_t>(j)]);
  Eigen::Ref<Eigen::MatrixXd> J = full.leftCols(k);
  // Columns scaled to unit norm so that millimetres and radians compare.
  Eigen::VectorXd scale = J.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < k; ++j)
    if (!(scale[j] > 0)) scale[j] = 1;
  J.array().rowwise() /= scale.transpose().array();

  ParameterUncertainty out;
  out.method = uncertaintyMethodName(method);
  out.correlation = estimateResidualCorrelation(points, residual, 1, method != UncertaintyMethod::SpatialModel, J);
  const double sse = residual.squaredNorm();
  Eigen::MatrixXd middle;
  if (method == UncertaintyMethod::SpatialModel) {
    // One pass over the cells for the meat and n_eff: J with a column of ones.
    Eigen::MatrixXd with_ones(n, k + 1);
    with_ones.leftCols(k) = J;
    with_ones.col(k).setOnes();
    const Eigen::MatrixXd gram = covarianceGram(points, with_ones, out.correlation);
    middle = gram.topLeftCorner(k, k);
    out.correlation.n_eff = nEffective(out.correlation, gram(k, k));
  } else {
    middle = meat(method, points, J, residual, out.correlation);
  }

  // J^T f before the QR below overwrites J.
  const Eigen::MatrixXd field_scores = edge_offset.active() ? Eigen::MatrixXd(J.transpose() * fields) : Eigen::MatrixXd();
  // J = QR and R share their singular values and right singular vectors: the
  // SVD of the small R, after a QR in place, keeps the memory of one J
  // (120 MB at 10^6 points) where an SVD of J would hold three.
  Eigen::HouseholderQR<Eigen::Ref<Eigen::MatrixXd>> qr(J);
  const Eigen::MatrixXd R = qr.matrixQR().topRows(k).triangularView<Eigen::Upper>();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(R, Eigen::ComputeThinV);
  const Eigen::VectorXd& sigma = svd.singularValues();
  out.condition_number = sigma[k - 1] > 0 ? std::pow(sigma[0] / sigma[k - 1], 2) : std::numeric_limits<double>::infinity();
  // (J^T J)^+ = V diag(1/sigma^2) V^T in scaled units; weak directions make
  // every parameter that loads on them unidentifiable (infinite error).
  Eigen::VectorXd inverse_square = Eigen::VectorXd::Zero(k);
  std::vector<char> weak(static_cast<size_t>(k), 0);
  for (Eigen::Index q = 0; q < k; ++q) {
    if (sigma[q] > kRelativeSingularValue * sigma[0]) inverse_square[q] = 1.0 / (sigma[q] * sigma[q]);
    else weak[static_cast<size_t>(q)] = 1;
  }
  const Eigen::MatrixXd& V = svd.matrixV();
  const Eigen::MatrixXd bread = V * inverse_square.asDiagonal() * V.transpose();
  if (method == UncertaintyMethod::SpatialModel) {
    // The level of Sigma: E[SSE] = tr(Sigma) - tr(bread J^T Sigma J) for the
    // model's Sigma, set equal to the SSE found. Independent residuals give
    // back s^2 = SSE / (n - k); a smooth error field, which the fit partly
    // absorbs, a larger variance than the residuals show (at most 10x).
    const ResidualCorrelation& c = out.correlation;
    const double trace = static_cast<double>(n) * c.variance();
    const double absorbed = (bread * middle).trace();
    const double level = trace > 0 ? sse / std::max(trace - absorbed, 0.1 * trace) : 0.0;
    middle *= level;
  }
  Eigen::MatrixXd covariance = bread * middle * bread;
  // A field f moves the estimate by bread J^T f.
  Eigen::MatrixXd systematic = Eigen::MatrixXd::Zero(k, k);
  if (edge_offset.active()) {
    const Eigen::MatrixXd shifts = bread * field_scores;
    systematic = shifts * shifts.transpose();
    covariance += systematic;
    out.edge_offset_absorbed_terms_mm2 = field_scores.transpose() * shifts;
    out.edge_offset_absorbed_mm2 = out.edge_offset_absorbed_terms_mm2.trace();
  }
  out.edge_offset = edge_offset;
  const double s2 = sse / static_cast<double>(n - k);

  const Eigen::VectorXd estimate = geometry::toVector(fitted);
  out.standard_error = Eigen::VectorXd::Constant(m, std::numeric_limits<double>::infinity());
  out.independent_standard_error = out.standard_error;
  out.systematic_standard_error = Eigen::VectorXd::Zero(m);
  out.ci95_lower = Eigen::VectorXd::Constant(m, -std::numeric_limits<double>::infinity());
  out.ci95_upper = Eigen::VectorXd::Constant(m, std::numeric_limits<double>::infinity());
  for (Eigen::Index j = 0; j < m; ++j)
    if (held[static_cast<size_t>(j)]) out.gauge.push_back(names[static_cast<size_t>(j)]);
  std::vector<char> open(static_cast<size_t>(k), 0);
  for (Eigen::Index a = 0; a < k; ++a)
    for (Eigen::Index q = 0; q < k; ++q)
      open[static_cast<size_t>(a)] |= weak[static_cast<size_t>(q)] && std::abs(V(a, q)) > 1e-3;
  for (Eigen::Index a = 0; a < k; ++a) {
    const Eigen::Index j = active[static_cast<size_t>(a)];
    const bool free = open[static_cast<size_t>(a)];
    const double canonical = free ? std::numeric_limits<double>::infinity()
                                  : std::sqrt(std::max(covariance(a, a), 0.0)) / scale[a];
    const double se = canonical * to_raw[j];
    out.standard_error[j] = se;
    out.systematic_standard_error[j] = free ? 0.0 : std::sqrt(std::max(systematic(a, a), 0.0)) / scale[a] * to_raw[j];
    out.independent_standard_error[j] = free ? se : std::sqrt(s2 * bread(a, a)) / scale[a] * to_raw[j];
    out.ci95_lower[j] = estimate[j] - 1.96 * se;
    out.ci95_upper[j] = estimate[j] + 1.96 * se;
    if (!(1.96 * canonical <= uselessHalfWidth(kinds[static_cast<size_t>(j)])))
      out.not_identifiable.push_back(names[static_cast<size_t>(j)]);
  }
  return out;
}

}  // namespace articula::fit
