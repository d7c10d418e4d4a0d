#include "articula/testsupport/interval_errors.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "articula/geometry/pose.hpp"

namespace articula::fit {

using geometry::ShapeModel;

IntervalErrors intervalErrors(const geometry::ShapeParameters& fitted, const ParameterUncertainty& uncertainty,
                              const geometry::ShapeParameters& truth, double offset_mm) {
  const auto names = geometry::parameterNames(fitted.model);
  // The interval's half width on the side of the estimate where the error
  // puts the truth, over 1.96 (the standard error where the interval is
  // symmetric; an egg's may not be, fit/other_optima.hpp).
  const Eigen::VectorXd estimate = geometry::toVector(fitted);
  auto se_of = [&](const std::string& name, double error) -> double {
    const auto at = std::find(names.begin(), names.end(), name);
    if (at == names.end()) return NAN;
    const auto k = at - names.begin();
    return (error > 0 ? estimate[k] - uncertainty.ci95_lower[k] : uncertainty.ci95_upper[k] - estimate[k]) / 1.96;
  };
  IntervalErrors e;
  for (int i = 0; i < 3; ++i) {
    const double error = fitted.center[i] - truth.center[i];
    e.centre_z[i] = error / se_of("t" + std::to_string(i + 1), error);
  }
  // A sphere has one rotation for any angles: its axes are the truth's.
  const Eigen::Matrix3d Rt = geometry::rotationFromAngles(truth.angles);
  const Eigen::Matrix3d Rf = fitted.model == ShapeModel::Sphere ? Rt : geometry::rotationFromAngles(fitted.angles);
  const Eigen::Vector3d true_semi = geometry::semiAxes(truth), semi = geometry::semiAxes(fitted);
  const bool ovoid = fitted.model == ShapeModel::Ovoid || fitted.model == ShapeModel::Superovoid;
  const char* axis_names[3] = {"a", "b", "c"};
  for (int i = 0; i < 3; ++i) {
    // The fitted axis along true axis i.
    int j = i;
    if (fitted.model != ShapeModel::Sphere) {
      j = 0;
      for (int k = 1; k < 3; ++k)
        if (std::abs(Rf.col(k).dot(Rt.col(i))) > std::abs(Rf.col(j).dot(Rt.col(i)))) j = k;
    }
    const auto z = [&](double error) {
      double se = se_of(fitted.model == ShapeModel::Sphere ? "a" : axis_names[j], error);
      if (ovoid && j < 2) se *= j == 0 ? fitted.cx[0] : fitted.cy[0];  // of the semi-axis, c0 held
      return error / se;
    };
    e.semi_axis_z[i] = z(semi[j] - true_semi[i]);
    e.semi_axis_less_offset_z[i] = z(semi[j] - true_semi[i] - offset_mm);
  }
  return e;
}

}  // namespace articula::fit
