#pragma once
// Connected parts of a chosen set of mesh vertices, joined through triangle
// edges (a union-find over the edges: Eigen has none, and a graph library
// for one loop would be a heavier dependency than the loop).
#include <vector>

#include <Eigen/Core>

namespace articula::geometry {

/// For each vertex, the index (0, 1, ...) of its connected part among the
/// `chosen` vertices (chosen[v] != 0), or -1 where not chosen. Parts are
/// numbered in order of their lowest vertex.
std::vector<int> connectedParts(const std::vector<char>& chosen, const Eigen::MatrixX3i& triangles);

}  // namespace articula::geometry
