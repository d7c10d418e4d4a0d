#include "articula/imaging/cortex_edge.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Cholesky>
#include <nlopt.hpp>

#include "articula/core/parallel.hpp"

namespace articula::imaging {
namespace {

constexpr double kSearchMm = 1.0;        // the surface is sought this far either side of the guess
constexpr double kMinThicknessMm = 0.1, kMaxThicknessMm = 4.0;
constexpr double kMinGapMm = 0.8, kMaxGapMm = 4.0;  // the narrowest joint gaps are about 1.5 mm
constexpr int kMinLines = 30;
constexpr size_t kCoarseLines = 200;  // the point-spread's grids find their basin on about this many lines
constexpr double kMinAcrossShare = 0.1;  // of the lines' summed slice share, for a slice width of its own
constexpr double kWidthRange = 2.5;      // each width within this factor of the common one
constexpr double kExplainedRmsRatio = 1.3;  // a line within long slices tells their width when its misfit is within this of the median
constexpr double kSocketRiseHu = 150;  // a rise beyond the edge this high is a socket (the edges' least contrast)
constexpr double kHeldLevelVoxels = 4;          // a held level weighs as much as this many voxels that show it
constexpr double kHeldAcrossSlicesRatio = 1.2;  // slices this much longer than the in-plane voxel ...
constexpr double kHeldAcrossBlurRatio = 1.1;    // ... or a blur this much wider across them (an isotropic one: within 0.93-1.07)

constexpr unsigned kNoiseLeanSeed = 20261202;  // the noise the width's lean is measured under (estimatePointSpread)
constexpr double kTableStepMm = 0.01;    // a voxel-grid blur's step response is tabulated this finely
constexpr double kGridKernelWidths = 4;  // image filters' usual truncation of a sampled Gaussian

// The standard normal's distribution function, tabulated every 1/1024 over
// +-8 and read by linear interpolation (error below 1e-7): the scanner
// blur's response is read some 10^8 times in a CT's estimate, and erfc
// took a tenth of the mesh stage.
constexpr double kPhiReach = 8.0, kPhiPerUnit = 1024.0;
const std::vector<double>& phiTable() {
  static const std::vector<double> table = [] {
    std::vector<double> t(static_cast<size_t>(2 * kPhiReach * kPhiPerUnit) + 1);
    for (size_t i = 0; i < t.size(); ++i)
      t[i] = 0.5 * std::erfc(-(static_cast<double>(i) / kPhiPerUnit - kPhiReach) * M_SQRT1_2);
    return t;
  }();
  return table;
}
double Phi(double z) {
  const std::vector<double>& t = phiTable();
  const double at = (z + kPhiReach) * kPhiPerUnit;
  if (!(at > 0)) return t.front();
  if (at >= static_cast<double>(t.size() - 1)) return t.back();
  const auto below = static_cast<size_t>(at);
  const double f = at - static_cast<double>(below);
  return t[below] + f * (t[below + 1] - t[below]);
}

/// `density` (every kTableStepMm from `first_mm`) convolved with weights
/// at `offsets_mm`, each split between its two nearest steps.
std::vector<double> spreadOver(const std::vector<double>& density, double& first_mm,
                               const std::vector<std::pair<double, double>>& offsets_weights) {
  double low = 0, high = 0;
  for (const auto& [offset, weight] : offsets_weights) low = std::min(low, offset), high = std::max(high, offset);
  const auto pad_low = static_cast<int>(std::ceil(-low / kTableStepMm)) + 1;
  const auto pad_high = static_cast<int>(std::ceil(high / kTableStepMm)) + 1;
  // Each weight lands a whole number of steps away plus the same share of
  // one for every point of the density.
  struct Landing {
    size_t steps;
    double below, above;
  };
  std::vector<Landing> landings;
  for (const auto& [offset, weight] : offsets_weights) {
    const double at = pad_low + offset / kTableStepMm, whole = std::floor(at);
    landings.push_back({static_cast<size_t>(whole), weight * (1 - (at - whole)), weight * (at - whole)});
  }
  std::vector<double> out(density.size() + static_cast<size_t>(pad_low + pad_high), 0.0);
  for (const Landing& l : landings) {
    double* below = out.data() + l.steps;
    double* above = below + 1;
    for (size_t i = 0; i < density.size(); ++i) below[i] += density[i] * l.below;
    for (size_t i = 0; i < density.size(); ++i) above[i] += density[i] * l.above;
  }
  first_mm -= pad_low * kTableStepMm;
  return out;
}

/// `density` (every kTableStepMm from `first_mm`) averaged over a box of
/// `width_mm` about each point: differences of its running sum, read
/// between steps by linear interpolation. Every output reads the running
/// sum at the same fraction of a step, so each end of the box is a fixed
/// index offset and one weight (this ran for every line at every width
/// tried, and per-point floors and clamps took most of the mesh stage's
/// point-spread estimate).
std::vector<double> boxOver(const std::vector<double>& density, double& first_mm, double width_mm) {
  const double half = 0.5 * width_mm / kTableStepMm;  // in steps
  const auto pad = static_cast<std::ptrdiff_t>(std::ceil(half)) + 1;
  const auto n = static_cast<std::ptrdiff_t>(density.size());
  const std::ptrdiff_t size = n + 2 * pad;
  // The running sum and the density on a margin of `size` steps either
  // side: the sum 0 below the first step and the total beyond the last,
  // the density 0 outside, so no read needs a clamp.
  const std::ptrdiff_t margin = size;
  std::vector<double> running(static_cast<size_t>(n + 2 * margin + 1), 0.0), steps(running.size(), 0.0);
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    steps[static_cast<size_t>(margin + i)] = density[static_cast<size_t>(i)];
    running[static_cast<size_t>(margin + i + 1)] = running[static_cast<size_t>(margin + i)] + density[static_cast<size_t>(i)];
  }
  for (auto i = static_cast<size_t>(margin + n + 1); i < running.size(); ++i) running[i] = running[i - 1];
  // The sum of the steps whose middles lie below output i's end at `end`
  // steps from it (its position: i - pad + end + 0.5 from the first middle).
  const auto end = [&](double reach) {
    const double at = reach + 0.5 - static_cast<double>(pad), whole = std::floor(at);
    return std::pair<std::ptrdiff_t, double>{margin + static_cast<std::ptrdiff_t>(whole), at - whole};
  };
  const auto [upper, upper_share] = end(half);
  const auto [lower, lower_share] = end(-half);
  const double scale = 1.0 / (2 * half);
  std::vector<double> out(static_cast<size_t>(size));
  const double *ru = running.data() + upper, *du = steps.data() + upper;
  const double *rl = running.data() + lower, *dl = steps.data() + lower;
  for (std::ptrdiff_t i = 0; i < size; ++i)
    out[static_cast<size_t>(i)] = ((ru[i] + upper_share * du[i]) - (rl[i] + lower_share * dl[i])) * scale;
  first_mm -= static_cast<double>(pad) * kTableStepMm;
  return out;
}

/// The HU levels of the model's steps and the residual they leave.
struct Levels {
  Eigen::Vector4d coef = Eigen::Vector4d::Zero();  // outside, cortex - outside, cancellous - outside, socket - outside
  double sum_squares = 0;
};

/// Least squares of the voxels' values over the columns of `rows` in `use`
/// (the others held at zero), each level i < 3 drawn towards prior[i] with
/// weight `prior_weight` (as if that many voxels had shown it alone); the
/// residual includes that pull. `normal` and `rhs`: the rows' sums
/// (rows^T rows, rows^T values), made once for both of fitLevels' solves.
Levels solveLevels(const std::vector<Eigen::Vector4d>& rows, const std::vector<double>& values,
                   const Eigen::Matrix4d& sums, const Eigen::Vector4d& rhs_sums, const Eigen::Vector4d& use,
                   const Eigen::Vector4d& prior, double prior_weight) {
  Eigen::Matrix4d normal = sums.cwiseProduct(use * use.transpose());
  Eigen::Vector4d rhs = rhs_sums.cwiseProduct(use);
  // A tiny ridge: a level the window does not reach (a cortex thicker than
  // it) stays at the outside's instead of making the system singular.
  normal.diagonal().array() += 1e-6 * static_cast<double>(rows.size());
  for (int i = 0; i < 3; ++i) {
    normal(i, i) += prior_weight * use[i];
    rhs[i] += prior_weight * use[i] * prior[i];
  }
  Levels l;
  l.coef = normal.ldlt().solve(rhs).cwiseProduct(use);
  for (size_t i = 0; i < rows.size(); ++i) {
    const double r = rows[i].dot(l.coef) - values[i];
    l.sum_squares += r * r;
  }
  for (int i = 0; i < 3; ++i) l.sum_squares += prior_weight * use[i] * (l.coef[i] - prior[i]) * (l.coef[i] - prior[i]);
  return l;
}

/// The blurred steps at surface e, cortex thickness t and gap g (to a socket
/// beyond the surface), with the HU levels that fit the voxels best:
/// f = outside + a (cortex layer) + b (cancellous) + c (socket), the levels
/// relative to the outside. The socket is brighter than the gap or absent:
/// a darker step there would reshape the surface's own fall and trade
/// against the blur. With `held` tissue, its levels are drawn towards the
/// held ones.
Levels fitLevels(const LineVoxels& line, double e, double t, double g, const StepResponse& blur,
                 const CortexTissue* held = nullptr) {
  const size_t n = line.offset_mm.size();
  thread_local std::vector<Eigen::Vector4d> rows;  // reused: this runs some 10^7 times in a CT's estimate
  rows.resize(n);
  // The normal equations' ten distinct sums by hand: Eigen's rank update of
  // a 4 x 4 matrix took a sixth of the model's time.
  double n00 = 0, n10 = 0, n11 = 0, n20 = 0, n21 = 0, n22 = 0, n30 = 0, n31 = 0, n32 = 0, n33 = 0;
  Eigen::Vector4d rhs = Eigen::Vector4d::Zero();
  for (size_t i = 0; i < n; ++i) {
    const double s = line.offset_mm[i];
    const double k0 = blur.brightShare(e - s), k1 = blur.brightShare(e - t - s), k2 = blur.brightShare(s - e - g);
    const Eigen::Vector4d r(1.0, k0 - k1, k1, k2);
    rows[i] = r;
    n00 += 1, n10 += r[1], n11 += r[1] * r[1], n20 += r[2], n21 += r[2] * r[1];
    n22 += r[2] * r[2], n30 += r[3], n31 += r[3] * r[1], n32 += r[3] * r[2], n33 += r[3] * r[3];
    rhs += r * line.value_hu[i];
  }
  Eigen::Matrix4d sums;
  sums << n00, n10, n20, n30, n10, n11, n21, n31, n20, n21, n22, n32, n30, n31, n32, n33;
  Eigen::Vector4d prior = Eigen::Vector4d::Zero();
  if (held) prior << held->outside_hu, held->cortex_hu - held->outside_hu, held->inside_hu - held->outside_hu, 0;
  const double weight = held ? kHeldLevelVoxels : 0.0;
  Levels l = solveLevels(rows, line.value_hu, sums, rhs, Eigen::Vector4d::Ones(), prior, weight);
  if (l.coef[3] < 0) l = solveLevels(rows, line.value_hu, sums, rhs, Eigen::Vector4d(1, 1, 1, 0), prior, weight);
  return l;
}

/// The residual at (surface, thickness, gap), and the best point met: NLopt
/// may end its search with an exception (roundoff limits its progress on a
/// flat residual) after it has found a good point, and that point is kept.
/// With `held` tissue the search is over the surface and the gap alone.
struct Objective {
  const LineVoxels* line = nullptr;
  const StepResponse* blur = nullptr;
  const CortexTissue* held = nullptr;
  double best = std::numeric_limits<double>::infinity();
  std::array<double, 3> best_point{};  // surface, thickness, gap

  std::array<double, 3> point(const double* p) const {
    return held ? std::array<double, 3>{p[0], held->thickness_mm, p[1]} : std::array<double, 3>{p[0], p[1], p[2]};
  }
};

double sumSquares(unsigned, const double* p, double*, void* data) {
  auto* o = static_cast<Objective*>(data);
  const std::array<double, 3> x = o->point(p);
  const double value = fitLevels(*o->line, x[0], x[1], x[2], *o->blur, o->held).sum_squares;
  if (value < o->best) {
    o->best = value;
    o->best_point = x;
  }
  return value;
}

/// Something bright beyond the edge: a socket across a joint gap (or
/// another bone), read from the voxels themselves in 0.25 mm bins beyond
/// half a millimetre outside, as a rise by more than kSocketRiseHu after
/// the lowest bin. (Not from the model's socket level, which also answers
/// noise and misfit on lines without one.) `window_end_mm`: the near side
/// of the brightest bin after the rise, about the middle of the socket's
/// own rise; a thin socket cortex falls again beyond it.
struct SocketInWindow {
  bool found = false;
  double window_end_mm = 0;
};
SocketInWindow socketInWindow(const LineVoxels& line) {
  constexpr double kFrom = 0.5, kBin = 0.25;
  constexpr int kBins = static_cast<int>((kCortexOutwardMm - kFrom) / kBin);
  std::array<double, kBins> sum{};
  std::array<int, kBins> count{};
  for (size_t i = 0; i < line.offset_mm.size(); ++i) {
    const int b = static_cast<int>(std::floor((line.offset_mm[i] - kFrom) / kBin));
    if (b < 0 || b >= kBins) continue;
    sum[static_cast<size_t>(b)] += line.value_hu[i];
    ++count[static_cast<size_t>(b)];
  }
  SocketInWindow socket;
  double lowest = std::numeric_limits<double>::infinity(), brightest = -lowest;
  for (int b = 0; b < kBins; ++b) {
    if (count[static_cast<size_t>(b)] == 0) continue;
    const double mean = sum[static_cast<size_t>(b)] / count[static_cast<size_t>(b)];
    if (!socket.found) {
      lowest = std::min(lowest, mean);
      socket.found = mean > lowest + kSocketRiseHu;
    }
    if (socket.found && mean > brightest) {
      brightest = mean;
      socket.window_end_mm = kFrom + b * kBin;
    }
  }
  return socket;
}

/// The line's voxels up to `outward_mm` along it.
LineVoxels upTo(const LineVoxels& line, double outward_mm) {
  LineVoxels near = line;
  near.offset_mm.clear();
  near.value_hu.clear();
  for (size_t i = 0; i < line.offset_mm.size(); ++i)
    if (line.offset_mm[i] <= outward_mm) {
      near.offset_mm.push_back(line.offset_mm[i]);
      near.value_hu.push_back(line.value_hu[i]);
    }
  return near;
}

/// The least of f near its samples' best: f sampled every `step` across
/// [from, to], the best sample's neighbourhood (five steps either side)
/// refined by the vertex of a least-squares parabola. The profile
/// likelihood summed over lines jumps by a few units from width to width
/// (each line's search ends a little differently); a bracketing search
/// follows those jumps into widths 0.02 mm off, a parabola over a span of
/// them does not. Returns the width and the parabola's value there.
template <class F>
std::pair<double, double> leastOfSmoothed(F f, double from, double to, double step) {
  constexpr double kLeastWidthMm = 0.01;
  std::vector<double> xs, ys;
  for (double x = std::max(from, kLeastWidthMm); x <= to + 1e-9; x += step) {
    xs.push_back(x);
    ys.push_back(f(x));
  }
  const auto best = static_cast<size_t>(std::min_element(ys.begin(), ys.end()) - ys.begin());
  constexpr int kReach = 5;
  const size_t first = best >= kReach ? best - kReach : 0, last = std::min(xs.size() - 1, best + kReach);
  if (last - first < 2) return {xs[best], ys[best]};
  // y = a + b (x - x0) + c (x - x0)^2 about the best sample.
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (size_t i = first; i <= last; ++i) {
    const double d = xs[i] - xs[best];
    const Eigen::Vector3d row(1, d, d * d);
    normal += row * row.transpose();
    rhs += row * ys[i];
  }
  const Eigen::Vector3d c = normal.ldlt().solve(rhs);
  const double vertex = -c[1] / (2 * c[2]);
  if (!(c[2] > 0) || std::abs(vertex) > (static_cast<double>(last - first) / 2) * step) return {xs[best], ys[best]};
  return {xs[best] + vertex, c[0] + c[1] * vertex + c[2] * vertex * vertex};
}

/// Every k-th of `all`, k the least that leaves at most kCoarseLines.
template <class T>
std::vector<T> thinned(const std::vector<T>& all) {
  const size_t stride = (all.size() + kCoarseLines - 1) / kCoarseLines;
  if (stride <= 1) return all;
  std::vector<T> out;
  for (size_t i = 0; i < all.size(); i += stride) out.push_back(all[i]);
  return out;
}

/// A grid search coarse to fine in lines: `f_few` (the sum over a few of
/// the lines) at each of `grid`, then `f` (over every line) at the few
/// sums' local minima, at most three, the lowest first; the grid index
/// where `f` is least. Fewer lines find the basins, and where a CT's
/// likelihood has two (a narrow width and a wide one trade against the
/// cortex's thickness at coarse voxels), every line chooses between them.
template <class F, class G>
size_t leastBasin(const std::vector<double>& grid, F f, G f_few) {
  constexpr size_t kBasins = 3;
  std::vector<double> few(grid.size());
  for (size_t i = 0; i < grid.size(); ++i) few[i] = f_few(grid[i]);
  std::vector<size_t> minima;
  for (size_t i = 0; i < grid.size(); ++i)
    if ((i == 0 || few[i] <= few[i - 1]) && (i + 1 == grid.size() || few[i] <= few[i + 1])) minima.push_back(i);
  std::sort(minima.begin(), minima.end(), [&](size_t a, size_t b) { return few[a] < few[b]; });
  if (minima.size() == 1) return minima.front();
  size_t best = minima.front();
  double best_value = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < std::min(kBasins, minima.size()); ++k)
    if (const double value = f(grid[minima[k]]); value < best_value) best = minima[k], best_value = value;
  return best;
}

}  // namespace

double cortexSearchMm(const Eigen::Vector3d& axis_extent_mm) {
  return std::max(kSearchMm, 0.75 * axis_extent_mm.norm());
}

double lineRadiusFor(const ImageGeometry& geometry, double noise_hu) {
  constexpr double kVoxels = 50;
  const double voxel_volume = geometry.spacing.prod();
  const double quiet = std::max(0.8, std::sqrt(kVoxels * voxel_volume / (M_PI * (kCortexInwardMm + kCortexOutwardMm))));
  // The voxels' count grows with the radius squared, the noise's variance
  // with the noise squared.
  if (!(noise_hu > kQuietCtNoiseHu)) return quiet;
  return std::max(quiet, std::min(quiet * std::min(noise_hu / kQuietCtNoiseHu, kMaxNoiseWidening), kMaxNoisyLineRadiusMm));
}

double lineRadiusFor(const ImageGeometry& geometry, const Eigen::Vector3d& u, double noise_hu) {
  const double radius = lineRadiusFor(geometry, noise_hu);
  if (!tissueHeldAcrossSlices(geometry.spacing)) return radius;
  // A slice met at angle theta from its axis spreads its voxels within the
  // radius r over 2 r sin(theta) of depth; one slice's reach along the line
  // is its spacing over cos(theta), the depths the next slice takes up.
  const double across = geometry.direction.col(2).dot(u);
  const double sine = std::sqrt(std::max(0.0, 1 - across * across));
  const double covering = 0.5 * geometry.spacing[2] / std::max(sine, 1e-3);
  return std::clamp(covering, radius, std::max(radius, kMaxLineRadiusMm));
}

LineVoxels voxelsAboutLine(const Volume& volume, const Eigen::Vector3d& x, const Eigen::Vector3d& u, double from_mm,
                           double to_mm, double radius_mm, double curvature_per_mm, const Eigen::Vector3d& extent_mm) {
  const ImageGeometry& g = volume.geometry;
  LineVoxels line;
  line.spacing_mm = g.spacing;
  line.extent_mm = extent_mm.isZero() ? g.voxelExtent() : extent_mm;
  line.point_mm = x;
  for (int a = 0; a < 3; ++a) {
    line.axis_step_mm[a] = g.spacing[a] * g.direction.col(a).dot(u);
    line.axis_extent_mm[a] = line.extent_mm[a] * g.direction.col(a).dot(u);
    line.box_variance_mm2 += line.axis_extent_mm[a] * line.axis_extent_mm[a] / 12.0;
  }
  const double across_slices = g.direction.col(2).dot(u);
  line.slice_share = across_slices * across_slices;
  line.curvature_per_mm = curvature_per_mm;
  // A voxel averages the bone over its extent across the line too, where a
  // curved surface lies deeper the further out: its value tells the surface
  // at its centre moved by the curvature times half that extent's variance
  // (0.02 mm on a 21 mm head across 3 mm slices; the offsets' lateral term).
  double lateral_box_variance_mm2 = 0;
  for (int a = 0; a < 3; ++a) {
    const double along = g.direction.col(a).dot(u);
    lateral_box_variance_mm2 += line.extent_mm[a] * line.extent_mm[a] / 12.0 * (1 - along * along);
  }
  // The index box around the segment, widened by the radius.
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max()), hi = -lo;
  for (const double s : {from_mm, to_mm}) {
    const Eigen::Vector3d idx = g.toIndex(x + s * u);
    lo = lo.cwiseMin(idx);
    hi = hi.cwiseMax(idx);
  }
  const Eigen::Vector3d pad = g.spacing.cwiseInverse() * radius_mm;
  Eigen::Vector3i first, last;
  for (int a = 0; a < 3; ++a) {
    first[a] = std::max(0, static_cast<int>(std::floor(lo[a] - pad[a])));
    last[a] = std::min(g.size[a] - 1, static_cast<int>(std::ceil(hi[a] + pad[a])));
    if (first[a] > last[a]) return line;
  }
  const double r2 = radius_mm * radius_mm;
  for (int k = first[2]; k <= last[2]; ++k)
    for (int j = first[1]; j <= last[1]; ++j)
      for (int i = first[0]; i <= last[0]; ++i) {
        const Eigen::Vector3d d = g.toPhysical(Eigen::Vector3d(i, j, k)) - x;
        const double s = d.dot(u), lateral2 = d.squaredNorm() - s * s;
        if (s < from_mm || s > to_mm || lateral2 > r2) continue;
        line.offset_mm.push_back(s + 0.5 * curvature_per_mm * (lateral2 + lateral_box_variance_mm2));
        line.value_hu.push_back(volume.at(i, j, k));
      }
  return line;
}

namespace {

// A Gaussian of `width_voxels` sampled at whole voxels as image filters
// take it, to kGridKernelWidths widths: how many voxels it reaches, and
// `visit(j, weight)` for j = 0 .. reach, unnormalised (1 at 0), without a
// buffer (a step response is made for every line at every width tried).
// exp(-j^2 / 2 w^2) by its ratio from j to j + 1, q^(2 j + 1), q = exp(-1 / 2 w^2).
int gridReach(double width_voxels) {
  return std::max(1, static_cast<int>(std::ceil(kGridKernelWidths * width_voxels)));
}
template <typename Visit>
void forEachGridWeight(double width_voxels, Visit visit) {
  const double q = std::exp(-0.5 / (width_voxels * width_voxels)), q2 = q * q;
  double w = 1, ratio = q;
  visit(0, 1.0);
  for (int j = 1, reach = gridReach(width_voxels); j <= reach; ++j) {
    w *= ratio;
    ratio *= q2;
    visit(j, w);
  }
}

}  // namespace

StepResponse::StepResponse(const LineVoxels& line, const PointSpread& spread) {
  if (spread.kind == PointSpread::Kind::Scanner) {
    width_mm_ = std::sqrt(spread.along(line) * spread.along(line) + line.box_variance_mm2);
    return;
  }
  // The grid's weights along each axis (its Gaussian sampled at whole
  // voxels, as image filters take it), laid along the line at the line's
  // travel per voxel; then each voxel's extent and the running sum.
  // Hand-written: the response of a filter on a grid, seen along a line at
  // any angle, is no library's.
  std::vector<double> density = {1.0};
  table_first_mm_ = 0;
  for (int a = 0; a < 3; ++a) {
    const double width_voxels = (a == 2 ? spread.slice_sigma_mm : spread.sigma_mm) / line.spacing_mm[a];
    if (!(width_voxels >= 0.1) || line.axis_step_mm[a] == 0) continue;  // weights beyond the voxel itself below e^-50
    const int reach = gridReach(width_voxels);
    std::vector<std::pair<double, double>> taps(static_cast<size_t>(2 * reach + 1));
    double sum = 0;
    forEachGridWeight(width_voxels, [&](int j, double w) {
      taps[static_cast<size_t>(reach + j)] = {j * line.axis_step_mm[a], w};
      taps[static_cast<size_t>(reach - j)] = {-j * line.axis_step_mm[a], w};
      sum += j == 0 ? w : 2 * w;
    });
    for (auto& tap : taps) tap.second /= sum;
    density = spreadOver(density, table_first_mm_, taps);
  }
  // Each voxel's extent along the line: a box along each grid axis (partial volume).
  for (int a = 0; a < 3; ++a) {
    const double extent = std::abs(line.axis_extent_mm[a]);
    if (extent >= kTableStepMm) density = boxOver(density, table_first_mm_, extent);
  }
  if (density.size() < 2) {  // no blur and no extent (a line made by hand): a sharp step
    width_mm_ = kTableStepMm;
    return;
  }
  // The share behind depth z: the weights at offsets below z (the kernel is
  // symmetric), each bin's weight counted from its middle.
  table_.resize(density.size());
  double running = 0;
  for (size_t i = 0; i < density.size(); ++i) {
    table_[i] = running + 0.5 * density[i];
    running += density[i];
  }
  for (double& share : table_) share /= running;
}

double curvatureShiftMm(const LineVoxels& line, const PointSpread& spread) {
  double across_line_mm2 = 0;  // the blur's variance across the line, summed over both directions
  for (int a = 0; a < 3; ++a) {
    const double width_mm = a == 2 ? spread.slice_sigma_mm : spread.sigma_mm;
    double variance_mm2 = width_mm * width_mm;
    if (spread.kind == PointSpread::Kind::VoxelGrid) {
      // The Gaussian sampled at whole voxels, as StepResponse lays it: its
      // weights' own variance (narrower than the Gaussian's below a voxel).
      const double width_voxels = width_mm / line.spacing_mm[a];
      variance_mm2 = 0;
      if (width_voxels >= 0.1) {
        double sum = 0, moment = 0;
        forEachGridWeight(width_voxels, [&](int j, double w) {
          sum += j == 0 ? w : 2 * w;
          moment += 2 * w * j * j;
        });
        variance_mm2 = moment / sum * line.spacing_mm[a] * line.spacing_mm[a];
      }
    }
    const double along = line.spacing_mm[a] > 0 ? line.axis_step_mm[a] / line.spacing_mm[a] : 0;
    across_line_mm2 += variance_mm2 * (1 - along * along);
  }
  return 0.5 * line.curvature_per_mm * across_line_mm2;
}

double StepResponse::brightShare(double depth_mm) const {
  if (table_.empty()) return Phi(depth_mm / width_mm_);
  const double at = (depth_mm - table_first_mm_) * (1.0 / kTableStepMm);
  if (at <= 0) return table_.front();  // the table reaches the kernel's ends: about 0 and 1 there
  if (at >= static_cast<double>(table_.size() - 1)) return table_.back();
  const auto below = static_cast<size_t>(at);
  const double f = at - static_cast<double>(below);
  return table_[below] * (1 - f) + table_[below + 1] * f;
}

CortexFit fitCortex(const LineVoxels& line, double guess_mm, double sigma_mm, double min_contrast_hu) {
  if (!(sigma_mm > 0)) return CortexFit{};
  return fitCortex(line, guess_mm, StepResponse(std::sqrt(sigma_mm * sigma_mm + line.box_variance_mm2)),
                   min_contrast_hu);
}

CortexFit fitCortex(const LineVoxels& whole_line, double guess_mm, const StepResponse& blur, double min_contrast_hu,
                    const CortexTissue* held) {
  CortexFit fit;
  // The model's socket is one step up: a socket whose own cortex is thin
  // falls again within the window, and fitted over that fall the surface
  // moves out (0.13-0.16 mm for a 0.8 mm cortex 1.5-2 mm away under 0.5 mm
  // of blur). The window ends in the socket's rise instead.
  const SocketInWindow socket = socketInWindow(whole_line);
  const LineVoxels near = socket.found ? upTo(whole_line, socket.window_end_mm) : LineVoxels{};
  const LineVoxels& line = socket.found ? near : whole_line;  // no copy of a line without a socket
  if (line.offset_mm.size() < 12 || !blur.valid()) return fit;
  Objective objective;
  objective.line = &line;
  objective.blur = &blur;
  objective.held = held;
  // BOBYQA: two or three bounded parameters, a cheap smooth objective
  // without derivatives (the levels are solved inside it, variable projection).
  const double search = cortexSearchMm(line.axis_extent_mm);
  const unsigned unknowns = held ? 2 : 3;
  nlopt::opt opt(nlopt::LN_BOBYQA, unknowns);
  if (held) {
    opt.set_lower_bounds({guess_mm - search, kMinGapMm});
    opt.set_upper_bounds({guess_mm + search, kMaxGapMm});
  } else {
    opt.set_lower_bounds({guess_mm - search, kMinThicknessMm, kMinGapMm});
    opt.set_upper_bounds({guess_mm + search, kMaxThicknessMm, kMaxGapMm});
  }
  opt.set_min_objective(sumSquares, &objective);
  opt.set_xtol_abs(1e-3);
  opt.set_maxeval(300);
  std::vector<double> p = held ? std::vector<double>{guess_mm, 2.0} : std::vector<double>{guess_mm, 1.0, 2.0};
  double best = 0;
  try {
    opt.optimize(p, best);
  } catch (const std::exception&) {
    // Only the search's end is lost: its best point stands.
  }
  if (!std::isfinite(objective.best)) return fit;  // not one finite residual was evaluated
  p.assign(objective.best_point.begin(), objective.best_point.end());
  const Levels l = fitLevels(line, p[0], p[1], p[2], blur, held);
  fit.offset_mm = p[0];
  fit.thickness_mm = p[1];
  fit.gap_mm = p[2];
  fit.outside_hu = l.coef[0];
  fit.cortex_hu = l.coef[0] + l.coef[1];
  fit.inside_hu = l.coef[0] + l.coef[2];
  fit.sum_squares = l.sum_squares;
  const bool bright_bone = std::max(l.coef[1], l.coef[2]) >= min_contrast_hu;
  const bool inside_search = std::abs(p[0] - guess_mm) < 0.98 * search;
  fit.found = bright_bone && inside_search && std::isfinite(l.sum_squares);
  return fit;
}

bool tissueHeldAcrossSlices(const Eigen::Vector3d& extent_mm) {
  return extent_mm[2] > kHeldAcrossSlicesRatio * std::max(extent_mm[0], extent_mm[1]);
}

bool tissueHeldAcrossSlices(const Eigen::Vector3d& extent_mm, double sigma_mm, double slice_sigma_mm) {
  return tissueHeldAcrossSlices(extent_mm) || slice_sigma_mm > kHeldAcrossBlurRatio * sigma_mm;
}

std::vector<CortexTissue> nearbyTissue(const std::vector<Eigen::Vector3d>& points,
                                       const std::vector<Eigen::Vector3d>& known_points,
                                       const std::vector<CortexTissue>& known) {
  constexpr size_t kNearest = 15;
  std::vector<CortexTissue> out(points.size());
  if (known.empty()) return out;
  const size_t k = std::min(kNearest, known.size());
  std::vector<std::pair<double, size_t>> by_distance(known.size());
  std::vector<double> values(k);
  const auto median = [&](const std::vector<size_t>& nearest, double CortexTissue::*field) {
    for (size_t i = 0; i < k; ++i) values[i] = known[nearest[i]].*field;
    std::nth_element(values.begin(), values.begin() + static_cast<long>(k / 2), values.end());
    return values[k / 2];
  };
  std::vector<size_t> nearest(k);
  for (size_t p = 0; p < points.size(); ++p) {
    for (size_t i = 0; i < known.size(); ++i) by_distance[i] = {(known_points[i] - points[p]).squaredNorm(), i};
    std::partial_sort(by_distance.begin(), by_distance.begin() + static_cast<long>(k), by_distance.end());
    for (size_t i = 0; i < k; ++i) nearest[i] = by_distance[i].second;
    out[p].thickness_mm = median(nearest, &CortexTissue::thickness_mm);
    out[p].outside_hu = median(nearest, &CortexTissue::outside_hu);
    out[p].cortex_hu = median(nearest, &CortexTissue::cortex_hu);
    out[p].inside_hu = median(nearest, &CortexTissue::inside_hu);
  }
  return out;
}

PointSpread estimatePointSpread(const std::vector<LineVoxels>& all_lines, int threads,
                                const std::vector<LineVoxels>& more_within_slices, double noise_hu) {
  PointSpread ps;
  ps.profiles = static_cast<int>(all_lines.size());
  if (all_lines.size() < static_cast<size_t>(kMinLines)) return ps;
  // The model's one step beyond a joint gap does not describe a socket,
  // even up to its rise: with lines that face one, the widths come out
  // narrow (0.38 mm for a true 0.5 mm where half the lines face a thin
  // socket 2 mm away, 0.40 where all do). They are left out where enough
  // others remain.
  std::vector<LineVoxels> lines;
  for (const LineVoxels& line : all_lines)
    if (!socketInWindow(line).found) lines.push_back(line);
  if (lines.size() < static_cast<size_t>(kMinLines)) lines = all_lines;
  const size_t sampled = lines.size();  // the rest tell the width within long slices only
  if (tissueHeldAcrossSlices(lines.front().extent_mm))
    for (const LineVoxels& line : more_within_slices)
      if (line.slice_share < kWithinSlicesShare && !socketInWindow(line).found) lines.push_back(line);
  // Summed over the same lines at every width; a line found at no width adds
  // its fit anyway (its residual still tells how well that width explains it).
  // Each line's noise is its own (its misfit too): n log(residual) per line.
  // (Each search starts afresh: started from the line's fit at the nearest
  // width tried, the searches ended where they came from, and the estimate
  // followed them, 0.75 mm for a flat thick cortex's 0.7.)
  const auto profileLogLikelihood = [&](size_t index, const PointSpread& spread, const CortexTissue* held) {
    constexpr double kLeastSumSquares = 1e-9;  // a noiseless line
    const LineVoxels& line = lines[index];
    return static_cast<double>(line.offset_mm.size()) *
           std::log(std::max(fitCortex(line, 0.0, StepResponse(line, spread), 0.0, held).sum_squares, kLeastSumSquares));
  };
  // Over `subset` (indices into lines), each held to `held[i]` when given.
  // Each search's grid, which only finds the basins, is summed over a few
  // hundred of the lines (thinned, leastBasin); the refinement that sets
  // the width, over every line. (Grids over every line took half of the
  // mesh stage; on 32 phantom heads the surfaces moved 0.003 mm, median.)
  const auto total = [&](const std::vector<size_t>& subset, PointSpread::Kind kind, double in_plane, double across,
                         const std::vector<CortexTissue>* held = nullptr) {
    PointSpread trial;
    trial.kind = kind;
    trial.sigma_mm = in_plane;
    trial.slice_sigma_mm = across;
    std::vector<double> each(subset.size());
    parallelFor(static_cast<std::ptrdiff_t>(subset.size()), 8, threads, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
      for (auto i = static_cast<size_t>(begin); i < static_cast<size_t>(end); ++i)
        each[i] = profileLogLikelihood(subset[i], trial, held ? &(*held)[i] : nullptr);
    });
    double sum = 0;
    for (const double e : each) sum += e;  // in order: the same sum for any thread count
    return sum;
  };
  // One width for both directions, for each kind; the kind whose best fits better is kept.
  struct Common {
    bool found = false;
    double width_mm = 0, negated_log_likelihood = std::numeric_limits<double>::infinity();
  };
  // One width for both directions near `near_mm`: a parabola over a few of
  // the lines within a tenth of a millimetre, then over every line within
  // five hundredths of its least (leastOfSmoothed).
  constexpr double kFineStep = 0.01;
  struct Refined {
    double coarse_mm, fine_mm, fine_value;
  };
  const auto refinedNear = [&](const std::vector<size_t>& subset, PointSpread::Kind kind, double near_mm) {
    const std::vector<size_t> few = thinned(subset);
    const double coarse =
        leastOfSmoothed([&](double s) { return total(few, kind, s, s); }, near_mm - 0.1, near_mm + 0.1, kFineStep * 2).first;
    const auto [fine, value] = leastOfSmoothed([&](double s) { return total(subset, kind, s, s); },
                                               coarse - 5 * kFineStep, coarse + 5 * kFineStep, kFineStep);
    return Refined{coarse, fine, value};
  };
  const auto commonWidth = [&](const std::vector<size_t>& subset, PointSpread::Kind kind, bool flat_at_edge = false) {
    constexpr double kStep = 0.1, kFirst = 0.05, kLast = 2.0;
    const std::vector<size_t> few = thinned(subset);
    const auto f = [&](double s) { return total(subset, kind, s, s); };
    const auto f_few = [&](double s) { return total(few, kind, s, s); };
    std::vector<double> grid_mm;
    for (double s = kFirst; s <= kLast + 1e-9; s += kStep) grid_mm.push_back(s);
    const size_t at = leastBasin(grid_mm, f, f_few);
    Common c;
    if (at == 0 || at + 1 == grid_mm.size()) return c;
    const Refined r = refinedNear(subset, kind, grid_mm[at]);
    const double width = r.coarse_mm;
    double fine = r.fine_mm, fine_value = r.fine_value;
    // `flat_at_edge`: the lines within long slices, whose likelihood can
    // run flat (over 46 lines within 2 mm slices, from 0.56 to 0.70 mm):
    // where the fine window's least is its edge, a jump between widths took
    // it (0.69 mm, 0.05 from the wider window's 0.64) and the wider
    // window's parabola stands. (Over every line an edge is the fine search
    // moving where the wider one erred: a thick cortex's 0.7 mm read 0.77.)
    if (flat_at_edge && std::abs(fine - width) > 5 * kFineStep - 1e-6) {
      fine = width;
      fine_value = f(width);
    }
    c.width_mm = fine;
    c.negated_log_likelihood = fine_value;
    c.found = true;
    return c;
  };
  // The kind whose one width fits `subset` better, and that width: `current`
  // unless the other kind fits better by more than `margin` (log-likelihood).
  struct KindFit {
    PointSpread::Kind kind;
    Common fit;
  };
  const auto chooseKind = [&](const std::vector<size_t>& subset, PointSpread::Kind current, double margin,
                              bool flat_at_edge) {
    const auto other_kind =
        current == PointSpread::Kind::VoxelGrid ? PointSpread::Kind::Scanner : PointSpread::Kind::VoxelGrid;
    const Common same = commonWidth(subset, current, flat_at_edge);
    const Common other = commonWidth(subset, other_kind, flat_at_edge);
    if (other.found && (!same.found || same.negated_log_likelihood - other.negated_log_likelihood > margin))
      return KindFit{other_kind, other};
    return KindFit{current, same};
  };
  // The voxels of `subset`'s lines: a likelihood's gain per extra parameter
  // must exceed the log of their count (the Bayesian information criterion).
  const auto voxelCount = [&](const std::vector<size_t>& subset) {
    double voxels = 0;
    for (const size_t i : subset) voxels += static_cast<double>(lines[i].offset_mm.size());
    return voxels;
  };
  std::vector<size_t> every(sampled), within, across;
  for (size_t i = 0; i < lines.size(); ++i) {
    if (i < sampled) every[i] = i;
    (lines[i].slice_share < kWithinSlicesShare ? within : across).push_back(i);
  }
  double across_share = 0;
  for (const size_t i : every) across_share += lines[i].slice_share;
  const bool too_few_across = across_share < kMinAcrossShare * static_cast<double>(sampled);

  const KindFit common_fit = chooseKind(every, PointSpread::Kind::Scanner, 0.0, false);
  if (!common_fit.fit.found) return ps;
  ps.kind = common_fit.kind;
  ps.sigma_mm = ps.slice_sigma_mm = common_fit.fit.width_mm;
  const double chosen_value = common_fit.fit.negated_log_likelihood;  // at the common width
  const double common = ps.sigma_mm;
  // Voxels longer across the slices than within them: a thin cortex's
  // thickness trades against the blur on the lines across the slices (its
  // fitted thickness ran from 0.14 to 1.5 mm for 0.8 at 1 x 1 x 3 mm), and
  // the likelihood of one width across them hardly tells one from another
  // (0.13 to 1.3 mm where the slices had none beyond their voxels). With the
  // tissue of their nearest lines within the slices held, the width across
  // them is told by how far their edges spread.
  const auto sliceWidthWithHeldTissue = [&](const PointSpread& spread, const std::vector<size_t>& in,
                                            const std::vector<size_t>& out) {
    if (in.size() < static_cast<size_t>(kMinLines) || out.size() < static_cast<size_t>(kMinLines))
      return spread.slice_sigma_mm;
    std::vector<Eigen::Vector3d> known_points, points;
    std::vector<CortexTissue> known;
    for (const size_t i : in) {
      const CortexFit fit = fitCortex(lines[i], 0.0, StepResponse(lines[i], spread));
      if (!fit.found) continue;
      known.push_back(fit);
      known_points.push_back(lines[i].point_mm);
    }
    if (known.size() < static_cast<size_t>(kMinLines)) return spread.slice_sigma_mm;
    for (const size_t i : out) points.push_back(lines[i].point_mm);
    const std::vector<CortexTissue> held = nearbyTissue(points, known_points, known);
    // With the tissue held, a width 0.05 mm off moves the surface little:
    // a coarse grid and one parabola about its best.
    const auto f = [&](double s) { return total(out, spread.kind, spread.sigma_mm, s, &held); };
    const std::vector<size_t> few = thinned(out);
    const std::vector<CortexTissue> few_held = thinned(held);
    const auto f_few = [&](double s) { return total(few, spread.kind, spread.sigma_mm, s, &few_held); };
    constexpr double kStep = 0.2, kFirst = 0.05, kLast = 2.85;
    std::vector<double> grid_mm;
    for (double s = kFirst; s <= kLast + 1e-9; s += kStep) grid_mm.push_back(s);
    const size_t at = leastBasin(grid_mm, f, f_few);
    if (at + 1 == grid_mm.size()) return spread.slice_sigma_mm;  // wider than any CT's slices blur
    return std::max(0.01, leastOfSmoothed(f, grid_mm[at] - kStep, grid_mm[at] + kStep, 0.04).first);
  };
  // Under noise each line's own cortex and socket fit part of it, and the
  // width leans: wide on lines oblique to the grid, where the socket's step,
  // a level at or above the gap's, takes up the noise on one side (0.635 mm
  // for a true 0.6 at 0.6 x 0.6 x 3 mm and 15 HU, the surface 0.07 mm
  // inside; noise-free 0.608), narrow on a thin cortex, whose thickness
  // trades against the width. A parametric bootstrap measures the lean: the
  // lines made again from their fits at the estimate (without a socket,
  // which these lines do not face) with the CT's noise added, once with
  // each sign so that what is linear in the noise cancels and its lean,
  // even in it, stays; the width is estimated on them near the estimate and
  // the lean taken off. Seeded: the same width for the same CT.
  const auto withoutNoiseLean = [&](const std::vector<size_t>& subset, double width, double slice_width) {
    if (!(noise_hu > 0)) return width;
    PointSpread at = ps;
    at.sigma_mm = width;
    at.slice_sigma_mm = slice_width;
    std::vector<CortexFit> fits(subset.size());
    parallelFor(static_cast<std::ptrdiff_t>(subset.size()), 8, threads, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
      for (auto k = static_cast<size_t>(begin); k < static_cast<size_t>(end); ++k)
        fits[k] = fitCortex(lines[subset[k]], 0.0, StepResponse(lines[subset[k]], at), 0.0);
    });
    std::mt19937 rng(kNoiseLeanSeed);
    std::normal_distribution<double> gauss(0.0, noise_hu);
    std::vector<std::vector<double>> noise(subset.size());
    for (size_t k = 0; k < subset.size(); ++k)
      for (size_t i = 0; i < lines[subset[k]].offset_mm.size(); ++i) noise[k].push_back(gauss(rng));
    // The remade lines join `lines` while their width is sought (`total`
    // reads lines by index), once for each sign.
    const size_t first = lines.size();
    std::vector<size_t> made(subset.size());
    double sum = 0;
    for (const double sign : {1.0, -1.0}) {
      for (size_t k = 0; k < subset.size(); ++k) {
        LineVoxels line = lines[subset[k]];
        const StepResponse blur(line, at);
        const CortexFit& f = fits[k];
        for (size_t i = 0; i < line.offset_mm.size(); ++i) {
          const double x = line.offset_mm[i];
          const double outer = blur.brightShare(f.offset_mm - x), inner = blur.brightShare(f.offset_mm - f.thickness_mm - x);
          line.value_hu[i] = f.outside_hu + (f.cortex_hu - f.outside_hu) * (outer - inner) +
                             (f.inside_hu - f.outside_hu) * inner + sign * noise[k][i];
        }
        lines.push_back(std::move(line));
        made[k] = lines.size() - 1;
      }
      sum += refinedNear(made, ps.kind, width).fine_mm;
      lines.resize(first);
    }
    return std::max(0.01, 2 * width - sum / 2);
  };
  // The slice width needs lines across the slices: where fewer than a tenth
  // of the lines' spread runs across them, it stays at the common one.
  if (too_few_across) {
    ps.sigma_mm = ps.slice_sigma_mm = withoutNoiseLean(every, ps.sigma_mm, ps.sigma_mm);
    ps.found = true;
    return ps;
  }

  // Across long slices the lines that cross them see the slice's profile,
  // which a generator or a scanner may take coarser or finer than the
  // model's box (synthetic CTs average 2-3 samples across a 3 mm slice):
  // fitted with every line, the width within the slices came out short
  // (0.457 mm for 0.5, 0.468 for 0.6 at 0.6 x 0.6 x 3 mm) and the surface
  // outside by up to 0.2 mm. The lines within the slices tell it alone.
  if (tissueHeldAcrossSlices(lines.front().extent_mm) && within.size() >= static_cast<size_t>(kMinLines)) {
    // Of those, the lines the model explains: a line whose residual at the
    // common width is well above most lines' sees what a blurred cortex is
    // not (a head-neck junction's crease, a socket's rim beyond the
    // window), and its likelihood swings with the width by tens of units
    // where a head's line's moves by one or two (at 0.6 x 0.6 x 1 mm the
    // tenth of the lines about the neck read 0.64 mm for a true 0.6, the
    // surface 0.07 mm inside).
    std::vector<double> rms(within.size());
    parallelFor(static_cast<std::ptrdiff_t>(within.size()), 8, threads, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
      for (auto k = static_cast<size_t>(begin); k < static_cast<size_t>(end); ++k) {
        const LineVoxels& line = lines[within[k]];
        rms[k] = std::sqrt(fitCortex(line, 0.0, StepResponse(line, ps), 0.0).sum_squares /
                           static_cast<double>(std::max<size_t>(1, line.offset_mm.size())));
      }
    });
    std::vector<double> sorted = rms;
    const auto middle = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2);
    std::nth_element(sorted.begin(), middle, sorted.end());
    std::vector<size_t> explained;
    for (size_t k = 0; k < within.size(); ++k)
      if (rms[k] <= kExplainedRmsRatio * *middle) explained.push_back(within[k]);
    if (explained.size() >= static_cast<size_t>(kMinLines)) within = explained;
    // And the kind: the common one was chosen with one width for both
    // directions, which misfits a blur twice as wide across the slices as
    // within them (0.4 and 0.8 mm on the grid at 0.8 x 0.8 x 1 mm was taken
    // for a scanner's 0.34 mm, the surface 0.08 mm inside). Within the
    // slices one width is the whole blur; the other kind replaces the
    // common one where it fits better by more than the log of the voxels'
    // count (at a width of about a voxel the two kinds hardly differ, and
    // noise alone tips the balance by a few units).
    const KindFit in_plane = chooseKind(within, ps.kind, std::log(voxelCount(within)), true);
    if (in_plane.fit.found) {
      ps.kind = in_plane.kind;
      ps.sigma_mm = in_plane.fit.width_mm;
    }
  } else {
    // The slice width, then the width within the slices, each searched over
    // [common / 2.5, common * 2.5] and refined; kept only when the two fit
    // better than the one by more than the log of the voxels' count (the
    // Bayesian information criterion for one width more), since a second
    // width also fits the noise (0.516 / 0.479 mm for a phantom's isotropic 0.5).
    const auto searched = [&](const auto& f, const auto& f_few) {
      constexpr int kSamples = 15;
      const double ratio = std::pow(kWidthRange * kWidthRange, 1.0 / (kSamples - 1));
      std::vector<double> grid_mm;
      for (double s = common / kWidthRange; s <= common * kWidthRange * 1.0001; s *= ratio) grid_mm.push_back(s);
      const double best = grid_mm[leastBasin(grid_mm, f, f_few)];
      return leastOfSmoothed(f, best - 0.05, best + 0.05, 0.01);
    };
    PointSpread split = ps;
    const std::vector<size_t> few = thinned(every);
    split.slice_sigma_mm = searched([&](double s) { return total(every, ps.kind, common, s); },
                                    [&](double s) { return total(few, ps.kind, common, s); })
                               .first;
    const auto [in_plane, split_value] =
        searched([&](double s) { return total(every, ps.kind, s, split.slice_sigma_mm); },
                 [&](double s) { return total(few, ps.kind, s, split.slice_sigma_mm); });
    split.sigma_mm = in_plane;
    if (chosen_value - split_value > std::log(voxelCount(every))) ps = split;
  }
  if (tissueHeldAcrossSlices(lines.front().extent_mm) && within.size() >= static_cast<size_t>(kMinLines))
    ps.sigma_mm = withoutNoiseLean(within, ps.sigma_mm, ps.slice_sigma_mm);
  else if (ps.sigma_mm == ps.slice_sigma_mm)
    ps.sigma_mm = ps.slice_sigma_mm = withoutNoiseLean(every, ps.sigma_mm, ps.sigma_mm);
  ps.found = true;
  ps.held_across = tissueHeldAcrossSlices(lines.front().extent_mm, ps.sigma_mm, ps.slice_sigma_mm);
  if (ps.held_across) ps.slice_sigma_mm = sliceWidthWithHeldTissue(ps, within, across);
  return ps;
}

}  // namespace articula::imaging
