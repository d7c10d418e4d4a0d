#include "articula/imaging/cortex_edge.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>
#include <nlopt.hpp>

#include "articula/core/parallel.hpp"

namespace articula::imaging {
namespace {

constexpr double kSearchMm = 1.0;        // the surface is sought this far either side of the guess
constexpr double kMinThicknessMm = 0.1, kMaxThicknessMm = 4.0;
constexpr double kMinGapMm = 0.8, kMaxGapMm = 4.0;  // the narrowest joint gaps are about 1.5 mm
constexpr int kMinLines = 30;
constexpr double kMinAcrossShare = 0.1;  // of the lines' summed slice share, for a slice width of its own
constexpr double kWidthRange = 2.5;      // each width within this factor of the common one
constexpr int kWidthRounds = 2;
constexpr double kSocketRiseHu = 150;  // a rise beyond the edge this high is a socket (the edges' least contrast)

double Phi(double z) { return 0.5 * std::erfc(-z * M_SQRT1_2); }

/// The HU levels of the model's steps and the residual they leave.
struct Levels {
  Eigen::Vector4d coef = Eigen::Vector4d::Zero();  // outside, cortex - outside, cancellous - outside, socket - outside
  double sum_squares = 0;
};

/// Least squares over the columns in `use` (the others held at zero).
Levels solveLevels(const std::vector<Eigen::Vector4d>& rows, const std::vector<double>& values,
                   const Eigen::Vector4d& use) {
  Eigen::Matrix4d normal = Eigen::Matrix4d::Zero();
  Eigen::Vector4d rhs = Eigen::Vector4d::Zero();
  for (size_t i = 0; i < rows.size(); ++i) {
    const Eigen::Vector4d r = rows[i].cwiseProduct(use);
    normal.selfadjointView<Eigen::Lower>().rankUpdate(r);
    rhs += r * values[i];
  }
  normal = normal.selfadjointView<Eigen::Lower>();
  // A tiny ridge: a level the window does not reach (a cortex thicker than
  // it) stays at the outside's instead of making the system singular.
  normal.diagonal().array() += 1e-6 * static_cast<double>(rows.size());
  Levels l;
  l.coef = normal.ldlt().solve(rhs).cwiseProduct(use);
  for (size_t i = 0; i < rows.size(); ++i) {
    const double r = rows[i].dot(l.coef) - values[i];
    l.sum_squares += r * r;
  }
  return l;
}

/// The blurred steps at surface e, cortex thickness t and gap g (to a socket
/// beyond the surface), with the HU levels that fit the voxels best:
/// f = outside + a (cortex layer) + b (cancellous) + c (socket), the levels
/// relative to the outside. The socket is brighter than the gap or absent:
/// a darker step there would reshape the surface's own fall and trade
/// against the blur.
Levels fitLevels(const LineVoxels& line, double e, double t, double g, double sigma) {
  const size_t n = line.offset_mm.size();
  std::vector<Eigen::Vector4d> rows(n);
  for (size_t i = 0; i < n; ++i) {
    const double s = line.offset_mm[i];
    const double k0 = Phi((e - s) / sigma), k1 = Phi((e - t - s) / sigma), k2 = Phi((s - e - g) / sigma);
    rows[i] = Eigen::Vector4d(1.0, k0 - k1, k1, k2);
  }
  Levels l = solveLevels(rows, line.value_hu, Eigen::Vector4d::Ones());
  if (l.coef[3] < 0) l = solveLevels(rows, line.value_hu, Eigen::Vector4d(1, 1, 1, 0));
  return l;
}

/// The residual at (surface, thickness, gap), and the best point met: NLopt
/// may end its search with an exception (roundoff limits its progress on a
/// flat residual) after it has found a good point, and that point is kept.
struct Objective {
  const LineVoxels* line = nullptr;
  double sigma = 0;
  double best = std::numeric_limits<double>::infinity();
  std::array<double, 3> best_point{};
};

double sumSquares(unsigned, const double* p, double*, void* data) {
  auto* o = static_cast<Objective*>(data);
  const double value = fitLevels(*o->line, p[0], p[1], p[2], o->sigma).sum_squares;
  if (value < o->best) {
    o->best = value;
    o->best_point = {p[0], p[1], p[2]};
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
  LineVoxels near;
  near.box_variance_mm2 = line.box_variance_mm2;
  near.slice_share = line.slice_share;
  for (size_t i = 0; i < line.offset_mm.size(); ++i)
    if (line.offset_mm[i] <= outward_mm) {
      near.offset_mm.push_back(line.offset_mm[i]);
      near.value_hu.push_back(line.value_hu[i]);
    }
  return near;
}

/// The least of a function unimodal on [a, b], to 0.004 mm: one bracketed
/// variable, a few hundred fits an evaluation; written out here (a dozen
/// lines) rather than set up as another NLopt problem.
template <class F>
double goldenMinimum(F f, double a, double b) {
  constexpr double kInvPhi = 0.6180339887498949, kTolerance = 0.004;
  double c = b - kInvPhi * (b - a), d = a + kInvPhi * (b - a);
  double fc = f(c), fd = f(d);
  while (b - a > kTolerance) {
    if (fc < fd) {
      b = d, d = c, fd = fc;
      c = b - kInvPhi * (b - a), fc = f(c);
    } else {
      a = c, c = d, fc = fd;
      d = a + kInvPhi * (b - a), fd = f(d);
    }
  }
  return 0.5 * (a + b);
}

}  // namespace

double lineRadiusFor(const ImageGeometry& geometry) {
  constexpr double kVoxels = 50;
  const double voxel_volume = geometry.spacing.prod();
  return std::max(0.8, std::sqrt(kVoxels * voxel_volume / (M_PI * (kCortexInwardMm + kCortexOutwardMm))));
}

LineVoxels voxelsAboutLine(const Volume& volume, const Eigen::Vector3d& x, const Eigen::Vector3d& u, double from_mm,
                           double to_mm, double radius_mm, double curvature_per_mm) {
  const ImageGeometry& g = volume.geometry;
  LineVoxels line;
  for (int a = 0; a < 3; ++a) {
    const double along = g.spacing[a] * g.direction.col(a).dot(u);
    line.box_variance_mm2 += along * along / 12.0;
  }
  const double across_slices = g.direction.col(2).dot(u);
  line.slice_share = across_slices * across_slices;
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
        line.offset_mm.push_back(s + 0.5 * curvature_per_mm * lateral2);
        line.value_hu.push_back(volume.at(i, j, k));
      }
  return line;
}

CortexFit fitCortex(const LineVoxels& whole_line, double guess_mm, double sigma_mm, double min_contrast_hu) {
  CortexFit fit;
  // The model's socket is one step up: a socket whose own cortex is thin
  // falls again within the window, and fitted over that fall the surface
  // moves out (0.13-0.16 mm for a 0.8 mm cortex 1.5-2 mm away under 0.5 mm
  // of blur). The window ends in the socket's rise instead.
  const SocketInWindow socket = socketInWindow(whole_line);
  const LineVoxels near = socket.found ? upTo(whole_line, socket.window_end_mm) : LineVoxels{};
  const LineVoxels& line = socket.found ? near : whole_line;  // no copy of a line without a socket
  if (line.offset_mm.size() < 12 || !(sigma_mm > 0)) return fit;
  Objective objective;
  objective.line = &line;
  objective.sigma = std::sqrt(sigma_mm * sigma_mm + line.box_variance_mm2);
  // BOBYQA: three bounded parameters, a cheap smooth objective without
  // derivatives (the levels are solved inside it, variable projection).
  nlopt::opt opt(nlopt::LN_BOBYQA, 3);
  opt.set_lower_bounds({guess_mm - kSearchMm, kMinThicknessMm, kMinGapMm});
  opt.set_upper_bounds({guess_mm + kSearchMm, kMaxThicknessMm, kMaxGapMm});
  opt.set_min_objective(sumSquares, &objective);
  opt.set_xtol_abs(1e-3);
  opt.set_maxeval(300);
  std::vector<double> p = {guess_mm, 1.0, 2.0};
  double best = 0;
  try {
    opt.optimize(p, best);
  } catch (const std::exception&) {
    // Only the search's end is lost: its best point stands.
  }
  if (!std::isfinite(objective.best)) return fit;  // not one finite residual was evaluated
  p.assign(objective.best_point.begin(), objective.best_point.end());
  const Levels l = fitLevels(line, p[0], p[1], p[2], objective.sigma);
  fit.offset_mm = p[0];
  fit.thickness_mm = p[1];
  fit.outside_hu = l.coef[0];
  fit.cortex_hu = l.coef[0] + l.coef[1];
  fit.inside_hu = l.coef[0] + l.coef[2];
  fit.sum_squares = l.sum_squares;
  const bool bright_bone = std::max(l.coef[1], l.coef[2]) >= min_contrast_hu;
  const bool inside_search = std::abs(p[0] - guess_mm) < 0.98 * kSearchMm;
  fit.found = bright_bone && inside_search && std::isfinite(l.sum_squares);
  return fit;
}

PointSpread estimatePointSpread(const std::vector<LineVoxels>& all_lines) {
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
  // Summed over the same lines at every width; a line found at no width adds
  // its fit anyway (its residual still tells how well that width explains it).
  // Each line's noise is its own (its misfit too): n log(residual) per line.
  const auto profileLogLikelihood = [](const LineVoxels& line, double sigma) {
    constexpr double kLeastSumSquares = 1e-9;  // a noiseless line
    return static_cast<double>(line.offset_mm.size()) *
           std::log(std::max(fitCortex(line, 0.0, sigma, 0.0).sum_squares, kLeastSumSquares));
  };
  const auto total = [&](double in_plane, double across) {
    PointSpread trial;
    trial.sigma_mm = in_plane;
    trial.slice_sigma_mm = across;
    std::vector<double> each(lines.size());
    parallelFor(static_cast<std::ptrdiff_t>(lines.size()), 8, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
      for (auto i = static_cast<size_t>(begin); i < static_cast<size_t>(end); ++i)
        each[i] = profileLogLikelihood(lines[i], trial.along(lines[i]));
    });
    double sum = 0;
    for (const double e : each) sum += e;  // in order: the same sum for any thread count
    return sum;
  };
  constexpr double kStep = 0.1, kFirst = 0.05, kLast = 2.0;
  std::vector<double> grid_mm, negated_log_likelihood;
  for (double s = kFirst; s <= kLast + 1e-9; s += kStep) {
    grid_mm.push_back(s);
    negated_log_likelihood.push_back(total(s, s));
  }
  const auto at = std::min_element(negated_log_likelihood.begin(), negated_log_likelihood.end()) -
                  negated_log_likelihood.begin();
  if (at == 0 || at + 1 == static_cast<long>(grid_mm.size())) return ps;
  const double common = goldenMinimum([&](double s) { return total(s, s); }, grid_mm[static_cast<size_t>(at) - 1],
                                      grid_mm[static_cast<size_t>(at) + 1]);
  ps.sigma_mm = ps.slice_sigma_mm = common;
  // Then the two widths in turn, each within a factor of 2.5 of the common
  // one. The slice width needs lines across the slices: where fewer than a
  // tenth of the lines' spread runs across them, it stays at the common one.
  double across_share = 0;
  for (const LineVoxels& line : lines) across_share += line.slice_share;
  if (across_share < kMinAcrossShare * static_cast<double>(lines.size())) {
    ps.found = true;
    return ps;
  }
  for (int round = 0; round < kWidthRounds; ++round) {
    ps.slice_sigma_mm = goldenMinimum([&](double s) { return total(ps.sigma_mm, s); }, common / kWidthRange,
                                      common * kWidthRange);
    ps.sigma_mm = goldenMinimum([&](double s) { return total(s, ps.slice_sigma_mm); }, common / kWidthRange,
                                common * kWidthRange);
  }
  ps.found = true;
  return ps;
}

}  // namespace articula::imaging
