#include "articula/fit/residual_correlation.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <vector>

#include <Eigen/SVD>

namespace articula::fit {
namespace {

constexpr int kVariogramPoints = 2000;
constexpr int kBins = 32;
constexpr int kMaxCellsAlong = 48;  // cells of at least 1/48 of the extent: at most a few thousand on a cap
constexpr int kSameCellSample = 16;  // points of a cell whose pairs give its mean kernel
// What a fit leaves of a variogram: taken on at most this many points (the
// share it takes up of a smooth field hardly depends on their number), the
// correction repeated this often, and a bin restored to at most this
// multiple of its residuals' variogram.
constexpr int kProjectionPoints = 500;
constexpr int kProjectionRounds = 3;
constexpr double kMostRestored = 5.0;

struct Bin {
  double sum_sq = 0, sum_h = 0;
  long count = 0;
};

// gamma(h) = c0 + c1 (1 - exp(-h/L1)) + c2 (1 - exp(-h/L2)) for given lengths:
// non-negative weighted least squares (every subset of the three terms
// solved free from the 3 x 3 normal equations, the best with no negative
// coefficient kept); returns the weighted residual, or infinity.
double fitAtLengths(const std::vector<double>& h, const std::vector<double>& gamma, const std::vector<double>& weight,
                    double l1, double l2, Eigen::Vector3d& c) {
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  double yy = 0;
  for (size_t k = 0; k < h.size(); ++k) {
    const Eigen::Vector3d x(1.0, 1.0 - std::exp(-h[k] / l1), 1.0 - std::exp(-h[k] / l2));
    normal += weight[k] * x * x.transpose();
    rhs += weight[k] * gamma[k] * x;
    yy += weight[k] * gamma[k] * gamma[k];
  }
  double best = INFINITY;
  for (int subset = 1; subset < 8; ++subset) {
    int cols[3], q = 0;
    for (int j = 0; j < 3; ++j)
      if (subset & (1 << j)) cols[q++] = j;
    Eigen::Matrix3d n = Eigen::Matrix3d::Identity();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    for (int i = 0; i < q; ++i) {
      b[i] = rhs[cols[i]];
      for (int j = 0; j < q; ++j) n(i, j) = normal(cols[i], cols[j]);
    }
    const Eigen::Vector3d solution = n.ldlt().solve(b);
    if (!solution.allFinite() || solution.head(q).minCoeff() < 0) continue;
    Eigen::Vector3d full = Eigen::Vector3d::Zero();
    for (int i = 0; i < q; ++i) full[cols[i]] = solution[i];
    // sum w (y - X c)^2 = y'Wy - 2 c'X'Wy + c'X'WXc.
    const double sse = yy - 2.0 * full.dot(rhs) + full.dot(normal * full);
    if (sse < best) {
      best = sse;
      c = full;
    }
  }
  return best;
}

// A fit's projection on a sample of its points: with Q an orthonormal basis
// of the fitted parameters' directions (the columns of J), residuals of
// errors of covariance K are (I - Q Q^T) e, of covariance
// C = K - Q Q^T K - K Q Q^T + Q Q^T K Q Q^T.
struct Projection {
  Eigen::MatrixX3d x;   // the sample's points
  Eigen::MatrixXd q;    // Q at them
  std::vector<int> bin; // each pair's (i < j, row-major) variogram bin, -1 beyond the last
  std::vector<long> pairs;
  std::vector<double> mean_h;  // each bin's mean distance over the sample's pairs

  // Per bin, the mean over its pairs of the residuals' semivariogram
  // (C_ii + C_jj) / 2 - C_ij for the kernel k(h) of K (k(0) = k0).
  std::vector<double> left(const std::function<double(double)>& kernel, double k0) const {
    const Eigen::Index n = x.rows();
    Eigen::MatrixXd K(n, n);
    for (Eigen::Index i = 0; i < n; ++i) {
      K(i, i) = k0;
      for (Eigen::Index j = i + 1; j < n; ++j) K(i, j) = K(j, i) = kernel((x.row(i) - x.row(j)).norm());
    }
    const Eigen::MatrixXd a = K * q;                   // K Q
    const Eigen::MatrixXd p = q * (q.transpose() * a); // Q Q^T K Q
    Eigen::VectorXd diagonal(n);
    for (Eigen::Index i = 0; i < n; ++i) diagonal[i] = k0 - 2.0 * q.row(i).dot(a.row(i)) + p.row(i).dot(q.row(i));
    std::vector<double> sum(pairs.size(), 0.0);
    size_t at = 0;
    for (Eigen::Index i = 0; i < n; ++i)
      for (Eigen::Index j = i + 1; j < n; ++j, ++at) {
        if (bin[at] < 0) continue;
        const double c = K(i, j) - q.row(i).dot(a.row(j)) - a.row(i).dot(q.row(j)) + p.row(i).dot(q.row(j));
        sum[static_cast<size_t>(bin[at])] += 0.5 * (diagonal[i] + diagonal[j]) - c;
      }
    for (size_t b = 0; b < sum.size(); ++b) sum[b] = pairs[b] > 0 ? sum[b] / static_cast<double>(pairs[b]) : 0.0;
    return sum;
  }
};

Projection fitProjection(const Eigen::MatrixX3d& points, const Eigen::Ref<const Eigen::MatrixXd>& directions,
                         double h_max, unsigned seed) {
  const Eigen::Index n = points.rows();
  std::vector<Eigen::Index> sample(static_cast<size_t>(n));
  std::iota(sample.begin(), sample.end(), Eigen::Index{0});
  if (n > kProjectionPoints) {
    std::mt19937 rng(seed + 1);
    std::shuffle(sample.begin(), sample.end(), rng);
    sample.resize(kProjectionPoints);
  }
  const auto m = static_cast<Eigen::Index>(sample.size());
  Projection out;
  out.x.resize(m, 3);
  Eigen::MatrixXd J(m, directions.cols());
  for (Eigen::Index i = 0; i < m; ++i) {
    out.x.row(i) = points.row(sample[static_cast<size_t>(i)]);
    J.row(i) = directions.row(sample[static_cast<size_t>(i)]);
  }
  // The orthonormal basis of J's column space; directions J leaves weak add nothing.
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeThinU);
  const Eigen::VectorXd& sv = svd.singularValues();
  Eigen::Index rank = 0;
  while (rank < sv.size() && sv[rank] > 1e-10 * sv[0]) ++rank;
  out.q = svd.matrixU().leftCols(rank);
  out.pairs.assign(kBins, 0);
  out.mean_h.assign(kBins, 0.0);
  const double per_bin = kBins / h_max;
  out.bin.reserve(static_cast<size_t>(m * (m - 1) / 2));
  for (Eigen::Index i = 0; i < m; ++i)
    for (Eigen::Index j = i + 1; j < m; ++j) {
      const double h = (out.x.row(i) - out.x.row(j)).norm();
      const int k = static_cast<int>(h * per_bin);
      out.bin.push_back(k < kBins ? k : -1);
      if (k >= kBins) continue;
      ++out.pairs[static_cast<size_t>(k)];
      out.mean_h[static_cast<size_t>(k)] += h;
    }
  for (int k = 0; k < kBins; ++k)
    if (out.pairs[static_cast<size_t>(k)] > 0) out.mean_h[static_cast<size_t>(k)] /= static_cast<double>(out.pairs[static_cast<size_t>(k)]);
  return out;
}

// The nugget + one or two exponentials fitted to a binned variogram.
ResidualCorrelation fitVariogram(const std::vector<double>& h, const std::vector<double>& gamma,
                                 const std::vector<double>& weight, double h_max) {
  ResidualCorrelation model;
  // Lengths from a fiftieth of a bin to half the extent, 40 per grid.
  const double l_min = 0.02 * h_max / kBins, l_max = h_max;
  constexpr int kGrid = 40;
  std::vector<double> grid;
  for (int g = 0; g < kGrid; ++g) grid.push_back(l_min * std::pow(l_max / l_min, g / (kGrid - 1.0)));
  // One scale (L1 = L2), then two; the second kept only where it cuts the
  // weighted misfit to under 0.3 of one scale's: a single field's variogram wobbles at long lags,
  // and a second scale fitted to the wobbles makes n_eff a fraction of the
  // truth (on fields of one known length, tests/lib/fit_test.cpp).
  double one = INFINITY, two = INFINITY;
  Eigen::Vector3d c_one = Eigen::Vector3d::Zero(), c_two = Eigen::Vector3d::Zero();
  double l_one = 0, l_two_a = 0, l_two_b = 0;
  for (size_t i = 0; i < grid.size(); ++i)
    for (size_t j = i; j < grid.size(); ++j) {
      Eigen::Vector3d c;
      const double sse = fitAtLengths(h, gamma, weight, grid[i], grid[j], c);
      if (i == j && sse < one) one = sse, c_one = c, l_one = grid[i];
      if (i != j && sse < two) two = sse, c_two = c, l_two_a = grid[i], l_two_b = grid[j];
    }
  // The grid's steps are 21 % apart: refine each length over the step about it.
  const double step = std::pow(l_max / l_min, 1.0 / (kGrid - 1.0));
  for (int g = -10; g <= 10; ++g) {
    Eigen::Vector3d c;
    const double l = std::clamp(l_one * std::pow(step, g / 10.0), l_min, l_max);
    const double sse = fitAtLengths(h, gamma, weight, l, l, c);
    if (sse < one) one = sse, c_one = c, l_one = l;
  }
  const double a0 = l_two_a, b0 = l_two_b;
  for (int ga = -5; ga <= 5; ++ga)
    for (int gb = -5; gb <= 5; ++gb) {
      Eigen::Vector3d c;
      const double la = std::clamp(a0 * std::pow(step, ga / 5.0), l_min, l_max);
      const double lb = std::clamp(b0 * std::pow(step, gb / 5.0), l_min, l_max);
      if (la >= lb) continue;
      const double sse = fitAtLengths(h, gamma, weight, la, lb, c);
      if (sse < two) two = sse, c_two = c, l_two_a = la, l_two_b = lb;
    }
  constexpr double kSecondScaleGain = 0.3;
  if (two < kSecondScaleGain * one) {
    model.nugget_mm2 = c_two[0];
    model.sill_mm2 = {c_two[1], c_two[2]};
    model.length_mm = {l_two_a, l_two_b};
  } else {
    model.nugget_mm2 = c_one[0];
    model.sill_mm2 = {c_one[1] + c_one[2], 0.0};
    model.length_mm = {l_one, 0.0};
  }
  for (int k = 0; k < 2; ++k)
    if (!(model.sill_mm2[k] > 0)) model.sill_mm2[k] = 0, model.length_mm[k] = 0;
  if (model.sill_mm2[0] == 0 && model.sill_mm2[1] > 0) {  // the one part found goes first
    std::swap(model.sill_mm2[0], model.sill_mm2[1]);
    std::swap(model.length_mm[0], model.length_mm[1]);
  }
  return model;
}

}  // namespace

double nEffectiveAtLength(const Eigen::MatrixX3d& points, double length_mm) {
  const auto n = static_cast<double>(points.rows());
  if (!(length_mm > 0) || points.rows() == 0) return n;
  const double sum = exponentialGram(points, Eigen::MatrixXd::Ones(points.rows(), 1), length_mm)(0, 0);
  return sum > 0 ? std::min(n, n * n / sum) : n;
}

double nEffective(const ResidualCorrelation& c, double covariance_sum) {
  return covariance_sum > 0 ? static_cast<double>(c.n) * static_cast<double>(c.n) * c.variance() / covariance_sum
                            : static_cast<double>(c.n);
}

ResidualCorrelation estimateResidualCorrelation(const Eigen::MatrixX3d& points, const Eigen::VectorXd& residual,
                                                unsigned seed, bool with_n_eff,
                                                const Eigen::Ref<const Eigen::MatrixXd>& fitted_directions) {
  ResidualCorrelation out;
  const Eigen::Index n = points.rows();
  out.n = static_cast<int>(n);
  out.n_eff = static_cast<double>(n);
  if (n < 3) return out;
  std::vector<Eigen::Index> sample(static_cast<size_t>(n));
  std::iota(sample.begin(), sample.end(), Eigen::Index{0});
  if (n > kVariogramPoints) {
    std::mt19937 rng(seed);
    std::shuffle(sample.begin(), sample.end(), rng);
    sample.resize(kVariogramPoints);
  }
  const Eigen::Vector3d extent = points.colwise().maxCoeff() - points.colwise().minCoeff();
  const double h_max = 0.5 * extent.norm();
  if (!(h_max > 0)) return out;
  std::vector<Bin> bins(kBins);
  const double per_bin = kBins / h_max;
  for (size_t i = 0; i < sample.size(); ++i) {
    const Eigen::Vector3d xi = points.row(sample[i]).transpose();
    const double ri = residual[sample[i]];
    for (size_t j = i + 1; j < sample.size(); ++j) {
      const double h = (points.row(sample[j]).transpose() - xi).norm();
      const int k = static_cast<int>(h * per_bin);
      if (k >= kBins) continue;
      const double d = ri - residual[sample[j]];
      bins[static_cast<size_t>(k)].sum_sq += d * d;
      bins[static_cast<size_t>(k)].sum_h += h;
      ++bins[static_cast<size_t>(k)].count;
    }
  }
  std::vector<double> h, gamma, weight;
  std::vector<int> bin_of;
  for (int k = 0; k < kBins; ++k)
    if (const Bin& b = bins[static_cast<size_t>(k)]; b.count && b.sum_sq > 0) {
      const double g = b.sum_sq / (2.0 * static_cast<double>(b.count));
      bin_of.push_back(k);
      h.push_back(b.sum_h / static_cast<double>(b.count));
      gamma.push_back(g);
      weight.push_back(static_cast<double>(b.count));
    }
  if (h.size() < 3) return out;
  out = fitVariogram(h, gamma, weight, h_max);
  out.n = static_cast<int>(n);
  out.n_eff = static_cast<double>(n);
  if (fitted_directions.cols() > 0 && out.sill_mm2.sum() > 0) {
    // The fit took up part of each correlated error: its residuals' variogram
    // rises more slowly and to less than the errors' own, and a model fitted
    // to it straight is too short (0.6-0.7 of the length on caps with errors
    // correlated over 3-5 mm). The variogram divided by what the fit leaves
    // of the model's, and the model fitted again, until it explains the
    // residuals' variogram as the fit's residuals (a fixed point).
    const Projection projection = fitProjection(points, fitted_directions, h_max, seed);
    const std::vector<double> nugget_left = projection.left([](double) { return 0.0; }, 1.0);
    for (int round = 0; round < kProjectionRounds && out.sill_mm2.sum() > 0; ++round) {
      std::vector<double> expected(kBins, 0.0), model(kBins, 0.0);
      for (int b = 0; b < kBins; ++b) expected[static_cast<size_t>(b)] = out.nugget_mm2 * nugget_left[static_cast<size_t>(b)];
      for (int k = 0; k < 2; ++k) {
        if (!(out.sill_mm2[k] > 0)) continue;
        const double length = out.length_mm[k];
        const std::vector<double> left = projection.left([length](double d) { return std::exp(-d / length); }, 1.0);
        for (int b = 0; b < kBins; ++b) expected[static_cast<size_t>(b)] += out.sill_mm2[k] * left[static_cast<size_t>(b)];
      }
      std::vector<double> corrected = gamma;
      for (size_t q = 0; q < h.size(); ++q) {
        const auto b = static_cast<size_t>(bin_of[q]);
        double own = out.nugget_mm2;
        for (int k = 0; k < 2; ++k)
          if (out.sill_mm2[k] > 0) own += out.sill_mm2[k] * (1.0 - std::exp(-projection.mean_h[b] / out.length_mm[k]));
        if (projection.pairs[b] > 0 && expected[b] > 0 && own > 0)
          corrected[q] = gamma[q] * std::clamp(own / expected[b], 1.0, kMostRestored);
      }
      out = fitVariogram(h, corrected, weight, h_max);
      out.n = static_cast<int>(n);
      out.n_eff = static_cast<double>(n);
    }
  }
  // n_eff = n^2 var / sum_ij cov_ij: the variance of the residuals' mean is var / n_eff.
  if (with_n_eff && out.sill_mm2.sum() > 0)
    out.n_eff = nEffective(out, covarianceGram(points, Eigen::MatrixXd::Ones(n, 1), out)(0, 0));
  return out;
}

Eigen::MatrixXd kernelGram(const Eigen::MatrixX3d& points, const Eigen::Ref<const Eigen::MatrixXd>& a,
                           const std::function<double(double)>& kernel, double reach_mm, double cell_mm) {
  const Eigen::Index n = points.rows(), m = a.cols();
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(m, m);
  if (n == 0) return gram;
  const Eigen::Vector3d lo = points.colwise().minCoeff().transpose();
  const double extent = (points.colwise().maxCoeff().transpose() - lo).maxCoeff();
  const double cell = std::max({cell_mm, extent / kMaxCellsAlong, 1e-9});
  // Cells on a dense grid of at most 49^3 (kMaxCellsAlong + 1 along each axis).
  const Eigen::Vector3i dims =
      ((points.colwise().maxCoeff().transpose() - lo) / cell).array().floor().cast<int>() + 1;
  std::vector<int> index(static_cast<size_t>(dims.prod()), -1);
  const auto flat = [&dims](const Eigen::Vector3i& c) {
    return static_cast<size_t>((c[0] * dims[1] + c[1]) * dims[2] + c[2]);
  };
  std::vector<int> cell_of(static_cast<size_t>(n));
  std::vector<Eigen::Vector3i> coords;
  std::vector<std::vector<Eigen::Index>> members;
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3i c =
        ((points.row(i).transpose() - lo) / cell).array().floor().cast<int>().min(dims.array() - 1).max(0);
    int& at = index[flat(c)];
    if (at < 0) {
      at = static_cast<int>(coords.size());
      coords.push_back(c);
      members.emplace_back();
    }
    cell_of[static_cast<size_t>(i)] = at;
    members[static_cast<size_t>(at)].push_back(i);
  }
  const int cells = static_cast<int>(coords.size());
  Eigen::MatrixXd sums = Eigen::MatrixXd::Zero(cells, m);
  Eigen::MatrixX3d centroid = Eigen::MatrixX3d::Zero(cells, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    sums.row(cell_of[static_cast<size_t>(i)]) += a.row(i);
    centroid.row(cell_of[static_cast<size_t>(i)]) += points.row(i);
  }
  // Within a cell: the mean kernel of its points' pairs off the diagonal.
  const double k0 = kernel(0.0);
  Eigen::VectorXd same(cells);
  for (int c = 0; c < cells; ++c) {
    const auto& p = members[static_cast<size_t>(c)];
    centroid.row(c) /= static_cast<double>(p.size());
    const size_t used = std::min<size_t>(p.size(), kSameCellSample);
    double sum = 0;
    int pairs = 0;
    for (size_t i = 0; i < used; ++i)
      for (size_t j = i + 1; j < used; ++j, ++pairs) sum += kernel((points.row(p[i]) - points.row(p[j])).norm());
    same[c] = pairs ? sum / pairs : k0;
  }
  Eigen::VectorXd diagonal_weight(n);
  for (Eigen::Index i = 0; i < n; ++i) diagonal_weight[i] = k0 - same[cell_of[static_cast<size_t>(i)]];
  gram += a.transpose() * diagonal_weight.asDiagonal() * a;
  gram += sums.transpose() * same.asDiagonal() * sums;
  // Between cells: each cell's kernel-weighted sum of its neighbours.
  Eigen::MatrixXd neighbours = Eigen::MatrixXd::Zero(cells, m);
  // Neighbouring cells: the offsets whose nearest points may lie within reach.
  const int r = static_cast<int>(std::ceil(reach_mm / cell));
  std::vector<Eigen::Vector3i> offsets;
  for (int dx = -r; dx <= r; ++dx)
    for (int dy = -r; dy <= r; ++dy)
      for (int dz = -r; dz <= r; ++dz) {
        const Eigen::Vector3d gap = (Eigen::Vector3i(dx, dy, dz).cwiseAbs().array() - 1).max(0).cast<double>() * cell;
        if ((dx || dy || dz) && gap.norm() <= reach_mm) offsets.emplace_back(dx, dy, dz);
      }
  if (offsets.size() >= static_cast<size_t>(cells)) {
    for (int c = 0; c < cells; ++c)
      for (int d = c + 1; d < cells; ++d) {
        const double h = (centroid.row(c) - centroid.row(d)).norm();
        if (h > reach_mm) continue;
        const double k = kernel(h);
        neighbours.row(c) += k * sums.row(d);
        neighbours.row(d) += k * sums.row(c);
      }
  } else {
    for (int c = 0; c < cells; ++c)
      for (const Eigen::Vector3i& offset : offsets) {
        const Eigen::Vector3i o = coords[static_cast<size_t>(c)] + offset;
        if ((o.array() < 0).any() || (o.array() >= dims.array()).any()) continue;
        const int d = index[flat(o)];
        if (d < 0) continue;
        const double h = (centroid.row(c) - centroid.row(d)).norm();
        if (h <= reach_mm) neighbours.row(c) += kernel(h) * sums.row(d);
      }
  }
  gram += sums.transpose() * neighbours;
  return 0.5 * (gram + gram.transpose());
}

Eigen::MatrixXd exponentialGram(const Eigen::MatrixX3d& points, const Eigen::Ref<const Eigen::MatrixXd>& a,
                                double length_mm) {
  return kernelGram(points, a, [length_mm](double h) { return std::exp(-h / length_mm); }, 6.0 * length_mm,
                    0.5 * length_mm);
}

Eigen::MatrixXd covarianceGram(const Eigen::MatrixX3d& points, const Eigen::Ref<const Eigen::MatrixXd>& a,
                               const ResidualCorrelation& c) {
  Eigen::MatrixXd gram = c.nugget_mm2 * (a.transpose() * a);
  for (int k = 0; k < 2; ++k)
    if (c.sill_mm2[k] > 0 && c.length_mm[k] > 0) gram += c.sill_mm2[k] * exponentialGram(points, a, c.length_mm[k]);
  return gram;
}

}  // namespace articula::fit
