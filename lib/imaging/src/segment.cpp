// Head segmentation with ITK filters on plain buffers (see segment.hpp).
#include "articula/imaging/segment.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <itkBinaryFillholeImageFilter.h>
#include <itkBinaryMorphologicalClosingImageFilter.h>
#include <itkBlackTopHatImageFilter.h>
#include <itkSmoothingRecursiveGaussianImageFilter.h>
#include <itkFlatStructuringElement.h>
#include <itkGeodesicActiveContourLevelSetImageFilter.h>
#include <itkGradientMagnitudeRecursiveGaussianImageFilter.h>
#include <itkMorphologicalWatershedFromMarkersImageFilter.h>
#include <itkSigmoidImageFilter.h>
#include <itkSignedMaurerDistanceMapImageFilter.h>

#include "articula/core/error.hpp"
#include "articula/core/log.hpp"
#include "articula/geometry/fibonacci.hpp"
#include "articula/geometry/sphere_fit.hpp"
#include "articula/imaging/edges.hpp"
#include "itk_bridge.hpp"

namespace articula::imaging {
namespace {

using Mask = Image<std::uint8_t>;

std::string vec(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s.precision(4);
  s << "(" << v[0] << ", " << v[1] << ", " << v[2] << ")";
  return s.str();
}

Mask fillHoles(const Mask& mask) {
  auto filter = itk::BinaryFillholeImageFilter<itk::Image<std::uint8_t, 3>>::New();
  filter->SetInput(toItk(mask));
  filter->SetForegroundValue(1);
  filter->FullyConnectedOff();
  filter->Update();
  return fromItk<std::uint8_t>(filter->GetOutput());
}

/// Signed Euclidean distance to the mask boundary in mm (negative inside).
Image<float> signedDistance(const Mask& mask) {
  auto filter = itk::SignedMaurerDistanceMapImageFilter<itk::Image<std::uint8_t, 3>, itk::Image<float, 3>>::New();
  filter->SetInput(toItk(mask));
  filter->SetUseImageSpacing(true);
  filter->SetSquaredDistance(false);
  filter->SetInsideIsPositive(false);
  filter->SetBackgroundValue(0);
  filter->Update();
  return fromItk<float>(filter->GetOutput());
}

/// The sub-grid [lo, hi] (inclusive voxel indices) of an image.
template <typename T>
Image<T> crop(const Image<T>& image, const Eigen::Vector3i& lo, const Eigen::Vector3i& hi) {
  Image<T> out;
  out.geometry = image.geometry;
  out.geometry.size = hi - lo + Eigen::Vector3i::Ones();
  out.geometry.origin = image.geometry.toPhysical(lo.cast<double>());
  out.voxels.resize(static_cast<size_t>(out.geometry.voxelCount()));
  for (int k = 0; k < out.geometry.size[2]; ++k)
    for (int j = 0; j < out.geometry.size[1]; ++j)
      for (int i = 0; i < out.geometry.size[0]; ++i) out.at(i, j, k) = image.at(lo[0] + i, lo[1] + j, lo[2] + k);
  return out;
}

/// Morphological closing with a ball of `radius_mm`: bridges the speckled
/// cancellous bone and thin cortex of real CT, so that hole filling can fill
/// the head's interior.
Mask close(const Mask& mask, double radius_mm) {
  if (radius_mm <= 0) return mask;
  using Ball = itk::FlatStructuringElement<3>;
  Ball::RadiusType radius;
  for (unsigned a = 0; a < 3; ++a)
    radius[a] = static_cast<itk::SizeValueType>(std::max(1.0, std::round(radius_mm / mask.geometry.spacing[static_cast<int>(a)])));
  auto filter = itk::BinaryMorphologicalClosingImageFilter<itk::Image<std::uint8_t, 3>, itk::Image<std::uint8_t, 3>, Ball>::New();
  filter->SetInput(toItk(mask));
  filter->SetKernel(Ball::Ball(radius));
  filter->SetForegroundValue(1);
  filter->SetSafeBorder(true);  // the volume's edge is not bone
  filter->Update();
  return fromItk<std::uint8_t>(filter->GetOutput());
}

bool insideVolume(const ImageGeometry& g, const Eigen::Vector3d& x) {
  const Eigen::Vector3d idx = g.toIndex(x);
  return (idx.array() >= -0.5).all() && (idx.array() <= g.size.cast<double>().array() - 0.5).all();
}

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

// A joint head's cap is nearly spherical: the RMS of its edges about their
// sphere stays below this share of the radius (real femoral and humeral
// heads 1-2.5 %, superellipsoids of exponents up to 2.6 about 3 %) plus a
// quarter voxel of quantisation; an ellipsoidal trochanter or a tuberosity
// does not.
constexpr double kMaxRelativeRms = 0.04;
constexpr double kRmsVoxelShare = 0.25;
// A field of view this wide (left-right) holds both sides of the body: a
// joint head then lies at least kAutomaticMidlineMargin from its middle
// (hips 70-110 mm, shoulders 120-200 mm; vertebral bodies, near-spherical
// too, lie on it).
constexpr double kBothSidesWidthMm = 250, kAutomaticMidlineMargin = 40;
constexpr int kRayCount = 512;

/// A head measured from a point inside it: the sphere through the first bone
/// edges seen on rays from that point, and the edges themselves.
struct HeadCandidate {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 0, coverage = 0, rms_mm = 0;  // coverage: share of the rays whose edge lies on the sphere
  std::vector<double> edge_mm;                  // per ray of the lattice, from `center`; NaN: no edge on the sphere
  double area() const { return coverage * 4 * M_PI * radius * radius; }
  /// Edges on a third of the rays and nearly spherical: a head's cap seen
  /// through a visible gap.
  bool wellMeasured(double voxel_mm) const {
    return !edge_mm.empty() && coverage >= 0.3 && rms_mm <= kMaxRelativeRms * radius + kRmsVoxelShare * voxel_mm;
  }
};

/// Casts kRayCount rays (Fibonacci lattice) from `start`, takes the first
/// bone edge on each (imaging/edges.hpp: full resolution, sub-voxel), and
/// fits a sphere to the edges within a band of the median distance, twice
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
  for (int round = 0; round < 2; ++round) {
    std::vector<Eigen::Vector3d> edges(kRayCount, Eigen::Vector3d::Constant(NAN));
    std::vector<double> distances;
    for (int n = 0; n < kRayCount; ++n) {
      const Eigen::Vector3d u = geometry::fibonacciDirection(n, kRayCount);
      const Edge e = firstEdgeAlongRay(volume, c.center, u, 0.4 * r_lo, 1.25 * r_hi, search);
      if (!e.found) continue;
      edges[static_cast<size_t>(n)] = c.center + e.offset_mm * u;
      distances.push_back(e.offset_mm);
    }
    if (distances.size() < 10) return c;
    std::nth_element(distances.begin(), distances.begin() + static_cast<long>(distances.size() / 2), distances.end());
    geometry::Sphere sphere{c.center, distances[distances.size() / 2]};
    const double voxel = volume.geometry.spacing.maxCoeff();
    std::vector<char> inlier(edges.size(), 0);
    for (double band_share : {0.12, 0.06, 0.04}) {
      const double band = std::max({band_share * sphere.radius, 0.75 * voxel, 1.0});
      std::vector<Eigen::Vector3d> kept;
      for (size_t n = 0; n < edges.size(); ++n) {
        inlier[n] = !std::isnan(edges[n][0]) && std::abs((edges[n] - sphere.center).norm() - sphere.radius) <= band;
        if (inlier[n]) kept.push_back(edges[n]);
      }
      if (kept.size() < 10) return c;
      Eigen::MatrixX3d points(static_cast<Eigen::Index>(kept.size()), 3);
      for (size_t i = 0; i < kept.size(); ++i) points.row(static_cast<Eigen::Index>(i)) = kept[i].transpose();
      try {
        sphere = geometry::fitSphere(points);
      } catch (const ProcessingError&) {
        return c;  // degenerate support (a flat or tiny patch): no head here
      }
    }
    c.center = sphere.center;
    c.radius = sphere.radius;
    double sse = 0;
    int used = 0;
    c.edge_mm.assign(edges.size(), NAN);
    for (size_t n = 0; n < edges.size(); ++n) {
      if (!inlier[n]) continue;
      const double residual = (edges[n] - sphere.center).norm() - sphere.radius;
      sse += residual * residual;
      ++used;
      // The edge's distance from the final centre along its ray's direction
      // (the ray left from the previous centre, a fraction of a mm away).
      c.edge_mm[n] = (edges[n] - sphere.center).dot(geometry::fibonacciDirection(static_cast<int>(n), kRayCount));
    }
    c.coverage = static_cast<double>(used) / kRayCount;
    c.rms_mm = std::sqrt(sse / std::max(used, 1));
  }
  return c;
}

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

/// The head's edge distance per lattice direction, with the holes of its cap
/// (a missed edge, the fovea's pit) filled from their neighbours: a
/// direction without an edge whose nearest neighbours mostly have one lies
/// inside the cap. The neck's directions, without neighbours on the cap, stay empty.
std::vector<double> capEdges(const HeadCandidate& head) {
  std::vector<double> edge = head.edge_mm;
  constexpr int kNeighbours = 6;
  std::vector<std::vector<int>> neighbours(kRayCount);
  for (int n = 0; n < kRayCount; ++n) {
    const Eigen::Vector3d u = geometry::fibonacciDirection(n, kRayCount);
    std::vector<std::pair<double, int>> by_angle;
    for (int m = 0; m < kRayCount; ++m)
      if (m != n) by_angle.emplace_back(-u.dot(geometry::fibonacciDirection(m, kRayCount)), m);
    std::partial_sort(by_angle.begin(), by_angle.begin() + kNeighbours, by_angle.end());
    for (int k = 0; k < kNeighbours; ++k) neighbours[static_cast<size_t>(n)].push_back(by_angle[static_cast<size_t>(k)].second);
  }
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<double> next = edge;
    for (int n = 0; n < kRayCount; ++n) {
      if (!std::isnan(edge[static_cast<size_t>(n)])) continue;
      double sum = 0;
      int count = 0;
      for (int m : neighbours[static_cast<size_t>(n)])
        if (!std::isnan(edge[static_cast<size_t>(m)])) sum += edge[static_cast<size_t>(m)], ++count;
      if (count >= 4) next[static_cast<size_t>(n)] = sum / count;
    }
    edge = next;
  }
  return edge;
}

/// Removes from the bone mask what lies beyond the head's edge in the
/// directions of its cap: the joint gap and the socket, however narrow the
/// gap and whatever the closing bridged. The margin keeps the partial-volume
/// voxels of the head's own edge (the mesh stage places the surface on the
/// CT's edge within them).
void cutBeyondEdges(Image<std::uint8_t>& mask, const HeadCandidate& head) {
  static const LatticeLookup lookup;
  const std::vector<double> edge = capEdges(head);
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

/// The margin about the field of view's middle (left-right) that no head
/// lies in: as given, or automatic (options.midline_margin_mm < 0).
double effectiveMidlineMargin(const ImageGeometry& g, const SegmentOptions& options) {
  if (options.midline_margin_mm >= 0) return options.midline_margin_mm;
  double lo = INFINITY, hi = -INFINITY;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d ijk((corner & 1) ? g.size[0] - 1 : 0, (corner & 2) ? g.size[1] - 1 : 0, (corner & 4) ? g.size[2] - 1 : 0);
    const double x = g.toPhysical(ijk)[0];
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  return hi - lo >= kBothSidesWidthMm ? kAutomaticMidlineMargin : 0.0;
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
bool findHead(const Volume& volume, const SegmentOptions& options, HeadCandidate& head) {
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
  const double mid_x = g.toPhysical((g.size.cast<double>() - Eigen::Vector3d::Ones()) / 2.0)[0];
  const double midline_margin = effectiveMidlineMargin(g, options);
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
        if (sum > 0 && (options.side == Side::Right) == (x[0] < mid_x)) peaks.push_back({x, sum});
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
  const HeadCandidate* best = nullptr;
  for (const HeadCandidate& c : candidates) {
    const bool plausible = c.wellMeasured(g.spacing.maxCoeff()) && c.radius >= r_lo && c.radius <= r_hi &&
                           c.coverage >= options.min_coverage && (c.center[0] < mid_x) == (options.side == Side::Right) &&
                           std::abs(c.center[0] - mid_x) >= midline_margin && insideVolume(g, c.center);
    if (plausible && (!best || c.area() > best->area())) best = &c;
  }
  if (best) {
    head = *best;
    return true;
  }
  // No candidate's edges make a sphere: coarse voxels (3 mm) blur the gap
  // away and the rays meet socket and pelvis. Then the strongest peak whose
  // sphere through the surface voxels facing it (at about its radius) is a
  // plausible head; no cut along edges follows (edge_mm stays empty).
  const double cell_area = cg.spacing.prod() / cg.spacing.minCoeff();
  for (const Peak& p : kept) {
    HeadCandidate c = sphereOfFacingVoxels(p.x, voters, options, cg.spacing.minCoeff(), cell_area);
    log::debug("head candidate " + vec(p.x) + " mm by facing surface voxels: centre " + vec(c.center) + " mm, radius " +
               std::to_string(c.radius) + " mm, coverage " + std::to_string(c.coverage));
    if (c.radius >= r_lo && c.radius <= r_hi && c.coverage >= options.min_coverage &&
        (c.center[0] < mid_x) == (options.side == Side::Right) && std::abs(c.center[0] - mid_x) >= midline_margin &&
        insideVolume(g, c.center)) {
      head = c;
      return true;
    }
  }
  return false;
}

/// Marker watershed on the signed distance to the bone surface: the head's
/// centre is a deep basin, and the bone bridges across the joint gap and the
/// head-neck junction are saddles where the head region stops. Markers: the
/// head core (ball of 0.85 r), far bone (beyond 1.35 r: socket, pelvis, shaft)
/// and everything outside the bone mask.
Mask watershedHead(const Image<float>& distance, const Mask& bone, const Eigen::Vector3d& center, double r) {
  const ImageGeometry& bg = bone.geometry;
  Image<unsigned> markers;
  markers.geometry = bg;
  markers.voxels.assign(bone.voxels.size(), 0);
  long long head_marker = 0;
  for (int k = 0; k < bg.size[2]; ++k)
    for (int j = 0; j < bg.size[1]; ++j)
      for (int i = 0; i < bg.size[0]; ++i) {
        const double d = (bg.toPhysical(Eigen::Vector3d(i, j, k)) - center).norm();
        unsigned& m = markers.at(i, j, k);
        if (!bone.at(i, j, k)) m = 3;
        else if (d < 0.85 * r) m = 1, ++head_marker;
        else if (d > 1.35 * r) m = 2;
      }
  if (head_marker == 0)
    throw ProcessingError("the seed " + vec(center) + " mm is not inside bone in the HU window");
  using FloatImage = itk::Image<float, 3>;
  using LabelImage = itk::Image<unsigned, 3>;
  auto watershed = itk::MorphologicalWatershedFromMarkersImageFilter<FloatImage, LabelImage>::New();
  watershed->SetInput(toItk(distance));
  watershed->SetMarkerImage(toItk(markers));
  watershed->SetMarkWatershedLine(false);
  watershed->SetFullyConnected(false);
  watershed->Update();
  const Image<unsigned> regions = fromItk<unsigned>(watershed->GetOutput());
  Mask head;
  head.geometry = bg;
  head.voxels.resize(regions.voxels.size());
  for (size_t n = 0; n < regions.voxels.size(); ++n) head.voxels[n] = regions.voxels[n] == 1 && bone.voxels[n];
  // A head is a solid: closing with a ball of a third of its radius bridges
  // the gaps of a thin or porous cortex (osteoporotic or lossy-compressed
  // bone falls below the window), so that its interior fills. Its convex
  // articular surface is left as it is.
  return fillHoles(close(head, r / 3));
}

/// Median of the values of `image` where `where` holds.
double medianWhere(const Image<float>& image, const std::vector<char>& where) {
  std::vector<float> v;
  for (size_t n = 0; n < where.size(); ++n)
    if (where[n]) v.push_back(image.voxels[n]);
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

/// Geodesic active contour (Caselles et al. 1997; the "snake" of ITK-SNAP
/// the thesis used), started from the head label: it pulls the surface onto
/// the strongest HU edge nearby and smooths it. The edge map is a sigmoid of
/// the gradient magnitude scaled by the label's own statistics (the median
/// gradient on its boundary is an edge, the median inside is not). The result
/// stays within two voxels of the label, so it cannot leak across the gap.
Mask refineByLevelSet(const Volume& hu, const Mask& head, int iterations) {
  using FloatImage = itk::Image<float, 3>;
  const ImageGeometry& g = hu.geometry;
  auto gradient = itk::GradientMagnitudeRecursiveGaussianImageFilter<FloatImage, FloatImage>::New();
  gradient->SetInput(toItk(hu));
  gradient->SetSigma(g.spacing.minCoeff());
  gradient->Update();
  const Image<float> magnitude = fromItk<float>(gradient->GetOutput());
  const Image<float> initial = signedDistance(head);  // mm, negative inside
  const double voxel = g.spacing.maxCoeff();
  std::vector<char> boundary(head.voxels.size()), interior(head.voxels.size());
  for (size_t n = 0; n < head.voxels.size(); ++n) {
    boundary[n] = std::abs(initial.voxels[n]) <= voxel;
    interior[n] = initial.voxels[n] < -3 * voxel;
  }
  const double edge = medianWhere(magnitude, boundary), flat = medianWhere(magnitude, interior);
  if (!(edge > flat)) return head;  // no edge to snap to
  auto sigmoid = itk::SigmoidImageFilter<FloatImage, FloatImage>::New();
  sigmoid->SetInput(gradient->GetOutput());
  sigmoid->SetOutputMinimum(0.0f);
  sigmoid->SetOutputMaximum(1.0f);
  sigmoid->SetAlpha(-(edge - flat) / 6.0);  // the ITK guide's choice: ~0 on edges, ~1 inside
  sigmoid->SetBeta((edge + flat) / 2.0);
  auto contour = itk::GeodesicActiveContourLevelSetImageFilter<FloatImage, FloatImage>::New();
  contour->SetInput(toItk(initial));
  contour->SetFeatureImage(sigmoid->GetOutput());
  contour->SetPropagationScaling(0.0);
  contour->SetCurvatureScaling(0.5);
  contour->SetAdvectionScaling(1.0);
  contour->SetMaximumRMSError(0.002);
  contour->SetNumberOfIterations(static_cast<itk::IdentifierType>(iterations));
  contour->Update();
  const Image<float> phi = fromItk<float>(contour->GetOutput());
  Mask out = head;
  for (size_t n = 0; n < out.voxels.size(); ++n) {
    const float d = initial.voxels[n];
    out.voxels[n] = d < -2 * voxel || (d <= 2 * voxel && phi.voxels[n] < 0) ? 1 : 0;
  }
  log::debug("level set: " + std::to_string(contour->GetElapsedIterations()) + " iterations, RMS change " +
             std::to_string(contour->GetRMSChange()) + ", edge " + std::to_string(edge) + " HU/mm, flat " +
             std::to_string(flat) + " HU/mm");
  return fillHoles(out);
}

}  // namespace

void SegmentOptions::validate() const {
  // Ranges that keep the work bounded: joint heads are 15-35 mm in radius
  // (60 mm leaves room for any animal or implant study), the closing and the
  // gap filter act on millimetres, the search grid on a few voxels.
  const auto range = [](double v, double lo, double hi, const std::string& what) {
    if (!(v >= lo && v <= hi)) {
      std::ostringstream m;
      m << what << ": expected " << lo << " to " << hi << ", found " << v;
      throw UsageError(m.str());
    }
  };
  range(hu_min, -2000, 10000, "--hu-min (HU)");
  range(hu_max, -2000, 40000, "--hu-max (HU)");
  if (!(hu_min < hu_max)) throw UsageError("--hu-min must be below --hu-max");
  if (roi_min.has_value() != roi_max.has_value()) throw UsageError("--roi needs both corners");
  if (roi_min && (roi_max->array() <= roi_min->array()).any())
    throw UsageError("--roi: expected xmin,ymin,zmin,xmax,ymax,zmax with min < max");
  range(min_head_radius_mm, 1, 60, "--min-radius (mm)");
  range(max_head_radius_mm, 1, 60, "--max-radius (mm)");
  if (!(min_head_radius_mm < max_head_radius_mm)) throw UsageError("head radius range must satisfy min < max");
  range(search_spacing_mm, 0.5, 10, "search spacing (mm)");
  range(close_radius_mm, 0, 20, "--close-radius (mm)");
  range(gap_width_mm, 0.5, 20, "joint gap width (mm)");
  if (level_set_iterations < 0 || level_set_iterations > 10000) throw UsageError("--level-set: expected 0 to 10000 iterations");
  if (!(midline_margin_mm == -1)) range(midline_margin_mm, 0, 500, "--midline-margin (mm; -1: automatic)");
  range(min_coverage, 0, 1, "--min-coverage");
}

Label segmentHead(const Volume& volume, const SegmentOptions& options, SegmentSummary* summary_out) {
  options.validate();
  SegmentSummary summary;
  const ImageGeometry& g = volume.geometry;

  // 1. HU window within the ROI.
  Mask mask;
  mask.geometry = g;
  mask.voxels.assign(volume.voxels.size(), 0);
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        const float hu = volume.at(i, j, k);
        if (hu < options.hu_min || hu > options.hu_max) continue;
        if (options.roi_min) {
          const Eigen::Vector3d x = g.toPhysical(Eigen::Vector3d(i, j, k));
          if ((x.array() < options.roi_min->array()).any() || (x.array() > options.roi_max->array()).any()) continue;
        }
        mask.at(i, j, k) = 1;
        ++summary.threshold_voxels;
      }
  if (summary.threshold_voxels == 0) {
    std::ostringstream m;
    m << "no voxel in the HU window [" << options.hu_min << ", " << options.hu_max << "]"
      << (options.roi_min ? " inside the ROI" : "") << "; is this a CT in Hounsfield units?";
    throw InputError(m.str());
  }

  // 2. The head: measured from the seed point, or searched on the requested side.
  double depth = 0;
  Eigen::Vector3d center;
  HeadCandidate head_found;
  bool measured = false;  // a sphere through the head's edges (its rays cut the socket off)
  if (options.seed_point) {
    center = *options.seed_point;
    summary.seed_source = "seed-point";
    if (!insideVolume(g, center))
      throw InputError("--seed-point " + vec(center) + " lies outside the volume");
    depth = options.max_head_radius_mm;  // crop generously around a given seed
    head_found = measureHeadByRays(volume, center, options);
    measured = head_found.radius >= options.min_head_radius_mm && head_found.radius <= options.max_head_radius_mm &&
               head_found.coverage >= options.min_coverage && head_found.wellMeasured(g.spacing.maxCoeff()) &&
               (head_found.center - center).norm() <= head_found.radius;
    if (measured) center = head_found.center, depth = head_found.radius;
  } else {
    const std::string joint = options.joint == Joint::Hip ? "hip" : "shoulder";
    const std::string side = options.side == Side::Right ? "right" : "left";
    summary.seed_source = "automatic (" + joint + ", " + side + ")";
    if (!findHead(volume, options, head_found)) {
      std::ostringstream m;
      m << "no " << (options.joint == Joint::Hip ? "femoral" : "humeral") << " head found on the " << side
        << " side: no sphere of radius " << options.min_head_radius_mm << "-" << options.max_head_radius_mm
        << " mm has bone edges over " << options.min_coverage << " of its surface within "
        << kMaxRelativeRms * 100 << " % of its radius RMS (-v lists the candidates);"
        << " give --seed-point X,Y,Z (LPS mm) or adjust --hu-min";
      throw ProcessingError(m.str());
    }
    measured = !head_found.edge_mm.empty();
    center = head_found.center;
    depth = head_found.radius;
    log::info("head found at " + vec(center) + " mm, radius " + std::to_string(depth) + " mm" +
              (measured ? ", edges on " + std::to_string(static_cast<int>(std::lround(100 * head_found.coverage))) +
                              " % of the rays, RMS " + std::to_string(head_found.rms_mm) + " mm"
                        : " (by its facing surface voxels: the rays found no spherical edge)"));
  }
  if (measured) {
    summary.edge_coverage = head_found.coverage;
    summary.edge_rms_mm = head_found.rms_mm;
  }
  summary.seed_mm = center;

  // 3. Work on a box around the head that also holds the socket.
  const double half = std::max(2.2 * depth, depth + 25.0);
  Eigen::Vector3i lo = Eigen::Vector3i::Constant(1 << 30), hi = Eigen::Vector3i::Constant(-(1 << 30));
  for (int corner = 0; corner < 8; ++corner) {
    Eigen::Vector3d x = center;
    for (int a = 0; a < 3; ++a) x[a] += (corner >> a & 1) ? half : -half;
    const Eigen::Vector3d idx = g.toIndex(x);
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], static_cast<int>(std::floor(idx[a])));
      hi[a] = std::max(hi[a], static_cast<int>(std::ceil(idx[a])));
    }
  }
  lo = lo.cwiseMax(0);
  hi = hi.cwiseMin(g.size - Eigen::Vector3i::Ones());
  // The joint gap is a narrow dark valley between two bright cortices; where
  // partial volume lifts it into the HU window, or the closing bridges it,
  // the black top-hat (closing minus image) finds it, and those voxels leave
  // the bone mask.
  Mask box_raw = close(crop(mask, lo, hi), options.close_radius_mm);
  const Volume box_hu = crop(volume, lo, hi);
  if (options.gap_contrast_hu > 0) {
    using FloatImage = itk::Image<float, 3>;
    using Ball = itk::FlatStructuringElement<3>;
    Ball::RadiusType radius;
    for (unsigned a = 0; a < 3; ++a)
      radius[a] = static_cast<itk::SizeValueType>(std::max(1.0, std::ceil(options.gap_width_mm / 2 / box_hu.geometry.spacing[static_cast<int>(a)])));
    auto tophat = itk::BlackTopHatImageFilter<FloatImage, FloatImage, Ball>::New();
    tophat->SetInput(toItk(box_hu));
    tophat->SetKernel(Ball::Ball(radius));
    tophat->Update();
    const Image<float> valley = fromItk<float>(tophat->GetOutput());
    long long removed = 0;
    for (size_t n = 0; n < box_raw.voxels.size(); ++n)
      if (box_raw.voxels[n] && valley.voxels[n] > options.gap_contrast_hu && box_hu.voxels[n] < options.surface_hu)
        box_raw.voxels[n] = 0, ++removed;
    log::debug("joint-gap valley: " + std::to_string(removed) + " voxels removed from the bone mask");
  }
  if (measured) cutBeyondEdges(box_raw, head_found);
  const Mask box_mask = fillHoles(box_raw);
  const ImageGeometry& bg = box_mask.geometry;
  const Image<float> box_distance = signedDistance(box_mask);
  // A seed point is only somewhere inside the head: re-centre on the deepest
  // full-resolution bone near it, and once more on the label's deepest point
  // (the seed can sit off-centre where bone is joined). The automatic
  // search's sphere is already centred.
  const bool recentre = options.seed_point.has_value() && !measured;
  if (recentre) {
    const Eigen::Vector3d start = center;
    double deepest = 0;
    for (int k = 0; k < bg.size[2]; ++k)
      for (int j = 0; j < bg.size[1]; ++j)
        for (int i = 0; i < bg.size[0]; ++i) {
          const Eigen::Vector3d x = bg.toPhysical(Eigen::Vector3d(i, j, k));
          if ((x - start).norm() < 0.5 * depth && -box_distance.at(i, j, k) > deepest) {
            deepest = -box_distance.at(i, j, k);
            center = x;
          }
        }
    if (deepest > 0) depth = deepest;
  }

  // 4-6. Watershed from markers.
  Mask head;
  double best = 0;
  for (int pass = 0; pass < (recentre ? 2 : 1); ++pass) {
    const double r = pass == 0 ? depth : best;
    if (pass == 1) center = summary.head_center_mm;
    head = watershedHead(box_distance, box_mask, center, r);
    const Image<float> head_distance = signedDistance(head);
    best = 0;
    for (int k = 0; k < bg.size[2]; ++k)
      for (int j = 0; j < bg.size[1]; ++j)
        for (int i = 0; i < bg.size[0]; ++i)
          if (-head_distance.at(i, j, k) > best) {
            best = -head_distance.at(i, j, k);
            summary.head_center_mm = bg.toPhysical(Eigen::Vector3d(i, j, k));
          }
    if (best < 0.5 * options.min_head_radius_mm) break;  // no head to re-centre on
  }
  if (!recentre) summary.head_center_mm = center, summary.search_radius_mm = depth;
  summary.head_depth_mm = best;
  if (best < 0.5 * options.min_head_radius_mm)
    summary.warnings.push_back("the labelled head is thin (depth " + std::to_string(best) +
                               " mm): the seed may not be in a joint head");

  // The surface: on the HU edge by an active contour, or at the surface
  // level (nearer half maximum than the window's lower end, which sits a
  // third of a voxel outside in partial volume).
  if (options.level_set_iterations > 0) {
    head = refineByLevelSet(box_hu, head, options.level_set_iterations);
  } else if (!measured && options.surface_hu > options.hu_min) {
    // No cut along the head's edges (coarse voxels): peel the label's outer
    // layer twice where it is darker than surface_hu, which opens the thin
    // partial-volume bridges to the socket (the cortex keeps the darker
    // cancellous interior inside). With the cut, the label ends where the HU
    // window does and the mesh stage places the surface on the CT's edge.
    for (int peel = 0; peel < 2; ++peel) {
      Mask next = head;
      for (int k = 0; k < bg.size[2]; ++k)
        for (int j = 0; j < bg.size[1]; ++j)
          for (int i = 0; i < bg.size[0]; ++i) {
            if (!head.at(i, j, k) || box_hu.at(i, j, k) >= options.surface_hu) continue;
            const bool outer = i == 0 || j == 0 || k == 0 || i + 1 == bg.size[0] || j + 1 == bg.size[1] ||
                               k + 1 == bg.size[2] || !head.at(i - 1, j, k) || !head.at(i + 1, j, k) ||
                               !head.at(i, j - 1, k) || !head.at(i, j + 1, k) || !head.at(i, j, k - 1) ||
                               !head.at(i, j, k + 1);
            if (outer) next.at(i, j, k) = 0;
          }
      head = next;
    }
  }

  Label label;
  label.geometry = g;
  label.voxels.assign(volume.voxels.size(), 0);
  for (int k = 0; k < bg.size[2]; ++k)
    for (int j = 0; j < bg.size[1]; ++j)
      for (int i = 0; i < bg.size[0]; ++i)
        if (head.at(i, j, k)) {
          label.at(lo[0] + i, lo[1] + j, lo[2] + k) = 1;
          ++summary.label_voxels;
        }
  if (summary.label_voxels == 0) throw ProcessingError("the head label is empty after separation");
  if (summary_out) *summary_out = summary;
  return label;
}

}  // namespace articula::imaging
