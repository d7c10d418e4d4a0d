#include "articula/contact/reference.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "articula/core/error.hpp"

namespace articula::contact {

namespace {
using Vec3L = Eigen::Matrix<long double, 3, 1>;
using Mat3L = Eigen::Matrix<long double, 3, 3>;

Mat3L shapeMatrix(const ConvexShape& s) {
  const Mat3L R = s.rotation.cast<long double>();
  const Vec3L r2 = s.radii.cast<long double>().cwiseAbs2();
  return R * r2.asDiagonal() * R.transpose();
}
long double dual(const Mat3L& Ma, const Mat3L& Mb, const Vec3L& c, const Vec3L& v) {
  return v.dot(c) - std::sqrt(v.dot(Ma * v)) - std::sqrt(v.dot(Mb * v));
}
}  // namespace

double referenceEllipsoidDistance(const ConvexShape& a, const ConvexShape& b, int samples, int starts) {
  if (!a.quadric || !b.quadric) throw UsageError("referenceEllipsoidDistance: both shapes must be ellipsoids");
  const Mat3L Ma = shapeMatrix(a), Mb = shapeMatrix(b);
  const Vec3L c = (b.center - a.center).cast<long double>();
  std::vector<std::pair<long double, Vec3L>> best;
  best.reserve(static_cast<size_t>(samples));
  for (int i = 0; i < samples; ++i) {
    const long double z = 1.0L - (2.0L * i + 1.0L) / samples, r = std::sqrt(1.0L - z * z);
    const long double t = 2.39996322972865332L * i;  // golden angle
    const Vec3L v(r * std::cos(t), r * std::sin(t), z);
    best.push_back({dual(Ma, Mb, c, v), v});
  }
  const auto count = std::min<size_t>(static_cast<size_t>(starts), best.size());
  std::partial_sort(best.begin(), best.begin() + static_cast<long>(count), best.end(),
                    [](const auto& l, const auto& r) { return l.first > r.first; });
  long double answer = best.front().first;
  for (size_t k = 0; k < count; ++k) {
    Vec3L v = best[k].second;
    long double s = best[k].first, step = 0.05L;
    for (int it = 0; it < 20000 && step > 1e-17L; ++it) {
      const Vec3L g = c - Ma * v / std::sqrt(v.dot(Ma * v)) - Mb * v / std::sqrt(v.dot(Mb * v));
      const Vec3L gt = g - g.dot(v) * v;
      if (gt.norm() < 1e-19L) break;
      const Vec3L trial = (v + step * gt / gt.norm()).normalized();
      const long double ts = dual(Ma, Mb, c, trial);
      if (ts > s) {
        s = ts, v = trial, step *= 1.5L;
      } else {
        step *= 0.5L;
      }
    }
    answer = std::max(answer, s);
  }
  return static_cast<double>(answer);
}

}  // namespace articula::contact
