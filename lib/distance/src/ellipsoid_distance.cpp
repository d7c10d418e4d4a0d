#include "articula/distance/ellipsoid_distance.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

namespace articula::distance {
namespace {

// The root s of G(s) = sum_i (r_i z_i / (s + r_i))^2 - 1 on s > -1 (r_last = 1,
// r_i >= 1, z_i > 0). G is convex and decreasing there, so Newton from the
// left end of Eberly's bracket climbs monotonically; bisection takes over if
// rounding ever throws a step out of the bracket.
template <int N>
double rootOfSecular(const std::array<double, N>& r, const std::array<double, N>& z, double g) {
  std::array<double, N> n{};
  for (int i = 0; i < N; ++i) n[i] = r[i] * z[i];
  double lo = z[N - 1] - 1.0;
  double hi = 0.0;
  if (g >= 0.0) {
    double len2 = 0.0;
    for (int i = 0; i < N; ++i) len2 += n[i] * n[i];
    hi = std::sqrt(len2) - 1.0;
  }
  double s = lo;
  for (int iteration = 0; iteration < 200; ++iteration) {
    double G = -1.0, dG = 0.0;
    for (int i = 0; i < N; ++i) {
      const double inv = 1.0 / (s + r[i]);
      const double t = n[i] * inv;
      G += t * t;
      dG -= 2.0 * t * t * inv;
    }
    if (G > 0.0) lo = s;
    else if (G < 0.0) hi = s;
    else return s;
    double next = s - G / dG;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (next == s || hi - lo <= 4.0 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::fabs(s)))
      return next;
    s = next;
  }
  return s;
}

// 2-D case (Eberly's DistancePointEllipse), e0 >= e1, y >= 0.
double ellipse(double e0, double e1, double y0, double y1, double& x0, double& x1) {
  if (y1 > 0.0) {
    if (y0 > 0.0) {
      const double z0 = y0 / e0, z1 = y1 / e1, g = z0 * z0 + z1 * z1 - 1.0;
      if (g != 0.0) {
        const double r0 = (e0 / e1) * (e0 / e1);
        const double s = rootOfSecular<2>({r0, 1.0}, {z0, z1}, g);
        x0 = r0 * y0 / (s + r0);
        x1 = y1 / (s + 1.0);
        return std::hypot(x0 - y0, x1 - y1);
      }
      x0 = y0;
      x1 = y1;
      return 0.0;
    }
    x0 = 0.0;
    x1 = e1;
    return std::fabs(y1 - e1);
  }
  const double numer0 = e0 * y0, denom0 = e0 * e0 - e1 * e1;
  if (numer0 < denom0) {
    const double xde0 = numer0 / denom0;
    x0 = e0 * xde0;
    x1 = e1 * std::sqrt(std::max(0.0, 1.0 - xde0 * xde0));
    return std::hypot(x0 - y0, x1);
  }
  x0 = e0;
  x1 = 0.0;
  return std::fabs(y0 - e0);
}

// 3-D case (Eberly's DistancePointEllipsoid), e0 >= e1 >= e2, y >= 0.
double ellipsoid(const double e[3], const double y[3], double x[3]) {
  if (y[2] > 0.0) {
    if (y[1] > 0.0) {
      if (y[0] > 0.0) {
        const double z0 = y[0] / e[0], z1 = y[1] / e[1], z2 = y[2] / e[2];
        const double g = z0 * z0 + z1 * z1 + z2 * z2 - 1.0;
        if (g != 0.0) {
          const double r0 = (e[0] / e[2]) * (e[0] / e[2]), r1 = (e[1] / e[2]) * (e[1] / e[2]);
          const double s = rootOfSecular<3>({r0, r1, 1.0}, {z0, z1, z2}, g);
          x[0] = r0 * y[0] / (s + r0);
          x[1] = r1 * y[1] / (s + r1);
          x[2] = y[2] / (s + 1.0);
          return std::sqrt((x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) +
                           (x[2] - y[2]) * (x[2] - y[2]));
        }
        x[0] = y[0];
        x[1] = y[1];
        x[2] = y[2];
        return 0.0;
      }
      x[0] = 0.0;
      const double d = ellipse(e[1], e[2], y[1], y[2], x[1], x[2]);
      return std::hypot(d, y[0]);
    }
    x[1] = 0.0;
    if (y[0] > 0.0) {
      const double d = ellipse(e[0], e[2], y[0], y[2], x[0], x[2]);
      return std::hypot(d, y[1]);
    }
    x[0] = 0.0;
    x[2] = e[2];
    return std::fabs(y[2] - e[2]);
  }
  const double denom0 = e[0] * e[0] - e[2] * e[2], denom1 = e[1] * e[1] - e[2] * e[2];
  const double numer0 = e[0] * y[0], numer1 = e[1] * y[1];
  if (numer0 < denom0 && numer1 < denom1) {
    const double xde0 = numer0 / denom0, xde1 = numer1 / denom1;
    const double discr = 1.0 - xde0 * xde0 - xde1 * xde1;
    if (discr > 0.0) {
      x[0] = e[0] * xde0;
      x[1] = e[1] * xde1;
      x[2] = e[2] * std::sqrt(discr);
      return std::sqrt((x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) + x[2] * x[2]);
    }
  }
  x[2] = 0.0;
  return ellipse(e[0], e[1], y[0], y[1], x[0], x[1]);
}

}  // namespace

double ellipsoidClosestPoint(const Eigen::Vector3d& radii, const Eigen::Vector3d& y, Eigen::Vector3d& closest) {
  // Sort the axes by decreasing radius and reflect into the first octant.
  std::array<int, 3> order{0, 1, 2};
  std::sort(order.begin(), order.end(), [&](int i, int j) { return radii[i] > radii[j]; });
  double e[3], ya[3], x[3];
  for (int k = 0; k < 3; ++k) {
    e[k] = radii[order[k]];
    ya[k] = std::fabs(y[order[k]]);
  }
  const double d = ellipsoid(e, ya, x);
  for (int k = 0; k < 3; ++k) closest[order[k]] = std::copysign(x[k], y[order[k]]);
  const Eigen::Vector3d u = y.cwiseQuotient(radii);
  return u.squaredNorm() < 1.0 ? -d : d;
}

}  // namespace articula::distance
