#include "uv_sphere.hpp"

#include <cmath>
#include <array>
#include <vector>

#include "articula/core/error.hpp"

namespace articula::geometry {

namespace {
// Collects optional vertices and triangles, then compacts away missing ones.
class MeshBuilder {
 public:
  int add(const std::optional<Eigen::Vector3d>& p) {
    points_.push_back(p);
    return static_cast<int>(points_.size()) - 1;
  }
  void triangle(int a, int b, int c) { triangles_.push_back({a, b, c}); }
  SurfaceMesh build() const {
    std::vector<int> index(points_.size(), -1);
    int n = 0;
    for (size_t i = 0; i < points_.size(); ++i)
      if (points_[i]) index[i] = n++;
    SurfaceMesh mesh;
    mesh.vertices.resize(n, 3);
    for (size_t i = 0; i < points_.size(); ++i)
      if (points_[i]) mesh.vertices.row(index[i]) = points_[i]->transpose();
    std::vector<std::array<int, 3>> kept;
    for (const auto& t : triangles_)
      if (index[t[0]] >= 0 && index[t[1]] >= 0 && index[t[2]] >= 0) kept.push_back({index[t[0]], index[t[1]], index[t[2]]});
    mesh.triangles.resize(static_cast<Eigen::Index>(kept.size()), 3);
    for (size_t i = 0; i < kept.size(); ++i)
      mesh.triangles.row(static_cast<Eigen::Index>(i)) << kept[i][0], kept[i][1], kept[i][2];
    return mesh;
  }

 private:
  std::vector<std::optional<Eigen::Vector3d>> points_;
  std::vector<std::array<int, 3>> triangles_;
};

void requireSteps(int a, int b, int min_a, int min_b) {
  if (a < min_a || b < min_b)
    throw UsageError("sampling resolution: expected at least " + std::to_string(min_a) + " x " +
                     std::to_string(min_b) + " steps, found " + std::to_string(a) + " x " + std::to_string(b));
}
}  // namespace

SurfaceMesh uvSphereMesh(int azimuth_steps, int polar_steps, const SphericalParametrisation& point) {
  requireSteps(azimuth_steps, polar_steps, 3, 2);
  MeshBuilder mesh;
  const int south = mesh.add(point(0.0, -M_PI / 2));
  std::vector<std::vector<int>> rings(static_cast<size_t>(polar_steps - 1));
  for (int k = 1; k < polar_steps; ++k) {
    const double latitude = -M_PI / 2 + M_PI * k / polar_steps;
    for (int j = 0; j < azimuth_steps; ++j)
      rings[k - 1].push_back(mesh.add(point(-M_PI + 2.0 * M_PI * j / azimuth_steps, latitude)));
  }
  const int north = mesh.add(point(0.0, M_PI / 2));
  for (int j = 0; j < azimuth_steps; ++j) {
    const int next = (j + 1) % azimuth_steps;
    mesh.triangle(south, rings.front()[next], rings.front()[j]);
    for (size_t k = 0; k + 1 < rings.size(); ++k) {
      const auto& lo = rings[k];
      const auto& up = rings[k + 1];
      mesh.triangle(lo[j], lo[next], up[next]);
      mesh.triangle(lo[j], up[next], up[j]);
    }
    mesh.triangle(rings.back()[j], rings.back()[next], north);
  }
  return mesh.build();
}

SurfaceMesh gridMesh(int s_steps, int t_steps, const PlanarParametrisation& point) {
  requireSteps(s_steps, t_steps, 1, 1);
  MeshBuilder mesh;
  const int row = t_steps + 1;
  for (int i = 0; i <= s_steps; ++i)
    for (int j = 0; j <= t_steps; ++j) mesh.add(point(-1.0 + 2.0 * i / s_steps, -1.0 + 2.0 * j / t_steps));
  for (int i = 0; i < s_steps; ++i)
    for (int j = 0; j < t_steps; ++j) {
      const int a = i * row + j, b = (i + 1) * row + j;
      mesh.triangle(a, b, b + 1);
      mesh.triangle(a, b + 1, a + 1);
    }
  return mesh.build();
}

}  // namespace articula::geometry
