#pragma once
// Parameter uncertainty at a least-squares optimum of the signed distances,
// for residuals that are correlated over the surface (residual_correlation.hpp).
//
// With J the derivatives of the distances with respect to the parameters of
// thesis table 3.2, the estimate moves with the residuals e as
// (J^T J)^-1 J^T e, so its covariance is the sandwich
//   (J^T J)^-1 J^T Sigma J (J^T J)^-1,
// Sigma the residuals' covariance. Independent residuals (Sigma = s^2 I)
// give the Gauss-Newton s^2 (J^T J)^-1; on points from a CT surface that is
// several times too narrow. The default, SpatialModel, takes Sigma from the
// fit's own variogram (nugget + exponential), its level set so that the
// expected SSE of the fit equals the SSE found (the fit absorbs the part of
// a smooth error field that looks like a change of shape, which the
// residuals then no longer show). It is the limit of a parametric bootstrap
// with noise of the measured variogram, without the refits. Chosen over the
// two alternatives below by the coverage of its intervals on phantoms of
// known shape (docs/benchmarks.md).
//
// An ovoid's (a, c_x) and (k a, c_x / k) are one surface: c0x and c0y are
// held at their fitted values (listed as `gauge`), and a, b and the other
// ovoid terms get intervals with them held, so that a c0x, the semi-axis,
// is determined when the points determine the shape.
//
// What no interval holds: an offset of the whole surface shared by every
// point (a cortex's edge found outside the bone by the same amount
// everywhere) moves the radii by that offset and is not seen in the
// residuals; docs/user-guide.md names it.
//
// What the residuals cannot show either, but the voxel grid sizes: the
// edge's offset varies smoothly over the surface (partial volume against a
// neighbouring bone, a blur the edge model does not match), and across slices
// thicker than the in-plane voxels it varies with the normal's share across
// them, (n . s)^2 for the slice axis s. Such fields look like a change of
// position or shape and the fit absorbs them. EdgeOffsetField gives their
// size; their effect on the parameters is added to the covariance as a
// systematic component, each field less its mean over the points (the mean
// is the shared offset above).
#include <string>
#include <vector>

#include <Eigen/Core>

#include "articula/fit/residual_correlation.hpp"
#include "articula/geometry/shape.hpp"

namespace articula::fit {

enum class UncertaintyMethod {
  SpatialModel,    // sandwich with the fit's nugget + exponential covariance (the default)
  Independent,     // Gauss-Newton s^2 (J^T J)^-1, independent residuals
  SpatialHac,      // Conley's spatial HAC: residual products of point pairs, Bartlett kernel of reach 3 L
  PatchBootstrap,  // spatial block bootstrap over patches of the cap, linearised (the patch-cluster sandwich)
};
std::string uncertaintyMethodName(UncertaintyMethod m);
/// "spatial-model", "independent", "spatial-hac", "patch-bootstrap"; throws UsageError otherwise.
UncertaintyMethod uncertaintyMethodFromName(const std::string& name);

/// A surface offset beta . n + gamma (n . slice_axis)^2 + delta (n . slice_axis)^3
/// over the surface normals n, its coefficients shared by the points of one
/// scan: beta with standard deviation linear_sd_mm in each direction, gamma
/// across_slices_sd_mm, delta odd_across_slices_sd_mm.
struct EdgeOffsetField {
  Eigen::Vector3d slice_axis = Eigen::Vector3d::UnitZ();  // unit slice normal, LPS
  Eigen::Vector3d spacing_mm = Eigen::Vector3d::Zero();   // the voxels it was sized for (0: none)
  double linear_sd_mm = 0;
  double across_slices_sd_mm = 0;
  double odd_across_slices_sd_mm = 0;  // one side of the slices' offset unlike the other's (a dome's and its far side's)
  bool active() const { return linear_sd_mm > 0 || across_slices_sd_mm > 0 || odd_across_slices_sd_mm > 0; }
};

/// The field's size for a CT's voxels (`spacing_mm`: along the grid's i, j
/// and k, k across the slices) and slice axis (the grid's k direction), set
/// from the phantom benches of three generators (docs/benchmarks.md). Slices
/// thicker than their spacing are taken at their spacing: a label's header
/// holds no thickness.
EdgeOffsetField edgeOffsetField(const Eigen::Vector3d& spacing_mm, const Eigen::Vector3d& slice_axis);

/// Half-widths beyond which an interval says nothing about the head: a
/// radius or position known to only +-10 mm, an angle to +-45 degrees, an
/// exponent to +-1, an ovoid coefficient to +-0.5 (the parameter is then
/// listed as not identifiable).
double uselessHalfWidth(geometry::ParameterKind kind);

struct ParameterUncertainty {
  std::string method;                       // uncertaintyMethodName of the method used
  Eigen::VectorXd standard_error;           // table 3.2 order; infinity where not identifiable or a gauge
  Eigen::VectorXd ci95_lower, ci95_upper;   // estimate -+ 1.96 standard errors
  Eigen::VectorXd independent_standard_error;  // what independent residuals would give, for comparison
  Eigen::VectorXd systematic_standard_error;  // the edge offset field's part of standard_error (0: none)
  EdgeOffsetField edge_offset;              // the field used
  /// The sum of squares of the field that this model's parameters take up,
  /// expected over the field (sum_k sd_k^2 f_k^T J (J^T J)^-1 J^T f_k, mm^2):
  /// what a richer model's gain over a simpler one may owe to the field.
  double edge_offset_absorbed_mm2 = 0;
  /// The same per pair of the field's five terms (beta along x, y, z, gamma,
  /// delta, each at unit standard deviation): A = F^T J (J^T J)^-1 J^T F,
  /// whose trace is the above. A richer model's gain owed to the field is the
  /// quadratic form c^T (A_richer - A_simpler) c over the terms' standard
  /// normal weights c: of mean its trace and variance 2 ||.||_F^2 (empty: no field).
  Eigen::MatrixXd edge_offset_absorbed_terms_mm2;
  std::vector<std::string> not_identifiable;  // parameter names: a near-singular J^T J or a very wide interval
  std::vector<std::string> gauge;           // held at their fitted values: an ovoid's c0x and c0y
  double condition_number = 0;              // of J^T J with unit-scaled columns, gauge held
  ResidualCorrelation correlation;          // of this fit's residuals
  /// An egg's other local optima within the likelihood-ratio bound, whose
  /// centres and semi-axes its intervals take in (other_optima.hpp), and that
  /// bound on the rise of the sum of squares (mm^2; 0: not searched).
  int other_optima = 0;
  double other_optima_bound_mm2 = 0;
};

/// The uncertainty of `fitted` (a least-squares optimum) on `points` (#P x 3);
/// `closest`: the points' closest points on `fitted` if known (#P x 3, else
/// empty), which spares their global search.
/// Throws InputError when there are no more points than parameters.
ParameterUncertainty parameterUncertainty(const geometry::ShapeParameters& fitted, const Eigen::MatrixX3d& points,
                                          const Eigen::MatrixX3d& closest = {},
                                          UncertaintyMethod method = UncertaintyMethod::SpatialModel,
                                          const EdgeOffsetField& edge_offset = {}, int threads = 1);

}  // namespace articula::fit
