#include "articula/geometry/shape.hpp"

#include <cmath>

#include "articula/core/error.hpp"
#include "articula/core/excerpt.hpp"

namespace articula::geometry {

std::string modelName(ShapeModel m) {
  switch (m) {
    case ShapeModel::Sphere: return "sphere";
    case ShapeModel::Ellipsoid: return "ellipsoid";
    case ShapeModel::Superellipsoid: return "superellipsoid";
    case ShapeModel::Ovoid: return "ovoid";
    case ShapeModel::Superovoid: return "superovoid";
  }
  return "unknown";
}

const std::vector<ShapeModel>& allModels() {
  static const std::vector<ShapeModel> models = {ShapeModel::Sphere, ShapeModel::Ellipsoid,
                                                 ShapeModel::Superellipsoid, ShapeModel::Ovoid,
                                                 ShapeModel::Superovoid};
  return models;
}

ShapeModel modelFromName(const std::string& name) {
  for (ShapeModel m : allModels())
    if (modelName(m) == name) return m;
  throw UsageError("unknown shape model '" + excerpt(name) +
                   "': expected one of sphere, ellipsoid, superellipsoid, ovoid, superovoid");
}

namespace {
bool hasExponents(ShapeModel m) { return m == ShapeModel::Superellipsoid || m == ShapeModel::Superovoid; }
bool hasOvoidCoefficients(ShapeModel m) { return m == ShapeModel::Ovoid || m == ShapeModel::Superovoid; }
bool hasOrientation(ShapeModel m) { return m != ShapeModel::Sphere; }
}  // namespace

std::vector<ParameterKind> parameterKinds(ShapeModel m) {
  std::vector<ParameterKind> kinds = {ParameterKind::Radius};
  if (m != ShapeModel::Sphere) kinds.insert(kinds.end(), 2, ParameterKind::Radius);
  if (hasExponents(m)) kinds.insert(kinds.end(), 3, ParameterKind::Exponent);
  if (hasOvoidCoefficients(m))
    for (int axis = 0; axis < 2; ++axis) {
      kinds.insert(kinds.end(), 2, ParameterKind::OvoidScale);
      kinds.insert(kinds.end(), 2, ParameterKind::OvoidCurvature);
    }
  kinds.insert(kinds.end(), 3, ParameterKind::Translation);
  if (hasOrientation(m)) kinds.insert(kinds.end(), 3, ParameterKind::Angle);
  return kinds;
}

std::string parameterUnit(ParameterKind kind) {
  switch (kind) {
    case ParameterKind::Radius:
    case ParameterKind::Translation: return "mm";
    case ParameterKind::Angle: return "rad";
    default: return "";
  }
}

int parameterCount(ShapeModel m) { return static_cast<int>(parameterNames(m).size()); }

std::vector<std::string> gaugeParameterNames(ShapeModel m) {
  return hasOvoidCoefficients(m) ? std::vector<std::string>{"c0x", "c0y"} : std::vector<std::string>{};
}

int freeParameterCount(ShapeModel m) { return parameterCount(m) - static_cast<int>(gaugeParameterNames(m).size()); }

std::vector<std::string> parameterNames(ShapeModel m) {
  std::vector<std::string> names = {"a"};
  if (m != ShapeModel::Sphere) names.insert(names.end(), {"b", "c"});
  if (hasExponents(m)) names.insert(names.end(), {"gamma1", "gamma2", "gamma3"});
  if (hasOvoidCoefficients(m))
    names.insert(names.end(), {"c0x", "c1x", "c2x", "c3x", "c0y", "c1y", "c2y", "c3y"});
  names.insert(names.end(), {"t1", "t2", "t3"});
  if (hasOrientation(m)) names.insert(names.end(), {"phi", "theta", "psi"});
  return names;
}

Eigen::VectorXd toVector(const ShapeParameters& p) {
  std::vector<double> v = {p.radii[0]};
  if (p.model != ShapeModel::Sphere) v.insert(v.end(), {p.radii[1], p.radii[2]});
  if (hasExponents(p.model)) v.insert(v.end(), p.exponents.data(), p.exponents.data() + 3);
  if (hasOvoidCoefficients(p.model)) {
    v.insert(v.end(), p.cx.data(), p.cx.data() + 4);
    v.insert(v.end(), p.cy.data(), p.cy.data() + 4);
  }
  v.insert(v.end(), p.center.data(), p.center.data() + 3);
  if (hasOrientation(p.model)) v.insert(v.end(), p.angles.data(), p.angles.data() + 3);
  return Eigen::Map<Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

ShapeParameters fromVector(ShapeModel m, const Eigen::VectorXd& x) {
  if (x.size() != parameterCount(m))
    throw UsageError(modelName(m) + " expects " + std::to_string(parameterCount(m)) + " parameters, found " +
                     std::to_string(x.size()));
  ShapeParameters p;
  p.model = m;
  Eigen::Index i = 0;
  if (m == ShapeModel::Sphere) {
    p.radii.setConstant(x[i++]);
  } else {
    p.radii = x.segment<3>(i);
    i += 3;
  }
  if (hasExponents(m)) { p.exponents = x.segment<3>(i); i += 3; }
  if (hasOvoidCoefficients(m)) {
    p.cx = x.segment<4>(i);
    p.cy = x.segment<4>(i + 4);
    i += 8;
  }
  p.center = x.segment<3>(i);
  i += 3;
  if (hasOrientation(m)) p.angles = x.segment<3>(i);
  return p;
}

Eigen::Vector3d semiAxes(const ShapeParameters& p) {
  if (p.model == ShapeModel::Sphere) return Eigen::Vector3d::Constant(p.radii[0]);
  const bool egg = contains(p.model, ShapeModel::Ovoid);
  return {p.radii[0] * (egg ? p.cx[0] : 1.0), p.radii[1] * (egg ? p.cy[0] : 1.0), p.radii[2]};
}

bool contains(ShapeModel general, ShapeModel special) {
  if (general == special || special == ShapeModel::Sphere) return true;
  switch (general) {
    case ShapeModel::Superovoid: return true;
    case ShapeModel::Superellipsoid:
    case ShapeModel::Ovoid: return special == ShapeModel::Ellipsoid;
    default: return false;
  }
}

ShapeParameters promote(const ShapeParameters& p, ShapeModel target) {
  if (!contains(target, p.model))
    throw UsageError("a " + modelName(target) + " does not contain a " + modelName(p.model));
  ShapeParameters q = p;
  q.model = target;
  if (p.model == ShapeModel::Sphere) {
    q.radii.setConstant(p.radii[0]);
    q.angles.setZero();
  }
  if (!hasExponents(p.model)) q.exponents.setConstant(2.0);
  if (!hasOvoidCoefficients(p.model)) {
    q.cx = Eigen::Vector4d(1, 0, 0, 0);
    q.cy = Eigen::Vector4d(1, 0, 0, 0);
  }
  return q;
}

double minimumOnUnitInterval(const Eigen::Vector4d& c) {
  auto p = [&c](double z) { return c[0] + z * (c[1] + z * (c[2] + z * c[3])); };
  double best = std::min(p(-1.0), p(1.0));
  // Critical points: c1 + 2 c2 z + 3 c3 z^2 = 0.
  const double qa = 3.0 * c[3], qb = 2.0 * c[2], qc = c[1];
  if (qa == 0.0) {
    if (qb != 0.0) {
      double z = -qc / qb;
      if (z > -1.0 && z < 1.0) best = std::min(best, p(z));
    }
  } else {
    double disc = qb * qb - 4.0 * qa * qc;
    if (disc >= 0.0) {
      double s = std::sqrt(disc);
      for (double z : {(-qb - s) / (2.0 * qa), (-qb + s) / (2.0 * qa)})
        if (z > -1.0 && z < 1.0) best = std::min(best, p(z));
    }
  }
  return best;
}

namespace {
void requireFinite(const std::string& name, double v) {
  if (!std::isfinite(v)) throw InvalidParameter(name, "a finite number", v);
}
void requireRange(const std::string& name, double v, double lo, double hi) {
  requireFinite(name, v);
  if (v < lo || v > hi)
    throw InvalidParameter(name, "a value in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]", v);
}
void validateDenominator(const char* axis, const Eigen::Vector4d& c) {
  const std::string suffix(axis);
  requireRange("c0" + suffix, c[0], 0.0, 1.0);
  requireRange("c1" + suffix, c[1], 0.0, 1.0);
  requireRange("c2" + suffix, c[2], -0.1, 0.1);
  requireRange("c3" + suffix, c[3], -0.1, 0.1);
  double lowest = minimumOnUnitInterval(c);
  if (!(lowest > 1e-9))
    throw InvalidParameter("c0" + suffix + "..c3" + suffix,
                           "c0" + suffix + " + c1" + suffix + " z + c2" + suffix + " z^2 + c3" + suffix +
                               " z^3 > 0 for every local z in [-1, 1] (the superovoid's closed "
                               "component); its minimum there",
                           lowest);
}
}  // namespace

void validate(const ShapeParameters& p) {
  const char* radius_names[3] = {"a", "b", "c"};
  const int radius_count = p.model == ShapeModel::Sphere ? 1 : 3;
  for (int i = 0; i < radius_count; ++i) {
    requireFinite(radius_names[i], p.radii[i]);
    if (!(p.radii[i] > 0.0)) throw InvalidParameter(radius_names[i], "a radius > 0 mm", p.radii[i]);
  }
  if (hasExponents(p.model)) {
    const char* names[3] = {"gamma1", "gamma2", "gamma3"};
    for (int i = 0; i < 3; ++i) {
      requireFinite(names[i], p.exponents[i]);
      if (!(p.exponents[i] >= 2.0))
        throw InvalidParameter(names[i], "an exponent >= 2 (smooth convex)", p.exponents[i]);
    }
  }
  if (hasOvoidCoefficients(p.model)) {
    validateDenominator("x", p.cx);
    validateDenominator("y", p.cy);
  }
  const char* t_names[3] = {"t1", "t2", "t3"};
  const char* a_names[3] = {"phi", "theta", "psi"};
  for (int i = 0; i < 3; ++i) {
    requireFinite(t_names[i], p.center[i]);
    requireFinite(a_names[i], p.angles[i]);
  }
}

}  // namespace articula::geometry
