#include "articula/geometry/mesh_components.hpp"

#include <numeric>

namespace articula::geometry {
namespace {

int findRoot(std::vector<int>& parent, int i) {
  while (parent[static_cast<size_t>(i)] != i)
    i = parent[static_cast<size_t>(i)] = parent[static_cast<size_t>(parent[static_cast<size_t>(i)])];
  return i;
}

}  // namespace

std::vector<int> connectedParts(const std::vector<char>& chosen, const Eigen::MatrixX3i& triangles) {
  std::vector<int> parent(chosen.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (Eigen::Index t = 0; t < triangles.rows(); ++t)
    for (int e = 0; e < 3; ++e) {
      const int a = triangles(t, e), b = triangles(t, (e + 1) % 3);
      if (chosen[static_cast<size_t>(a)] && chosen[static_cast<size_t>(b)])
        parent[static_cast<size_t>(findRoot(parent, a))] = findRoot(parent, b);
    }
  std::vector<int> part(chosen.size(), -1), number_of_root(chosen.size(), -1);
  int parts = 0;
  for (size_t v = 0; v < chosen.size(); ++v) {
    if (!chosen[v]) continue;
    int& number = number_of_root[static_cast<size_t>(findRoot(parent, static_cast<int>(v)))];
    if (number < 0) number = parts++;
    part[v] = number;
  }
  return part;
}

}  // namespace articula::geometry
