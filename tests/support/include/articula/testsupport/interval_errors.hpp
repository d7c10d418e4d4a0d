#pragma once
// How far a fit lies from the true shape in its own standard errors, for
// the benchmarks that measure interval coverage (bench-coverage on phantom
// CTs, bench-selection-caps on caps with correlated errors).
#include <Eigen/Core>

#include "articula/fit/uncertainty.hpp"
#include "articula/geometry/shape.hpp"

namespace articula::fit {

struct IntervalErrors {
  Eigen::Vector3d centre_z;     // (fitted - true) / standard error, per LPS coordinate
  Eigen::Vector3d semi_axis_z;  // per true axis: the fitted semi-axis along it, less the true, over its standard error
  Eigen::Vector3d semi_axis_less_offset_z;  // the same with the true semi-axes moved by `offset_mm`
};

/// The errors of `fitted` (with `uncertainty`, from parameterUncertainty)
/// against `truth`, a model `fitted.model` contains; `offset_mm`: a shared
/// surface offset no interval holds (the points' median signed distance to
/// the true surface), taken out of the third field.
IntervalErrors intervalErrors(const geometry::ShapeParameters& fitted, const ParameterUncertainty& uncertainty,
                              const geometry::ShapeParameters& truth, double offset_mm = 0.0);

}  // namespace articula::fit
