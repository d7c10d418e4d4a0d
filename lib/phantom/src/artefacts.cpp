#include "artefacts.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Eigenvalues>

namespace articula::phantom::detail {

void blur(imaging::Volume& v, const Eigen::Vector3d& sigma_mm) {
  const imaging::ImageGeometry& g = v.geometry;
  for (int axis = 0; axis < 3; ++axis) {
    const double s = sigma_mm[axis] / g.spacing[axis];
    if (s < 0.1) continue;
    const int r = static_cast<int>(std::ceil(3 * s));
    std::vector<double> w(static_cast<size_t>(2 * r + 1));
    double sum = 0;
    for (int t = -r; t <= r; ++t) sum += w[static_cast<size_t>(t + r)] = std::exp(-0.5 * t * t / (s * s));
    for (double& x : w) x /= sum;
    const long long stride = axis == 0 ? 1 : axis == 1 ? g.size[0] : static_cast<long long>(g.size[0]) * g.size[1];
    const int n = g.size[axis];
    std::vector<float> line(static_cast<size_t>(n));
    for (long long start = 0; start < g.voxelCount(); ++start) {
      // Visit each line once, from its first voxel.
      if ((start / stride) % n != 0) continue;
      for (int t = 0; t < n; ++t) line[static_cast<size_t>(t)] = v.voxels[static_cast<size_t>(start + t * stride)];
      for (int t = 0; t < n; ++t) {
        double acc = 0;
        for (int q = -r; q <= r; ++q) acc += w[static_cast<size_t>(q + r)] * line[static_cast<size_t>(std::clamp(t + q, 0, n - 1))];
        v.voxels[static_cast<size_t>(start + t * stride)] = static_cast<float>(acc);
      }
    }
  }
}

void sharpenInPlane(imaging::Volume& v, double sigma_mm, double gain) {
  imaging::Volume smooth = v;
  blur(smooth, Eigen::Vector3d(sigma_mm, sigma_mm, 0.0));
  for (size_t n = 0; n < v.voxels.size(); ++n) v.voxels[n] += static_cast<float>(gain * (v.voxels[n] - smooth.voxels[n]));
}

namespace {

/// A connected part of a slice's metal: its centroid, long axis, and the
/// standard deviations along and across that axis (mm).
struct MetalPart {
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero(), axis = Eigen::Vector2d::UnitX();
  double along_sd = 0, across_sd = 0;
};

/// The 4-connected parts of a slice's metal mask (nx x ny, i fastest), with
/// pixel (i, j) at `at(i, j)` in the plane.
std::vector<MetalPart> metalParts(std::vector<std::uint8_t> mask, int nx, int ny,
                                  const std::function<Eigen::Vector2d(int, int)>& at) {
  std::vector<MetalPart> parts;
  std::vector<int> stack;
  for (int start = 0; start < nx * ny; ++start) {
    if (!mask[static_cast<size_t>(start)]) continue;
    std::vector<Eigen::Vector2d> pixels;
    stack.assign(1, start);
    mask[static_cast<size_t>(start)] = 0;
    while (!stack.empty()) {
      const int p = stack.back();
      stack.pop_back();
      const int i = p % nx, j = p / nx;
      pixels.push_back(at(i, j));
      for (const auto& [di, dj] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
        const int a = i + di, b = j + dj;
        if (a < 0 || b < 0 || a >= nx || b >= ny || !mask[static_cast<size_t>(a + nx * b)]) continue;
        mask[static_cast<size_t>(a + nx * b)] = 0;
        stack.push_back(a + nx * b);
      }
    }
    MetalPart part;
    for (const Eigen::Vector2d& q : pixels) part.centroid += q / static_cast<double>(pixels.size());
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    for (const Eigen::Vector2d& q : pixels) cov += (q - part.centroid) * (q - part.centroid).transpose() / static_cast<double>(pixels.size());
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
    part.axis = eig.eigenvectors().col(1);
    part.along_sd = std::sqrt(std::max(eig.eigenvalues()[1], 0.0));
    part.across_sd = std::sqrt(std::max(eig.eigenvalues()[0], 0.0));
    parts.push_back(part);
  }
  return parts;
}

}  // namespace

void addMetalStreaks(imaging::Volume& v, const std::function<bool(const Eigen::Vector3d&)>& is_metal,
                     unsigned long long seed) {
  const imaging::ImageGeometry& g = v.geometry;
  const int nx = g.size[0], ny = g.size[1];
  std::mt19937_64 rng(seed);
  const auto uniform = [&rng](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  const double pixel_area = g.spacing[0] * g.spacing[1];
  std::vector<std::uint8_t> mask(static_cast<size_t>(nx) * ny);
  std::vector<Eigen::Vector2d> plane(static_cast<size_t>(nx) * ny);
  for (int k = 0; k < g.size[2]; ++k) {
    std::vector<int> metal;
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const Eigen::Vector3d x = g.toPhysical(Eigen::Vector3d(i, j, k));
        plane[static_cast<size_t>(i + nx * j)] = x.head<2>();
        mask[static_cast<size_t>(i + nx * j)] = is_metal(x);
        if (is_metal(x)) metal.push_back(i + nx * j);
      }
    if (metal.empty()) continue;
    const auto at = [&](int i, int j) { return plane[static_cast<size_t>(i + nx * j)]; };
    const double strength = std::sqrt(std::min(1.0, static_cast<double>(metal.size()) * pixel_area / 30.0));
    // A band adds `amplitude` across a Gaussian of width sd about the line
    // through p along unit d, full within `half` of p and fading beyond.
    const auto band = [&](const Eigen::Vector2d& p, const Eigen::Vector2d& d, double amplitude, double sd, double half,
                          double fade) {
      const Eigen::Vector2d across(-d.y(), d.x());
      for (int n = 0; n < nx * ny; ++n) {
        const Eigen::Vector2d r = plane[static_cast<size_t>(n)] - p;
        const double t = r.dot(across) / sd;
        if (std::abs(t) > 4) continue;
        const double beyond = std::max(0.0, std::abs(r.dot(d)) - half);
        v.voxels[static_cast<size_t>(n + static_cast<long long>(nx) * ny * k)] +=
            static_cast<float>(amplitude * std::exp(-0.5 * t * t - beyond / fade));
      }
    };
    for (int line = 0; line < 12; ++line) {
      const double angle = uniform(0.0, M_PI);
      const int through = metal[static_cast<size_t>(uniform(0.0, 1.0) * metal.size()) % metal.size()];
      const double amplitude = (uniform(0.0, 1.0) < 0.5 ? -1.0 : 1.0) * uniform(150.0, 500.0) * strength;
      band(plane[static_cast<size_t>(through)], Eigen::Vector2d(std::cos(angle), std::sin(angle)), amplitude, 0.7, 0.0, 60.0);
    }
    const std::vector<MetalPart> parts = metalParts(mask, nx, ny, at);
    for (size_t a = 0; a < parts.size(); ++a) {
      const MetalPart& p = parts[a];
      if (p.along_sd > 1.5 * p.across_sd)
        band(p.centroid, p.axis, -uniform(200.0, 500.0) * strength, std::max(p.across_sd, 0.7), 2.0 * p.along_sd, 30.0);
      for (size_t b = a + 1; b < parts.size(); ++b) {
        const Eigen::Vector2d join = parts[b].centroid - p.centroid;
        if (join.norm() < 1e-9) continue;
        band(0.5 * (p.centroid + parts[b].centroid), join.normalized(), -uniform(200.0, 500.0),
             std::max(0.5 * (p.across_sd + parts[b].across_sd), 0.7), 0.5 * join.norm(), 30.0);
      }
    }
  }
}

void clipToScannerRange(imaging::Volume& v) {
  for (float& x : v.voxels) x = std::clamp(x, -1024.0f, 3071.0f);
}

}  // namespace articula::phantom::detail
