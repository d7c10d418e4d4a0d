// Finding a joint head in a CT (see head_search.hpp).
#include "head_search.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>

#include <itkSmoothingRecursiveGaussianImageFilter.h>

#include "articula/core/error.hpp"
#include "articula/core/log.hpp"
#include "articula/geometry/fibonacci.hpp"
#include "articula/geometry/sphere_fit.hpp"
#include "articula/imaging/edges.hpp"
#include "itk_bridge.hpp"

namespace articula::imaging::detail {

std::string vec(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s.precision(4);
  s << "(" << v[0] << ", " << v[1] << ", " << v[2] << ")";
  return s.str();
}

bool insideVolume(const ImageGeometry& g, const Eigen::Vector3d& x) {
  const Eigen::Vector3d idx = g.toIndex(x);
  return (idx.array() >= -0.5).all() && (idx.array() <= g.size.cast<double>().array() - 0.5).all();
}

namespace {

/// Mean of f x f x f blocks (f per axis): the CT on the search's coarse grid.
Volume blockMean(const Volume& volume, const Eigen::Vector3i& factor) {
  const ImageGeometry& g = volume.geometry;
  Volume coarse;
  coarse.geometry = g;
  for (int a = 0; a < 3; ++a) coarse.geometry.size[a] = (g.size[a] + factor[a] - 1) / factor[a];
  coarse.geometry.spacing = g.spacing.cwiseProduct(factor.cast<double>());
  // Block (0,0,0) covers voxels 0..f-1: its centre is at index (f-1)/2.
  coarse.geometry.origin = g.toPhysical((factor.cast<double>() - Eigen::Vector3d::Ones()) / 2.0);
  std::vector<double> sum(static_cast<size_t>(coarse.geometry.voxelCount()), 0.0);
  std::vector<int> count(sum.size(), 0);
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        const auto n = static_cast<size_t>(coarse.geometry.linear(i / factor[0], j / factor[1], k / factor[2]));
        sum[n] += volume.at(i, j, k);
        ++count[n];
      }
  coarse.voxels.resize(sum.size());
  for (size_t n = 0; n < sum.size(); ++n) coarse.voxels[n] = static_cast<float>(sum[n] / count[n]);
  return coarse;
}

}  // namespace

/// Casts kRayCount rays (Fibonacci lattice) from `start`, takes the first
/// bone edge on each (imaging/edges.hpp: full resolution, sub-voxel), and
/// fits a sphere to the edges within a band of the median distance (or of
/// the first or third quartile, where many more edges agree), twice
/// tightening the band; then once more from the fitted centre, so that the
/// rays cross the head's surface nearly normally.
/// Hand-written: ITK has no ray-cast edge detector; a sphere through edges
/// that agree is the model a joint head's cap calls for.
HeadCandidate measureHeadByRays(const Volume& volume, const Eigen::Vector3d& start, const SegmentOptions& options) {
  EdgeSearch search;
  search.step_mm = 0.15;
  search.min_inside_hu = options.hu_min;
  const double r_lo = options.min_head_radius_mm, r_hi = options.max_head_radius_mm;
  HeadCandidate c;
  c.center = start;
  // A candidate whose centre is still moving was measured from elsewhere.
  const auto unmeasured = [&c]() {
    c.edge_mm.clear();
    c.coverage = 0;
    return c;
  };
  // Until the rays leave from within half a millimetre of the centre they
  // find: a start far off the centre (a Hough peak inside the head but near
  // its edge) finds a small sphere first, and edge distances measured along
  // rays from elsewhere would not be the head's radius in their direction.
  for (int round = 0; round < kMaxRayRounds; ++round) {
    const Eigen::Vector3d ray_origin = c.center;
    std::vector<Eigen::Vector3d> edges(kRayCount, Eigen::Vector3d::Constant(NAN)), valleys = edges;
    std::vector<double> distances;
    for (int n = 0; n < kRayCount; ++n) {
      const Eigen::Vector3d u = geometry::fibonacciDirection(n, kRayCount);
      const Edge e = firstEdgeAlongRay(volume, c.center, u, 0.4 * r_lo, 1.25 * r_hi, search);
      if (!e.found) continue;
      edges[static_cast<size_t>(n)] = c.center + e.offset_mm * u;
      distances.push_back(e.offset_mm);
      const Edge v = firstValleyAlongRay(volume, c.center, u, 0.4 * r_lo, e.offset_mm, search);
      if (isGapValleyBefore(v, e) && e.offset_mm - v.offset_mm <= kValleyGapReachMm)
        valleys[static_cast<size_t>(n)] = c.center + v.offset_mm * u;
    }
    if (distances.size() < 10) return unmeasured();
    std::sort(distances.begin(), distances.end());
    const double voxel = volume.geometry.spacing.maxCoeff();
    // The sphere of the edges within a band of `radius` about the ray
    // origin, the band twice tightened about the sphere fitted to them.
    struct Consensus {
      geometry::Sphere sphere;
      std::vector<char> inlier;
      int count = 0;
    };
    const auto consensus = [&](double radius,
                               const std::vector<Eigen::Vector3d>& ray_edges) -> std::optional<Consensus> {
      Consensus fit{{c.center, radius}, std::vector<char>(ray_edges.size(), 0), 0};
      for (double band_share : {0.12, 0.06, 0.04}) {
        const double band = std::max({band_share * fit.sphere.radius, 0.75 * voxel, 1.0});
        std::vector<Eigen::Vector3d> kept;
        for (size_t n = 0; n < ray_edges.size(); ++n) {
          fit.inlier[n] = !std::isnan(ray_edges[n][0]) &&
                          std::abs((ray_edges[n] - fit.sphere.center).norm() - fit.sphere.radius) <= band;
          if (fit.inlier[n]) kept.push_back(ray_edges[n]);
        }
        if (kept.size() < 10) return std::nullopt;
        Eigen::MatrixX3d points(static_cast<Eigen::Index>(kept.size()), 3);
        for (size_t i = 0; i < kept.size(); ++i) points.row(static_cast<Eigen::Index>(i)) = kept[i].transpose();
        try {
          fit.sphere = geometry::fitSphere(points);
        } catch (const ProcessingError&) {
          return std::nullopt;  // degenerate support (a flat or tiny patch): no head here
        }
        fit.count = static_cast<int>(kept.size());
      }
      return fit;
    };
    const auto consensusRms = [](const Consensus& fit, const std::vector<Eigen::Vector3d>& ray_edges) {
      double sse = 0;
      for (size_t n = 0; n < ray_edges.size(); ++n)
        if (fit.inlier[n]) {
          const double residual = (ray_edges[n] - fit.sphere.center).norm() - fit.sphere.radius;
          sse += residual * residual;
        }
      return std::sqrt(sse / std::max(fit.count, 1));
    };
    const auto quantile = [](const std::vector<double>& sorted, double q) {
      return sorted[std::min(sorted.size() - 1, static_cast<size_t>(q * double(sorted.size())))];
    };
    std::optional<Consensus> best = consensus(quantile(distances, 0.5), edges);
    // Metal's streaks inside the head give edges short of its surface on
    // the rays along them, which can outnumber the surface's: the median
    // then lies among them, and a sphere of a head's size a quarter of the
    // rays further out is taken where many more rays agree on it.
    for (double q : {0.25, 0.75})
      if (std::optional<Consensus> other = consensus(quantile(distances, q), edges);
          other && other->sphere.radius >= r_lo && other->sphere.radius <= r_hi &&
          (!best || other->count > kConsensusGain * best->count))
        best = std::move(other);
    if (!best) return unmeasured();
    // Across a joint gap of about a millimetre between thin, faint cortices
    // (osteoporotic bone) the gap's blurred valley need not fall as far as
    // a bone edge must, and the first edge on many rays facing the socket
    // is then the socket cortex's far side: the sphere runs between the two.
    // Where the rays' valleys, put in place of their edges, make a sphere
    // that a fifth more rays agree on as closely, or nearly as many far more
    // closely, it is the head's. (Inside a head, the valleys of its texture
    // or of the noise make no sphere.)
    const auto valleys_taken =
        std::count_if(valleys.begin(), valleys.end(), [](const Eigen::Vector3d& v) { return !std::isnan(v[0]); });
    if (valleys_taken >= kMinValleyRays) {
      std::vector<Eigen::Vector3d> nearer = edges;
      std::vector<double> nearer_distances;
      for (size_t n = 0; n < edges.size(); ++n) {
        if (!std::isnan(valleys[n][0])) nearer[n] = valleys[n];
        if (!std::isnan(nearer[n][0])) nearer_distances.push_back((nearer[n] - c.center).norm());
      }
      std::sort(nearer_distances.begin(), nearer_distances.end());
      std::optional<Consensus> across_gap;
      for (double q : {0.5, 0.25, 0.75}) {
        if (std::optional<Consensus> other = consensus(quantile(nearer_distances, q), nearer);
            other && other->sphere.radius >= r_lo && other->sphere.radius <= r_hi &&
            (!across_gap || other->count > across_gap->count))
          across_gap = std::move(other);
      }
      const auto takes = [&](const Consensus& gap) {
        const double rms = consensusRms(gap, nearer), best_rms = consensusRms(*best, edges);
        return (gap.count >= kValleyCountGain * best->count && rms <= kValleyRmsTie * best_rms) ||
               (gap.count >= kValleyCountShare * best->count && rms <= kValleyRmsGain * best_rms);
      };
      if (across_gap && takes(*across_gap)) {
        best = std::move(across_gap);
        edges = std::move(nearer);
      }
    }
    const geometry::Sphere& sphere = best->sphere;
    const std::vector<char>& inlier = best->inlier;
    c.center = sphere.center;
    c.radius = sphere.radius;
    c.edge_mm.assign(edges.size(), NAN);
    c.short_of_sphere.assign(edges.size(), 0);
    for (size_t n = 0; n < edges.size(); ++n) {
      if (!inlier[n]) {
        c.short_of_sphere[n] = !std::isnan(edges[n][0]) && (edges[n] - sphere.center).norm() < sphere.radius;
        continue;
      }
      // The edge's distance from the final centre along its ray's direction
      // (the ray left from the previous centre, within half a millimetre).
      c.edge_mm[n] = (edges[n] - sphere.center).dot(geometry::fibonacciDirection(static_cast<int>(n), kRayCount));
    }
    c.coverage = static_cast<double>(best->count) / kRayCount;
    c.rms_mm = consensusRms(*best, edges);
    if (round > 0 && (c.center - ray_origin).norm() <= 0.5) return c;
  }
  return unmeasured();
}

namespace {

/// A bone-surface voxel of the search's coarse grid and its inward HU gradient.
struct Voter {
  Eigen::Vector3d x, n;
};

/// The Hough peak refined by a least-squares sphere through the surface
/// voxels facing it at about its radius (the votes only locate it to a
/// cell); coverage: the share of that sphere's surface that took part.
HeadCandidate sphereOfFacingVoxels(const Eigen::Vector3d& peak, const std::vector<Voter>& voters,
                                   const SegmentOptions& options, double cell_mm, double cell_area) {
  const double r_lo = options.min_head_radius_mm, r_hi = options.max_head_radius_mm;
  HeadCandidate c;
  c.center = peak;
  std::vector<double> distances;
  for (const Voter& voter : voters) {
    const Eigen::Vector3d d = peak - voter.x;
    const double t = d.dot(voter.n);
    if (t >= r_lo && t <= r_hi && (d - t * voter.n).norm() <= 1.5 * cell_mm) distances.push_back(t);
  }
  if (distances.empty()) return c;
  std::nth_element(distances.begin(), distances.begin() + static_cast<long>(distances.size() / 2), distances.end());
  c.radius = distances[distances.size() / 2];
  size_t used = 0;
  for (int iteration = 0; iteration < 5; ++iteration) {
    std::vector<Eigen::Vector3d> facing;  // surface voxels near the sphere, their normals towards its centre
    for (const Voter& voter : voters) {
      const Eigen::Vector3d d = c.center - voter.x;
      const double t = d.norm();
      if (std::abs(t - c.radius) <= 0.25 * c.radius && d.dot(voter.n) >= 0.9 * t) facing.push_back(voter.x);
    }
    used = facing.size();
    if (used < 10) break;
    Eigen::MatrixX3d points(static_cast<Eigen::Index>(used), 3);
    for (size_t i = 0; i < used; ++i) points.row(static_cast<Eigen::Index>(i)) = facing[i].transpose();
    try {
      const geometry::Sphere sphere = geometry::fitSphere(points);
      c.center = sphere.center;
      c.radius = sphere.radius;
    } catch (const ProcessingError&) {
      break;  // degenerate support (a flat or tiny patch): keep the Hough estimate
    }
  }
  c.coverage = static_cast<double>(used) * cell_area / (4 * M_PI * c.radius * c.radius);
  return c;
}

/// Nearest direction of the ray lattice, through a table over polar and
/// azimuth angles (a voxel's direction is looked up millions of times).
class LatticeLookup {
 public:
  LatticeLookup() : nearest_(kPolarBins * kAzimuthBins) {
    for (int a = 0; a < kPolarBins; ++a)
      for (int b = 0; b < kAzimuthBins; ++b) {
        const double polar = M_PI * (a + 0.5) / kPolarBins, azimuth = 2 * M_PI * (b + 0.5) / kAzimuthBins;
        const Eigen::Vector3d u(std::sin(polar) * std::cos(azimuth), std::sin(polar) * std::sin(azimuth), std::cos(polar));
        int best = 0;
        for (int n = 1; n < kRayCount; ++n)
          if (u.dot(geometry::fibonacciDirection(n, kRayCount)) > u.dot(geometry::fibonacciDirection(best, kRayCount))) best = n;
        nearest_[static_cast<size_t>(a * kAzimuthBins + b)] = best;
      }
  }
  int operator()(const Eigen::Vector3d& u) const {
    const double polar = std::acos(std::clamp(u[2], -1.0, 1.0));
    double azimuth = std::atan2(u[1], u[0]);
    if (azimuth < 0) azimuth += 2 * M_PI;
    const int a = std::min(kPolarBins - 1, static_cast<int>(polar / M_PI * kPolarBins));
    const int b = std::min(kAzimuthBins - 1, static_cast<int>(azimuth / (2 * M_PI) * kAzimuthBins));
    return nearest_[static_cast<size_t>(a * kAzimuthBins + b)];
  }

 private:
  static constexpr int kPolarBins = 64, kAzimuthBins = 128;
  std::vector<int> nearest_;
};

}  // namespace

Eigen::Vector3d neckSide(Side side) {
  return Eigen::Vector3d(side == Side::Right ? -1.0 : 1.0, 0.0, -1.0).normalized();
}

/// The head's edge distance per lattice direction, with the holes of its cap
/// (a missed edge, the fovea's pit, a flattened dome) filled from their
/// neighbours: a direction without an edge whose nearest neighbours mostly
/// have one lies inside the cap, and so does every part without edges but
/// the neck's whose rays mostly met bone short of the sphere. The neck's
/// directions stay empty. `slice_axis`: the grid's slice normal (unit, LPS).
std::vector<double> capEdges(const HeadCandidate& head, const Eigen::Vector3d& slice_axis, const Eigen::Vector3d& neck_side,
                             bool thick_slices) {
  std::vector<double> edge = head.edge_mm;
  constexpr int kNeighbours = 6;
  // The rays within kPoleDeg of the slice axis cross the dome's edge in one
  // or two slices and at 3 mm slices often miss it: a hole at the pole that
  // two rings leave open keeps a column of the socket's roof in the label.
  constexpr double kPoleDeg = 15;
  const double pole_cos = std::cos(kPoleDeg * M_PI / 180);
  std::vector<std::vector<int>> neighbours(kRayCount);
  std::vector<char> at_pole(kRayCount);
  for (int n = 0; n < kRayCount; ++n) {
    const Eigen::Vector3d u = geometry::fibonacciDirection(n, kRayCount);
    at_pole[static_cast<size_t>(n)] = std::abs(u.dot(slice_axis)) >= pole_cos;
    std::vector<std::pair<double, int>> by_angle;
    for (int m = 0; m < kRayCount; ++m)
      if (m != n) by_angle.emplace_back(-u.dot(geometry::fibonacciDirection(m, kRayCount)), m);
    std::partial_sort(by_angle.begin(), by_angle.begin() + kNeighbours, by_angle.end());
    for (int k = 0; k < kNeighbours; ++k) neighbours[static_cast<size_t>(n)].push_back(by_angle[static_cast<size_t>(k)].second);
  }
  // One ring of the holes filled: a direction without an edge, among those
  // `where` admits, takes the mean edge of its neighbours if at least
  // `least` of them have one. Whether an admitted direction stays empty.
  const auto fillRing = [&](const auto& where, int least) {
    std::vector<double> next = edge;
    bool open = false;
    for (int n = 0; n < kRayCount; ++n) {
      if (!std::isnan(edge[static_cast<size_t>(n)]) || !where(n)) continue;
      double sum = 0;
      int count = 0;
      for (int m : neighbours[static_cast<size_t>(n)])
        if (!std::isnan(edge[static_cast<size_t>(m)])) sum += edge[static_cast<size_t>(m)], ++count;
      if (count >= least) next[static_cast<size_t>(n)] = sum / count;
      else open = true;
    }
    edge = next;
    return open;
  };
  constexpr int kMost = 4;  // of the kNeighbours
  for (int ring = 0; ring < 2; ++ring) fillRing([](int) { return true; }, kMost);
  for (int ring = 0; ring < 3; ++ring) fillRing([&at_pole](int n) { return at_pole[static_cast<size_t>(n)] != 0; }, kMost);
  // Wider holes the cap's edges enclose (a dome flattened or eroded below
  // the sphere's band, its rays' edges all short of it) take their rim's
  // mean, ring by ring: left open, they kept the socket across a gap the
  // closing bridged. The part that lies most towards the neck's side is the
  // neck's, left open (not the largest: at 3 mm slices an osteoporotic
  // head's faint dome can leave more rays without edges than its neck).
  // Across thick slices, so is a hole whose rays mostly found no edge or one
  // beyond the sphere (a faint dome under the socket's roof, seen along the
  // slices): filled, its cut took the dome's edge for the socket's and moved
  // the surface there. Where the slices are not thick, such a hole is the
  // socket bridged across a narrow gap (a thin, faint cortex at 0.7 x 0.7 x
  // 0.9 mm, its gap 1.5 mm): left open, it kept the socket in the label.
  std::vector<int> part(kRayCount, -1), part_size;
  for (int n = 0; n < kRayCount; ++n) {
    if (!std::isnan(edge[static_cast<size_t>(n)]) || part[static_cast<size_t>(n)] >= 0) continue;
    const int id = static_cast<int>(part_size.size());
    part_size.push_back(0);
    std::vector<int> todo{n};
    part[static_cast<size_t>(n)] = id;
    while (!todo.empty()) {
      const int m = todo.back();
      todo.pop_back();
      ++part_size.back();
      for (int k : neighbours[static_cast<size_t>(m)])
        if (std::isnan(edge[static_cast<size_t>(k)]) && part[static_cast<size_t>(k)] < 0) part[static_cast<size_t>(k)] = id, todo.push_back(k);
    }
  }
  if (part_size.size() > 1) {
    std::vector<Eigen::Vector3d> direction(part_size.size(), Eigen::Vector3d::Zero());
    std::vector<int> short_rays(part_size.size(), 0);
    for (int n = 0; n < kRayCount; ++n)
      if (const int q = part[static_cast<size_t>(n)]; q >= 0) {
        direction[static_cast<size_t>(q)] += geometry::fibonacciDirection(n, kRayCount);
        short_rays[static_cast<size_t>(q)] += head.short_of_sphere.empty() ? 0 : head.short_of_sphere[static_cast<size_t>(n)];
      }
    int neck = 0;
    for (int q = 1; q < static_cast<int>(direction.size()); ++q)
      if (direction[static_cast<size_t>(q)].normalized().dot(neck_side) > direction[static_cast<size_t>(neck)].normalized().dot(neck_side))
        neck = q;
    std::vector<char> fill(part_size.size(), 0);
    for (size_t q = 0; q < part_size.size(); ++q)
      fill[q] = static_cast<int>(q) != neck && (!thick_slices || 2 * short_rays[q] >= part_size[q]);
    const auto enclosed = [&part, &fill](int n) {
      const int q = part[static_cast<size_t>(n)];
      return q >= 0 && fill[static_cast<size_t>(q)] != 0;
    };
    for (int ring = 0; ring < kRayCount; ++ring)
      if (!fillRing(enclosed, 1)) break;
  }
  return edge;
}

/// Removes from the bone mask what lies beyond the head's edge in the
/// directions of its cap: the joint gap and the socket, however narrow the
/// gap and whatever the closing bridged. The margin keeps the partial-volume
/// voxels of the head's own edge (the mesh stage places the surface on the
/// CT's edge within them).
void cutBeyondEdges(Image<std::uint8_t>& mask, const HeadCandidate& head, const std::vector<double>& edge) {
  static const LatticeLookup lookup;
  const ImageGeometry& g = mask.geometry;
  const double margin = std::max(0.5, 0.5 * g.spacing.maxCoeff());
  long long removed = 0;
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        std::uint8_t& m = mask.at(i, j, k);
        if (!m) continue;
        const Eigen::Vector3d d = g.toPhysical(Eigen::Vector3d(i, j, k)) - head.center;
        const double r = d.norm();
        if (r < 0.7 * head.radius || r > 1.6 * head.radius) continue;
        const double e = edge[static_cast<size_t>(lookup(d / r))];
        if (!std::isnan(e) && r > e + margin) m = 0, ++removed;
      }
  log::debug("cut beyond the head's edges: " + std::to_string(removed) + " voxels");
}

namespace {

// The field of view's extent left-right (LPS x) over its corners.
std::pair<double, double> fieldXRange(const ImageGeometry& g) {
  double lo = INFINITY, hi = -INFINITY;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d ijk((corner & 1) ? g.size[0] - 1 : 0, (corner & 2) ? g.size[1] - 1 : 0, (corner & 4) ? g.size[2] - 1 : 0);
    lo = std::min(lo, g.toPhysical(ijk)[0]);
    hi = std::max(hi, g.toPhysical(ijk)[0]);
  }
  return {lo, hi};
}

double fieldWidthMm(const ImageGeometry& g) {
  const auto [lo, hi] = fieldXRange(g);
  return hi - lo;
}

/// The margin about the field of view's middle (left-right) that no head
/// lies in: as given, or automatic (options.midline_margin_mm < 0).
double effectiveMidlineMargin(const ImageGeometry& g, const SegmentOptions& options) {
  if (options.midline_margin_mm >= 0) return options.midline_margin_mm;
  return fieldWidthMm(g) >= kBothSidesWidthMm ? kAutomaticMidlineMargin : 0.0;
}

// The body's middle, left-right (LPS x), when the field holds the body's
// outline whole on both sides: air beyond it at the field's left and right
// edges. The middle of its 1st and 99th percentiles of x (an arm or the
// table's edge does not move it). None when the body reaches either edge:
// then the field's own middle says nothing (a field centred on one hip).
std::optional<double> bodyMidline(const Volume& coarse) {
  const ImageGeometry& g = coarse.geometry;
  const auto [lo, hi] = fieldXRange(g);
  const double edge_band = 2.0 * g.spacing.maxCoeff();
  std::vector<double> body_x;
  long edge_cells[2] = {0, 0}, edge_body[2] = {0, 0};
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        const double x = g.toPhysical(Eigen::Vector3d(i, j, k))[0];
        const bool body = coarse.at(i, j, k) > kBodyHu;
        for (int e = 0; e < 2; ++e)
          if (e == 0 ? x < lo + edge_band : x > hi - edge_band) {
            ++edge_cells[e];
            edge_body[e] += body;
          }
        if (body) body_x.push_back(x);
      }
  if (body_x.size() < 100) return std::nullopt;
  for (int e = 0; e < 2; ++e)
    if (edge_body[e] > kBodyAtEdgeShare * static_cast<double>(edge_cells[e])) return std::nullopt;
  const auto at = [&](double q) {
    const auto n = static_cast<std::ptrdiff_t>(q * static_cast<double>(body_x.size() - 1));
    std::nth_element(body_x.begin(), body_x.begin() + n, body_x.end());
    return body_x[static_cast<size_t>(n)];
  };
  return 0.5 * (at(0.01) + at(0.99));
}

}  // namespace

std::optional<Side> sideBySocket(const Volume& volume, const HeadCandidate& head, const SegmentOptions& options) {
  // Rays from the head's centre: its cortex falls into the joint space,
  // which rises again into the socket within half a radius. A fall and a
  // rise of a contrast each, not a level: a narrow gap's blurred valley
  // stays above the bone window. The neck does not fall at the head's
  // edge, and the open cap does not rise again.
  int socket = 0;
  double sum_x = 0;
  for (int n = 0; n < kRayCount; ++n) {
    const Eigen::Vector3d u = geometry::fibonacciDirection(n, kRayCount);
    double peak = -INFINITY, valley = INFINITY;
    bool fell = false, rose = false;
    for (double t = head.radius - 2.0; t <= 1.5 * head.radius && !rose; t += 0.25) {
      const double hu = interpolate(volume, head.center + t * u);
      if (std::isnan(hu)) break;
      if (!fell) {
        peak = std::max(peak, hu);
        fell = peak - hu >= kSocketContrastHu && t <= head.radius + 2.0;
        valley = hu;
      } else {
        valley = std::min(valley, hu);
        rose = hu - valley >= kSocketContrastHu && hu >= options.hu_min;
      }
    }
    if (rose) {
      ++socket;
      sum_x += u[0];
    }
  }
  if (socket < kMinSocketRayShare * kRayCount) return std::nullopt;
  const double mean_x = sum_x / socket;
  if (std::abs(mean_x) < kMinSocketMedialShift) return std::nullopt;
  // LPS +x is the patient's left: a socket on the +x side is medial to a right joint.
  return mean_x > 0 ? Side::Right : Side::Left;
}

/// Automatic head search: a 3-D Hough transform for spheres on a grid of
/// about options.search_spacing_mm. Every voxel on the bone's surface votes
/// along its inward HU gradient at the distances a head radius can have: the
/// normals of a spherical head meet in its centre, those of a shaft or a
/// vertebral body only along a line, and a socket's point away from it. The
/// strongest centres are refined by a least-squares sphere on the surface
/// voxels facing them; the strongest on the requested side whose sphere is a
/// plausible head is the head.
/// Hand-written: ITK's Hough filters are 2-D only.
bool findHead(const Volume& volume, const SegmentOptions& options, HeadCandidate& head, SideCheck& side,
              std::optional<HeadCandidate>* outside_range) {
  const ImageGeometry& g = volume.geometry;
  Eigen::Vector3i factor;
  for (int a = 0; a < 3; ++a)
    factor[a] = std::max(1, static_cast<int>(std::lround(options.search_spacing_mm / g.spacing[a])));
  const Volume coarse = blockMean(volume, factor);
  const ImageGeometry& cg = coarse.geometry;
  // Smoothed once; the gradient is then taken only where it is needed (a
  // gradient filter would fill three components at every voxel).
  using FloatImage = itk::Image<float, 3>;
  auto smoothing = itk::SmoothingRecursiveGaussianImageFilter<FloatImage, FloatImage>::New();
  smoothing->SetInput(toItk(coarse));
  smoothing->SetSigma(cg.spacing.maxCoeff());
  smoothing->Update();
  const Volume smooth = fromItk<float>(smoothing->GetOutput());

  auto bone = [&](int i, int j, int k) {
    const float hu = coarse.at(i, j, k);
    return hu >= options.hu_min && hu <= options.hu_max;
  };
  std::vector<Voter> voters;
  for (int k = 1; k + 1 < cg.size[2]; ++k)
    for (int j = 1; j + 1 < cg.size[1]; ++j)
      for (int i = 1; i + 1 < cg.size[0]; ++i) {
        if (!bone(i, j, k)) continue;
        if (bone(i - 1, j, k) && bone(i + 1, j, k) && bone(i, j - 1, k) && bone(i, j + 1, k) && bone(i, j, k - 1) &&
            bone(i, j, k + 1))
          continue;
        const Eigen::Vector3d index_gradient(smooth.at(i + 1, j, k) - smooth.at(i - 1, j, k),
                                             smooth.at(i, j + 1, k) - smooth.at(i, j - 1, k),
                                             smooth.at(i, j, k + 1) - smooth.at(i, j, k - 1));
        // Physical (LPS) gradient: d/dx = D^-T diag(1/spacing) d/dijk.
        const Eigen::Vector3d n = cg.direction * index_gradient.cwiseQuotient(cg.spacing);
        if (n.norm() <= 0) continue;
        const Eigen::Vector3d x = cg.toPhysical(Eigen::Vector3d(i, j, k));
        if (options.roi_min && ((x.array() < options.roi_min->array()).any() || (x.array() > options.roi_max->array()).any()))
          continue;
        voters.push_back({x, n.normalized()});
      }

  // Votes along the inward normal, then summed over 3x3x3 cells: the
  // discretised rays of one sphere spread over about one cell.
  std::vector<float> votes(static_cast<size_t>(cg.voxelCount()), 0.0f);
  const double step = 0.5 * cg.spacing.minCoeff();
  const double r_lo = options.min_head_radius_mm, r_hi = options.max_head_radius_mm;
  auto cellOf = [&](const Eigen::Vector3d& x, Eigen::Vector3i& v) {
    v = cg.toIndex(x).array().round().cast<int>();
    return (v.array() >= 0).all() && (v.array() < cg.size.array()).all();
  };
  for (const Voter& voter : voters)
    for (double t = r_lo; t <= r_hi; t += step) {
      Eigen::Vector3i v;
      if (cellOf(voter.x + t * voter.n, v)) votes[static_cast<size_t>(cg.linear(v[0], v[1], v[2]))] += 1.0f;
    }
  // The body's middle from its outline; else the field's, when the field is
  // wide enough to hold both sides; else (one joint in a narrow field) no
  // side is taken from positions, and the socket tells it below.
  const bool right = options.side == Side::Right;
  const std::optional<double> body_mid = bodyMidline(coarse);
  const bool wide = fieldWidthMm(g) >= kBothSidesWidthMm;
  const double mid_x = body_mid ? *body_mid : g.toPhysical((g.size.cast<double>() - Eigen::Vector3d::Ones()) / 2.0)[0];
  // One labelled bone: the label chose the side, and the bone's own outline
  // is no body's.
  const bool side_by_position = !options.one_bone && (body_mid.has_value() || wide);
  const double midline_margin = side_by_position ? effectiveMidlineMargin(g, options) : 0.0;
  // A head lies on its side of the middle and clear of it: structures on
  // the midline (a sacrum, a symphysis) can look round. Within the margin a
  // head is still taken when its socket lies medially on the asked side (a
  // field of view that is wide but not centred on the body puts a real head
  // near the field's middle).
  const auto onSide = [&](const HeadCandidate& c) {
    if (!side_by_position) return true;
    if ((c.center[0] < mid_x) != right) return false;
    if (std::abs(c.center[0] - mid_x) >= midline_margin) return true;
    const std::optional<Side> by_socket = sideBySocket(volume, c, options);
    return by_socket && *by_socket == options.side;
  };
  if (side_by_position) side.middle_x_mm = mid_x;
  side.middle_from_outline = body_mid.has_value();
  side.how = options.one_bone ? "the label's bone"
             : body_mid       ? "left or right of the body's middle (x = " + std::to_string(*body_mid) + " mm, from its outline)"
               : wide   ? "left or right of the field of view's middle"
                        : "";
  struct Peak { Eigen::Vector3d x; double votes; };
  std::vector<Peak> peaks;
  for (int k = 1; k + 1 < cg.size[2]; ++k)
    for (int j = 1; j + 1 < cg.size[1]; ++j)
      for (int i = 1; i + 1 < cg.size[0]; ++i) {
        double sum = 0;
        for (int dk = -1; dk <= 1; ++dk)
          for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di) sum += votes[static_cast<size_t>(cg.linear(i + di, j + dj, k + dk))];
        const Eigen::Vector3d x = cg.toPhysical(Eigen::Vector3d(i, j, k));
        // LPS: +x points to the patient's left; the field of view is centred on the body.
        if (sum > 0 && (!side_by_position || right == (x[0] < mid_x))) peaks.push_back({x, sum});
      }
  std::sort(peaks.begin(), peaks.end(), [](const Peak& a, const Peak& b) { return a.votes > b.votes; });
  std::vector<Peak> kept;  // strongest first, at least a head radius apart
  for (const Peak& p : peaks) {
    bool separate = true;
    for (const Peak& q : kept) separate = separate && (p.x - q.x).norm() > 0.5 * r_lo;
    if (separate) kept.push_back(p);
    if (kept.size() == 8) break;
  }
  // Each peak measured by rays cast from it at full resolution: the first
  // bone edge on each ray, and a sphere through the edges that agree.
  std::vector<HeadCandidate> candidates;
  for (const Peak& p : kept) {
    HeadCandidate c = measureHeadByRays(volume, p.x, options);
    log::debug("head candidate " + vec(p.x) + " mm (" + std::to_string(p.votes) + " votes) -> centre " + vec(c.center) +
               " mm, radius " + std::to_string(c.radius) + " mm, coverage " + std::to_string(c.coverage) + ", RMS " +
               std::to_string(c.rms_mm) + " mm");
    candidates.push_back(std::move(c));
  }
  // The plausible head with the largest spherical bone surface: a trochanter
  // or a tuberosity is smaller and less spherical, the outer surface of a
  // socket is never the first edge seen from the centre.
  // A head's size and share of bone surface, on the side, in the volume;
  // measured by rays, its edges must also make a sphere.
  const auto plausibleSphere = [&](const HeadCandidate& c) {
    return c.radius >= r_lo && c.radius <= r_hi && c.coverage >= options.min_coverage && insideVolume(g, c.center) &&
           onSide(c);
  };
  const auto plausible = [&](const HeadCandidate& c) { return c.wellMeasured(g.spacing.maxCoeff()) && plausibleSphere(c); };
  const HeadCandidate* best = nullptr;
  for (const HeadCandidate& c : candidates)
    if (plausible(c) && (!best || c.area() > best->area())) best = &c;
  // Candidates about the same place are two spheres through one structure's
  // edges: the one that fits them better is its shape (with coarse voxels a
  // sphere through part of a head and its socket can span more area).
  if (best) {
    const HeadCandidate* largest = best;
    for (const HeadCandidate& c : candidates)
      if (plausible(c) && (c.center - largest->center).norm() < 0.5 * largest->radius &&
          c.rms_mm / c.radius < best->rms_mm / best->radius)
        best = &c;
  }
  // A sphere as well measured but outside the radii a head may have: a head
  // larger or smaller than the range expects is passed over for lesser bone
  // (a trochanter), which the caller names. Within a factor of the range:
  // a screw's hole in the real 3 mm hip makes a sphere of 7 mm.
  if (outside_range) {
    constexpr double kNamedBeyondRange = 1.5;
    const HeadCandidate* passed_over = nullptr;
    for (const HeadCandidate& c : candidates)
      if (c.wellMeasured(g.spacing.maxCoeff()) && (c.radius < r_lo || c.radius > r_hi) &&
          c.radius > r_lo / kNamedBeyondRange && c.radius < r_hi * kNamedBeyondRange &&
          c.coverage >= options.min_coverage && insideVolume(g, c.center) && onSide(c) &&
          (!passed_over || c.area() > passed_over->area()))
        passed_over = &c;
    if (passed_over) *outside_range = *passed_over;
  }
  // In a narrow field without the body's outline, the socket says which
  // side the joint is: a joint of the other side is refused, not analysed.
  const auto sideConfirmed = [&](const HeadCandidate& c) {
    if (side_by_position || options.one_bone) return true;  // a labelled bone shows no socket
    const std::optional<Side> by_socket = sideBySocket(volume, c, options);
    const std::string joint_side = by_socket == Side::Right ? "right" : "left";
    if (!by_socket) {
      side.how = "";
    } else if (*by_socket != options.side) {
      side.other_side = true;
      side.how = "the joint in view is a " + joint_side + " one: its socket lies on its " +
                   (by_socket == Side::Right ? "left (+x)" : "right (-x)") + ", medially";
      return false;
    } else {
      side.how = "its socket lies medially (" + std::string(right ? "+x" : "-x") + "), in a field of view too narrow for both sides";
    }
    return true;
  };
  if (best) {
    if (!sideConfirmed(*best)) return false;
    head = *best;
    return true;
  }
  // No candidate's edges make a sphere: coarse voxels (2-3 mm slices) blur
  // the gap away and the rays meet socket and pelvis. Then the strongest
  // peak whose sphere through the surface voxels facing it (at about its
  // radius) is a plausible head; no cut along edges follows (edge_mm stays
  // empty). With finer voxels the rays see a head's edges: a rounded corner
  // of other bone (a sacrum's) would be all this finds, so nothing is taken.
  if (g.spacing.maxCoeff() < kSeparateEdgesMaxVoxelMm - 1e-6) return false;
  const double cell_area = cg.spacing.prod() / cg.spacing.minCoeff();
  for (const Peak& p : kept) {
    HeadCandidate c = sphereOfFacingVoxels(p.x, voters, options, cg.spacing.minCoeff(), cell_area);
    log::debug("head candidate " + vec(p.x) + " mm by facing surface voxels: centre " + vec(c.center) + " mm, radius " +
               std::to_string(c.radius) + " mm, coverage " + std::to_string(c.coverage));
    if (plausibleSphere(c)) {
      if (!sideConfirmed(c)) return false;
      head = c;
      return true;
    }
  }
  return false;
}

}  // namespace articula::imaging::detail
