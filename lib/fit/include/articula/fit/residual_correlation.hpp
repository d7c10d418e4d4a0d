#pragma once
// The spatial correlation of a fit's residuals over the surface. Points
// taken from a CT surface do not err independently: blur, partial volume,
// smoothing and anisotropic voxels move neighbouring points together, so a
// thousand points carry far less than a thousand points' information.
//
// Measured per fit by the empirical semivariogram of the signed residuals
// against the Euclidean distance between points (on a head's cap, at the
// lengths that matter, within a few per cent of the geodesic one), fitted
// with a nugget and two exponentials:
//   gamma(h) = nugget + sill_1 (1 - exp(-h / L_1)) + sill_2 (1 - exp(-h / L_2)),
// i.e. residuals of variance nugget + sill_1 + sill_2 whose correlated parts
// fall off as exp(-h / L). Two scales, since a CT surface has both: blur and
// partial volume tie points within a voxel or two (L_1 about a millimetre),
// and the direction-dependent error of anisotropic voxels and a thin cortex
// varies over the whole cap. Both lengths are kept within half the points'
// extent: a longer one would be a constant shared by every point, which the
// residuals cannot show (the radius absorbs it), and whose size the
// variogram's slope leaves open. From it: the effective number of independent points
// n_eff = n^2 var / sum_ij cov(r_i, r_j) (the points that would give the
// residuals' mean as precisely), and the sums of kernels over point pairs
// the sandwich covariance needs (kernelGram), accumulated over cells so that
// 10^5 points cost about what 10^3 do.
#include <cmath>
#include <functional>

#include <Eigen/Cholesky>
#include <Eigen/Core>

namespace articula::fit {

struct ResidualCorrelation {
  double nugget_mm2 = 0;                  // variance without spatial correlation (noise)
  Eigen::Vector2d sill_mm2{0, 0};         // variances of the correlated parts, shorter length first
  Eigen::Vector2d length_mm{0, 0};        // their correlation lengths (0: that part absent)
  double n_eff = 0;                       // effective number of independent points
  int n = 0;                              // points
  double variance() const { return nugget_mm2 + sill_mm2.sum(); }
  double correlatedShare() const { return variance() > 0 ? sill_mm2.sum() / variance() : 0.0; }
  /// The length of the one exponential whose correlated area (the integral
  /// of the correlation over the surface, 2 pi L^2) the two parts share.
  double effectiveLength() const {
    const double s = sill_mm2.sum();
    return s > 0 ? std::sqrt((sill_mm2.array() * length_mm.array().square()).sum() / s) : 0.0;
  }
};

/// The semivariogram of `residual` (#P) over `points` (#P x 3, mm) and its
/// nugget + two-exponential fit (non-negative least squares over 32 distance
/// bins up to half the points' extent, weighted by the bins' pair counts, the
/// lengths searched on a log grid). More than 2,000 points: the variogram
/// is taken from a seeded random 2,000 of them; n_eff from all (left at n
/// with `with_n_eff` false, for a caller that sums the covariance itself:
/// nEffective).
///
/// `fitted_directions` (#P x k, optional): the derivatives of the residuals
/// with respect to the k parameters of the fit they are left by. The fit
/// takes up the part of a correlated error that looks like a change of its
/// parameters, so its residuals' variogram rises more slowly than the
/// errors'; with them, the model is the one whose errors, less what the fit
/// takes up, give the residuals' variogram (three rounds of fitting the
/// variogram divided by what the fit leaves of the model's own).
ResidualCorrelation estimateResidualCorrelation(const Eigen::MatrixX3d& points, const Eigen::VectorXd& residual,
                                                unsigned seed = 1, bool with_n_eff = true,
                                                const Eigen::Ref<const Eigen::MatrixXd>& fitted_directions = Eigen::MatrixXd());

/// n_eff = n^2 var / sum_ij cov_ij from the sum of the covariance over
/// every pair of n points (1^T Sigma 1).
double nEffective(const ResidualCorrelation& c, double covariance_sum);

/// n_eff of `points` for errors wholly correlated as exp(-h / length_mm):
/// n^2 / sum_ij exp(-|x_i - x_j| / L) (about the cap's area over 2 pi L^2
/// on a cap much wider than L; n for L = 0).
double nEffectiveAtLength(const Eigen::MatrixX3d& points, double length_mm);

/// sum_i sum_j k(|x_i - x_j|) a_i a_j^T (#m x #m; a_i the rows of `a`, k(0)
/// included), for a kernel that vanishes beyond `reach_mm`. Pairs are taken
/// cell by cell (cells of `cell_mm`, at least 1/48 of the extent): between
/// two cells at their centroids' distance, within one at the mean kernel of
/// its points' pairs, exactly on the diagonal.
Eigen::MatrixXd kernelGram(const Eigen::MatrixX3d& points, const Eigen::Ref<const Eigen::MatrixXd>& a,
                           const std::function<double(double)>& kernel, double reach_mm, double cell_mm);

/// The exponential kernel exp(-h / L), cut at 6 L (where it has fallen to
/// 0.25 %), through kernelGram.
Eigen::MatrixXd exponentialGram(const Eigen::MatrixX3d& points, const Eigen::Ref<const Eigen::MatrixXd>& a,
                                double length_mm);

/// a^T Sigma a for the covariance Sigma of `c` (nugget on the diagonal, each
/// correlated part through exponentialGram).
Eigen::MatrixXd covarianceGram(const Eigen::MatrixX3d& points, const Eigen::Ref<const Eigen::MatrixXd>& a,
                               const ResidualCorrelation& c);

}  // namespace articula::fit
