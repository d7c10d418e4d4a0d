#include "articula/fit/other_optima.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <boost/math/distributions/normal.hpp>

#include "articula/fit/residual_correlation.hpp"
#include "articula/geometry/pose.hpp"

namespace articula::fit {
namespace {

constexpr double kChiSquare1At95 = 3.841458820694124;  // the 95 % point of chi^2 with one degree of freedom
constexpr double kZ95 = 1.96;                          // as parameterUncertainty's intervals

Eigen::Index indexOf(const std::vector<std::string>& names, const std::string& name) {
  const auto at = std::find(names.begin(), names.end(), name);
  return at == names.end() ? -1 : at - names.begin();
}

// What takes radius i of `p` to its semi-axis (an egg's c0x, c0y; else 1).
double semiAxisFactor(const geometry::ShapeParameters& p, int i) { return geometry::semiAxes(p)[i] / p.radii[i]; }

}  // namespace

double likelihoodRatioBoundMm2(const geometry::ShapeParameters& fitted, const ParameterUncertainty& u, double sse_mm2,
                               Eigen::Index points) {
  const auto names = geometry::parameterNames(fitted.model);
  if (u.standard_error.size() != static_cast<Eigen::Index>(names.size())) return 0;
  Eigen::Index held = -1;
  for (const char* t : {"t1", "t2", "t3"}) {
    const Eigen::Index j = indexOf(names, t);
    if (std::isfinite(u.standard_error[j]) && u.standard_error[j] > 0 &&
        (held < 0 || u.standard_error[j] > u.standard_error[held]))
      held = j;
  }
  const auto free = static_cast<Eigen::Index>(names.size() - u.gauge.size());
  if (held < 0 || points <= free) return 0;
  const double se = u.standard_error[held], independent = u.independent_standard_error[held];
  const double design = independent > 0 && std::isfinite(independent) ? std::max(1.0, std::pow(se / independent, 2)) : 1.0;
  return kChiSquare1At95 * sse_mm2 / static_cast<double>(points - free) * design;
}

bool couldBeTheTruth(const Eigen::VectorXd& own, const Eigen::VectorXd& theirs, const Eigen::MatrixX3d& points,
                     const ResidualCorrelation& errors, int alternatives) {
  const double level = 0.05 / std::max(alternatives, 1);
  const double z = boost::math::quantile(boost::math::complement(boost::math::normal(), level));
  const Eigen::VectorXd d = own - theirs;
  const double variance = covarianceGram(points, d, errors)(0, 0);
  return variance > 0 && -theirs.dot(d) <= z * std::sqrt(variance);
}

void spanOtherOptima(const geometry::ShapeParameters& fitted, double bound_mm2, const std::vector<OtherOptimum>& others,
                     ParameterUncertainty& u) {
  const auto names = geometry::parameterNames(fitted.model);
  const auto kinds = geometry::parameterKinds(fitted.model);
  if (u.standard_error.size() != static_cast<Eigen::Index>(names.size())) return;
  const Eigen::Matrix3d R = geometry::rotationFromAngles(fitted.angles);
  const Eigen::Index radius[3] = {indexOf(names, "a"), indexOf(names, "b"), indexOf(names, "c")};
  std::vector<char> widened(names.size(), 0);
  // Parameter j's interval (in the reported optimum's own units) to take in
  // value -+ 1.96 se (the value alone where the other optimum leaves it undetermined).
  const auto takeIn = [&](Eigen::Index j, double value, double se) {
    if (j < 0 || !std::isfinite(u.standard_error[j]) || !std::isfinite(value)) return;
    const double half = std::isfinite(se) ? kZ95 * se : 0.0;
    const double lower = value - half, upper = value + half;
    if (lower < u.ci95_lower[j] || upper > u.ci95_upper[j]) widened[static_cast<size_t>(j)] = 1;
    u.ci95_lower[j] = std::min(u.ci95_lower[j], lower);
    u.ci95_upper[j] = std::max(u.ci95_upper[j], upper);
  };
  int spanned = 0;
  for (const OtherOptimum& other : others) {
    const ParameterUncertainty& v = other.uncertainty;
    if (other.parameters.model != fitted.model ||
        v.standard_error.size() != u.standard_error.size())
      continue;
    for (int i = 0; i < 3; ++i) {
      const Eigen::Index t = indexOf(names, "t" + std::to_string(i + 1));
      takeIn(t, other.parameters.center[i], v.standard_error[t]);
    }
    if (radius[1] >= 0 && radius[2] >= 0) {
      const Eigen::Matrix3d S = geometry::rotationFromAngles(other.parameters.angles);
      for (int i = 0; i < 3; ++i) {
        int k = 0;  // the other optimum's axis most nearly along axis i
        for (int m = 1; m < 3; ++m)
          if (std::abs(S.col(m).dot(R.col(i))) > std::abs(S.col(k).dot(R.col(i)))) k = m;
        const double own = semiAxisFactor(fitted, i), theirs = semiAxisFactor(other.parameters, k);
        takeIn(radius[i], other.parameters.radii[k] * theirs / own, v.standard_error[radius[k]] * theirs / own);
      }
    }
    ++spanned;
  }
  for (size_t j = 0; j < names.size(); ++j) {
    if (!widened[j]) continue;
    const auto k = static_cast<Eigen::Index>(j);
    u.standard_error[k] = (u.ci95_upper[k] - u.ci95_lower[k]) / (2 * kZ95);
    double canonical = u.standard_error[k];
    for (int i = 0; i < 3; ++i)
      if (radius[i] == k) canonical *= semiAxisFactor(fitted, i);
    if (!(kZ95 * canonical <= uselessHalfWidth(kinds[j])) &&
        std::find(u.not_identifiable.begin(), u.not_identifiable.end(), names[j]) == u.not_identifiable.end())
      u.not_identifiable.push_back(names[j]);
  }
  u.other_optima = spanned;
  u.other_optima_bound_mm2 = bound_mm2;
}

}  // namespace articula::fit
