#pragma once
// The fitting hierarchy of thesis ch. 3: sphere -> ellipsoid ->
// {superellipsoid, ovoid} -> superovoid, their parameters named as in thesis
// table 3.2, and the checks that keep them valid.
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace articula::geometry {

enum class ShapeModel { Sphere, Ellipsoid, Superellipsoid, Ovoid, Superovoid };

/// "sphere", "ellipsoid", "superellipsoid", "ovoid", "superovoid".
std::string modelName(ShapeModel model);
/// Inverse of modelName; throws UsageError naming the valid names.
ShapeModel modelFromName(const std::string& name);
/// All five, in hierarchy order.
const std::vector<ShapeModel>& allModels();

/// Parameters of any model of the hierarchy (a superset: the superovoid's).
/// A model ignores what it does not use; the defaults make every model the
/// special case of its parent (exponents 2, c0 = 1, c1..c3 = 0).
struct ShapeParameters {
  ShapeModel model = ShapeModel::Sphere;
  Eigen::Vector3d radii = Eigen::Vector3d::Ones();                // a, b, c (mm); sphere: a
  Eigen::Vector3d exponents = Eigen::Vector3d::Constant(2.0);     // gamma1, gamma2, gamma3
  Eigen::Vector4d cx = Eigen::Vector4d(1.0, 0.0, 0.0, 0.0);       // c0x, c1x, c2x, c3x
  Eigen::Vector4d cy = Eigen::Vector4d(1.0, 0.0, 0.0, 0.0);       // c0y, c1y, c2y, c3y
  Eigen::Vector3d center = Eigen::Vector3d::Zero();               // t1, t2, t3 (mm)
  Eigen::Vector3d angles = Eigen::Vector3d::Zero();               // phi, theta, psi (rad)
};

/// Number of parameters M of thesis table 3.2: 4, 9, 12, 17, 20.
int parameterCount(ShapeModel model);
/// The parameters a fit holds fixed because the surface does not pin them
/// down: an ovoid's (a, c_jx) and (k a, c_jx / k) are one surface, and so for
/// b and c_jy, so c0x and c0y (the gauge); none for the other models.
std::vector<std::string> gaugeParameterNames(ShapeModel model);
/// The parameters a surface pins down: parameterCount less the gauge (4, 9, 12, 15, 18).
int freeParameterCount(ShapeModel model);
/// Names in table 3.2 order, e.g. {"a","b","c","gamma1",...,"t1","t2","t3","phi","theta","psi"}.
std::vector<std::string> parameterNames(ShapeModel model);

/// What a parameter of thesis table 3.2 is, for the code that bounds,
/// steps, converts or labels it (never by the letters of its name).
enum class ParameterKind {
  Radius,           // a, b, c (mm)
  Exponent,         // gamma1..3
  OvoidScale,       // c0x, c1x, c0y, c1y: the ovoid's constant and linear terms
  OvoidCurvature,   // c2x, c3x, c2y, c3y: its quadratic and cubic terms
  Translation,      // t1..3 (mm)
  Angle,            // phi, theta, psi (rad)
};
/// The kind of each parameter, in the order of parameterNames(model).
std::vector<ParameterKind> parameterKinds(ShapeModel model);
/// "mm", "rad" or "" (dimensionless).
std::string parameterUnit(ParameterKind kind);
/// The parameter vector lambda of table 3.2 (angles in radians).
Eigen::VectorXd toVector(const ShapeParameters& p);
/// Inverse of toVector; throws UsageError if the length is not parameterCount(model).
ShapeParameters fromVector(ShapeModel model, const Eigen::VectorXd& lambda);
/// The same shape as a member of a more general model (e.g. an ellipsoid as a
/// superovoid); throws UsageError if `target` does not contain p.model.
ShapeParameters promote(const ShapeParameters& p, ShapeModel target);
/// True if `general` contains `special` in the hierarchy (a model contains itself).
bool contains(ShapeModel general, ShapeModel special);
/// The half widths through the local origin along the local axes: an
/// ovoid's a c0x, b c0y and c (its a and b share their scale with c0x and
/// c0y; only the products are its shape); a sphere's radius three times.
Eigen::Vector3d semiAxes(const ShapeParameters& p);

/// Throws InvalidParameter naming the first parameter out of range:
/// radii finite and > 0; exponents finite and >= 2; ovoid coefficients within
/// the thesis bounds (0 <= c0, c1 <= 1; -0.1 <= c2, c3 <= 0.1) and with
/// denominators c0 + c1 z + c2 z^2 + c3 z^3 > 0 on local z in [-1, 1]; every
/// value finite.
void validate(const ShapeParameters& p);

/// Smallest value of c0 + c1 z + c2 z^2 + c3 z^3 over z in [-1, 1].
double minimumOnUnitInterval(const Eigen::Vector4d& c);

}  // namespace articula::geometry
