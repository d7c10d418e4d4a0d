#include "articula/imaging/edges.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace articula::imaging {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// A fall counts as the bone's edge only if it is this steep relative to the
// steepest fall on the same ray: trabecular texture inside a head falls too,
// but far less than a cortex meeting soft tissue.
constexpr double kRelativeStrength = 0.25;
constexpr double kContrastReachMm = 1.5;  // the fall is measured within this distance either side

/// HU at a continuous index by trilinear interpolation; NaN outside the grid.
double interpolateAtIndex(const Volume& volume, const Eigen::Vector3d& idx) {
  const ImageGeometry& g = volume.geometry;
  Eigen::Vector3i base;
  Eigen::Vector3d frac;
  for (int a = 0; a < 3; ++a) {
    if (!(idx[a] >= 0 && idx[a] <= g.size[a] - 1)) return kNaN;
    base[a] = std::min(static_cast<int>(std::floor(idx[a])), std::max(g.size[a] - 2, 0));
    frac[a] = idx[a] - base[a];
  }
  double value = 0;
  for (int corner = 0; corner < 8; ++corner) {
    double weight = 1;
    Eigen::Vector3i v = base;
    for (int a = 0; a < 3; ++a) {
      const bool up = corner >> a & 1;
      weight *= up ? frac[a] : 1 - frac[a];
      if (up) v[a] = std::min(v[a] + 1, g.size[a] - 1);
    }
    if (weight != 0) value += weight * volume.at(v[0], v[1], v[2]);
  }
  return value;
}

/// The profile I(t0 + n step), smoothed by a Gaussian of sigma_mm, and its derivative.
struct Profile {
  double t0 = 0, step = 0.1;
  std::vector<double> value, slope;
  bool complete = true;  // every sample inside the grid

  double t(size_t n) const { return t0 + static_cast<double>(n) * step; }
};

Profile sampleProfile(const Volume& volume, const Eigen::Vector3d& x, const Eigen::Vector3d& u, double from,
                      double to, const EdgeSearch& search) {
  Profile p;
  p.t0 = from;
  p.step = search.step_mm;
  const auto count = static_cast<size_t>(std::floor((to - from) / p.step)) + 1;
  std::vector<double> raw(count);
  // The line in index space once, not the direction's inverse per sample.
  const ImageGeometry& g = volume.geometry;
  const Eigen::Vector3d start = g.toIndex(x + p.t0 * u);
  const Eigen::Vector3d stride = g.toIndex(x + (p.t0 + p.step) * u) - start;
  for (size_t n = 0; n < count; ++n) {
    raw[n] = interpolateAtIndex(volume, start + static_cast<double>(n) * stride);
    if (std::isnan(raw[n])) {
      p.complete = false;
      raw.resize(n);
      break;
    }
  }
  const double sigma_mm =
      search.smoothing_mm > 0 ? search.smoothing_mm : std::max(0.15, 0.25 * volume.geometry.spacing.minCoeff());
  const double s = sigma_mm / p.step;
  const int r = static_cast<int>(std::ceil(3 * s));
  std::vector<double> w(static_cast<size_t>(2 * r + 1)), dw(w.size());
  double sum = 0;
  for (int q = -r; q <= r; ++q) sum += w[static_cast<size_t>(q + r)] = std::exp(-0.5 * q * q / (s * s));
  for (int q = -r; q <= r; ++q) {
    w[static_cast<size_t>(q + r)] /= sum;
    dw[static_cast<size_t>(q + r)] = -q / (s * s) * w[static_cast<size_t>(q + r)] / p.step;  // d/dt of the kernel
  }
  const auto m = static_cast<long>(raw.size());
  p.value.assign(raw.size(), 0.0);
  p.slope.assign(raw.size(), 0.0);
  for (long n = 0; n < m; ++n)
    for (int q = -r; q <= r; ++q) {
      const double v = raw[static_cast<size_t>(std::clamp(n - q, 0L, m - 1))];
      p.value[static_cast<size_t>(n)] += w[static_cast<size_t>(q + r)] * v;
      p.slope[static_cast<size_t>(n)] += dw[static_cast<size_t>(q + r)] * v;
    }
  return p;
}

/// The edge at sample n (a local minimum of the slope): sub-sample offset by a
/// parabola through the slopes at n-1, n, n+1, with the contrast across it.
Edge edgeAt(const Profile& p, size_t n) {
  Edge e;
  const double a = p.slope[n - 1], b = p.slope[n], c = p.slope[n + 1];
  const double curvature = a - 2 * b + c;
  const double shift = curvature > 0 ? std::clamp(0.5 * (a - c) / curvature, -0.5, 0.5) : 0.0;
  e.offset_mm = p.t(n) + shift * p.step;
  e.slope_hu_per_mm = -b;
  const auto reach = static_cast<size_t>(std::lround(kContrastReachMm / p.step));
  const size_t lo = n > reach ? n - reach : 0, hi = std::min(p.value.size() - 1, n + reach);
  e.inside_hu = *std::max_element(p.value.begin() + static_cast<long>(lo), p.value.begin() + static_cast<long>(n) + 1);
  e.outside_hu = *std::min_element(p.value.begin() + static_cast<long>(n), p.value.begin() + static_cast<long>(hi) + 1);
  return e;
}

bool strongEnough(const Edge& e, const EdgeSearch& search) {
  return e.inside_hu - e.outside_hu >= search.min_contrast_hu && e.inside_hu >= search.min_inside_hu;
}

bool isFallingMinimum(const Profile& p, size_t n) {
  return p.slope[n] < 0 && p.slope[n] <= p.slope[n - 1] && p.slope[n] < p.slope[n + 1];
}

}  // namespace

double interpolate(const Volume& volume, const Eigen::Vector3d& x) {
  return interpolateAtIndex(volume, volume.geometry.toIndex(x));
}

Edge locateEdge(const Volume& volume, const Eigen::Vector3d& x, const Eigen::Vector3d& outward,
                const EdgeSearch& search) {
  // Sampled beyond the window so that the smoothing and the contrast see both sides.
  const double margin = kContrastReachMm;
  const Profile p = sampleProfile(volume, x, outward, -search.inward_mm - margin, search.outward_mm + margin, search);
  if (!p.complete || p.value.size() < 3) return {};
  size_t best = 0;
  for (size_t n = 1; n + 1 < p.value.size(); ++n) {
    const double t = p.t(n);
    if (t < -search.inward_mm || t > search.outward_mm || !isFallingMinimum(p, n)) continue;
    if (best == 0 || p.slope[n] < p.slope[best]) best = n;
  }
  if (best == 0) return {};
  Edge e = edgeAt(p, best);
  e.found = strongEnough(e, search);
  return e;
}

namespace {

/// The steepest fall of the profile up to to_mm that is not a fall from
/// metal: how steep a bone edge on this ray must be.
double steepestBoneFall(const Profile& p, double to_mm) {
  // A ray through a screw meets the metal's falls first, and they are the
  // steepest: neither is a bone edge nor sets how steep one must be.
  double steepest = 0;
  for (size_t n = 1; n + 1 < p.value.size() && p.t(n) <= to_mm; ++n)
    if (p.slope[n] < steepest && edgeAt(p, n).inside_hu <= kMetalHu) steepest = p.slope[n];
  return steepest;
}

/// The first fall up to to_mm as steep as a bone edge on this ray, from
/// bone, not from metal, that `accept` takes.
template <typename Accept>
Edge firstFall(const Profile& p, double to_mm, const EdgeSearch& search, Accept accept) {
  const double steepest = steepestBoneFall(p, to_mm);
  for (size_t n = 1; n + 1 < p.value.size() && p.t(n) <= to_mm; ++n) {
    if (!isFallingMinimum(p, n) || p.slope[n] > kRelativeStrength * steepest) continue;
    Edge e = edgeAt(p, n);
    if (e.inside_hu < search.min_inside_hu || e.inside_hu > kMetalHu || !accept(e, n)) continue;
    e.found = true;
    return e;
  }
  return {};
}

}  // namespace

Edge firstEdgeAlongRay(const Volume& volume, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                       double from_mm, double to_mm, const EdgeSearch& search) {
  const Profile p = sampleProfile(volume, origin, direction, from_mm, to_mm + kContrastReachMm, search);
  if (p.value.size() < 3) return {};
  return firstFall(p, to_mm, search, [&](const Edge& e, size_t) { return strongEnough(e, search); });
}

Edge firstValleyAlongRay(const Volume& volume, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                         double from_mm, double to_mm, const EdgeSearch& search, const ValleySearch& valley) {
  const Profile p =
      sampleProfile(volume, origin, direction, from_mm, to_mm + valley.rise_reach_mm + kContrastReachMm, search);
  if (p.value.size() < 3) return {};
  const auto reach = static_cast<size_t>(std::lround(valley.rise_reach_mm / p.step));
  return firstFall(p, to_mm, search, [&](Edge& e, size_t n) {
    // The valley's floor: where the profile stops falling beyond the edge.
    size_t floor = n;
    while (floor + 1 < p.value.size() && p.value[floor + 1] <= p.value[floor]) ++floor;
    const size_t end = std::min(p.value.size() - 1, floor + reach);
    if (floor == n || end == floor) return false;
    const double rise =
        *std::max_element(p.value.begin() + static_cast<long>(floor), p.value.begin() + static_cast<long>(end) + 1);
    e.outside_hu = p.value[floor];
    return e.inside_hu - e.outside_hu >= std::max(valley.min_fall_hu, valley.min_fall_share * e.inside_hu) &&
           rise - e.outside_hu >= valley.min_rise_hu;
  });
}

bool isGapValleyBefore(const Edge& valley, const Edge& edge) {
  return valley.found && edge.found && edge.offset_mm - valley.offset_mm > kGapValleyShortOfEdgeMm &&
         valley.inside_hu >= kGapValleyPeakShare * edge.inside_hu;
}

Edge firstEdgeBeforeAGap(const Volume& volume, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                         double from_mm, double to_mm, const EdgeSearch& search) {
  const Edge edge = firstEdgeAlongRay(volume, origin, direction, from_mm, to_mm, search);
  if (!edge.found || volume.geometry.spacing.maxCoeff() > kGapValleyMaxVoxelMm + 1e-6) return edge;
  const Edge valley = firstValleyAlongRay(volume, origin, direction, from_mm, edge.offset_mm, search);
  return isGapValleyBefore(valley, edge) ? valley : edge;
}

}  // namespace articula::imaging
