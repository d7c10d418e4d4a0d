#include "articula/contact/scenario.hpp"

#include <cmath>

#include <Eigen/Geometry>

#include "articula/core/error.hpp"

namespace articula::contact {

using Eigen::Vector3d;

namespace {

struct Spec {
  const char* name;
  Vector3d radii_i, exponents_i, radii_j, exponents_j;
  Vector3d spin_axis_j;  // local axis body j turns about
  bool orbit;            // j orbits i (in the x-y plane) instead of moving along [1 1 1]
};

const std::vector<Spec>& specs() {
  static const Vector3d two = Vector3d::Constant(2.0), x = Vector3d::UnitX(), z = Vector3d::UnitZ();
  static const Vector3d d111 = Vector3d::Ones().normalized();
  static const std::vector<Spec> all = {
      {"table5.3-1", {3, 3, 3}, two, {0.5, 0.5, 0.5}, two, x, true},
      {"table5.3-2", {3, 3, 3}, two, {0.5, 0.5, 0.5}, two, x, false},
      {"table5.3-3", {5, 5, 2}, two, {5, 5, 2}, two, x, false},
      {"table5.3-4", {1, 5, 5}, two, {5, 1, 5}, two, x, false},
      {"table5.4-1", {1.0, 1.0, 1.0}, Vector3d::Constant(2.4), {1.5, 2.1, 1.9}, Vector3d::Constant(3.0), d111, false},
      {"table5.4-2", {0.4, 1.1, 1.1}, Vector3d::Constant(3.2), {1.0, 1.0, 0.4}, Vector3d::Constant(3.2), z, false},
      {"table5.4-3", {4.1, 1.1, 1.1}, Vector3d::Constant(2.5), {1.0, 1.0, 4.0}, Vector3d::Constant(3.2), z, false},
  };
  return all;
}

// Extent of a body along the global unit direction v (its support value about the centre).
double extent(const ConvexShape& s, const Vector3d& v) { return v.dot(toGlobal(s, supportCanonical(s, v)) - s.center); }

}  // namespace

const std::vector<std::string>& scenarioNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const Spec& s : specs()) n.push_back(s.name);
    return n;
  }();
  return names;
}

ScenarioPair scenarioPair(const std::string& name, int k, int steps) {
  for (const Spec& s : specs()) {
    if (name != s.name) continue;
    const double phase = 2.0 * M_PI * k / steps;
    const Eigen::Matrix3d Ri = Eigen::AngleAxisd(phase, Vector3d::UnitX()).toRotationMatrix();
    const Eigen::Matrix3d Rj = Eigen::AngleAxisd(1.7 * phase, s.spin_axis_j.normalized()).toRotationMatrix();
    ScenarioPair p{makeConvexShape(Vector3d::Zero(), Ri, s.radii_i, s.exponents_i),
                   makeConvexShape(Vector3d::Zero(), Rj, s.radii_j, s.exponents_j)};
    // Direction from i to j: an orbit in the x-y plane, or fixed along [1 1 1].
    const Vector3d dir = s.orbit ? Vector3d(std::cos(phase), std::sin(phase), 0.0) : Vector3d::Ones().normalized();
    // Centre distance so that the gap along dir goes 0.25 -> -0.25 -> 0.25 mm
    // (the support extents along dir make it exact for the gap measured along dir).
    const double gap = 0.25 * std::cos(phase);
    p.j.center = dir * (extent(p.i, dir) + extent(p.j, -dir) + gap);
    return p;
  }
  std::string list;
  for (const auto& n : scenarioNames()) list += (list.empty() ? "" : ", ") + n;
  throw UsageError("--scenario: unknown name '" + name + "' (expected one of " + list + ")");
}

}  // namespace articula::contact
