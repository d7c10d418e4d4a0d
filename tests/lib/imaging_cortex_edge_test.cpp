// The blurred-cortex model: on a flat cortex of known thickness, blurred by a
// known Gaussian and averaged over each voxel (closed form), or averaged over
// each voxel and then blurred on the voxel grid (as an image filter does),
// with CT noise, the point-spread and how it was applied are estimated from
// the CT alone and the model puts the surface where it is, also where the
// cortex is thin enough for the steepest fall to lie a fifth of a
// millimetre outside.
#include <algorithm>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "articula/imaging/cortex_edge.hpp"
#include "articula/imaging/edges.hpp"

namespace articula {
namespace {

double Phi(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }

/// A flat cortex whose outer surface is the plane n . x = surface (the bone
/// on its negative side), tilted against the grid so that the lines across
/// it meet the voxels at every phase.
struct FlatCortex {
  double soft = 40, cortical = 700, cancellous = 190, thickness = 0.8, sigma = 0.5, spacing = 0.7, noise = 20;
  double slice_spacing = 0;    // along the grid's third axis (0: `spacing`)
  double slice_sigma = 0;      // a blur on the grid across the slices (0: `sigma`)
  double slice_thickness = 0;  // what a voxel averages over across the slices (0: their spacing)
  bool thickness_stated = true;  // the volume's geometry says so (a DICOM series' Slice Thickness)
  int slice_samples = 0;       // a voxel's samples across the slice (0: as finely as within it)
  double surface = 0.23;
  Eigen::Vector3d n = Eigen::Vector3d(1, 0.21, -0.13).normalized();
  Eigen::Vector3i size = Eigen::Vector3i(24, 40, 40);  // voxels (the grid centred on the origin)
  // Two directions spanning the places where lines cross it (projected onto it).
  Eigen::Vector3d across1 = Eigen::Vector3d::UnitY(), across2 = Eigen::Vector3d::UnitZ();

  // A socket beyond a joint gap: its cortex and cancellous bone (none when the gap is 0).
  double gap = 0, socket_thickness = 0.8, socket_cortical = 700, socket_cancellous = 190;
  // The blur applied to the voxels along each grid axis, its Gaussian's
  // weights sampled at whole voxels (an image filter), instead of to the
  // object before its voxels are taken (a scanner).
  bool blur_on_grid = false;

  /// The profile at signed distance d beyond the surface, blurred by the
  /// scanner (closed form) or not yet (blurred on the grid later).
  double blurred(double d) const {
    if (blur_on_grid) {
      double hu = d > 0 ? soft : d > -thickness ? cortical : cancellous;
      if (gap > 0 && d > gap) hu = d < gap + socket_thickness ? socket_cortical : socket_cancellous;
      return hu;
    }
    double hu = soft + (cortical - soft) * Phi(-d / sigma) - (cortical - cancellous) * Phi(-(d + thickness) / sigma);
    if (gap > 0)
      hu += (socket_cortical - soft) * Phi((d - gap) / sigma) -
            (socket_cortical - socket_cancellous) * Phi((d - gap - socket_thickness) / sigma);
    return hu;
  }
  Eigen::Vector3d spacings() const {
    return Eigen::Vector3d(spacing, spacing, slice_spacing > 0 ? slice_spacing : spacing);
  }
  /// Faces `normal`, the lines crossing it at places spread over the plane.
  void face(const Eigen::Vector3d& normal) {
    n = normal.normalized();
    across1 = n.unitOrthogonal();
    across2 = n.cross(across1);
  }
  /// The cortex and levels it is made of.
  imaging::CortexTissue tissue() const {
    imaging::CortexTissue t;
    t.thickness_mm = thickness;
    t.outside_hu = soft;
    t.cortex_hu = cortical;
    t.inside_hu = cancellous;
    return t;
  }
  Eigen::Vector3d extents() const {
    return Eigen::Vector3d(spacing, spacing, slice_thickness > 0 ? slice_thickness : spacings().z());
  }
  /// A voxel: the blurred profile averaged over 5 x 5 x 5 points of it
  /// (partial volume; 5 x 5 x 15 across long slices, or `slice_samples`).
  double voxel(const Eigen::Vector3d& centre) const {
    const int sub = 5, sub_z = slice_samples > 0 ? slice_samples : extents().z() > 2 * spacing ? 15 : 5;
    double sum = 0;
    for (int c = 0; c < sub * sub * sub_z; ++c) {
      const Eigen::Vector3d offset((c % sub + 0.5) / sub - 0.5, (c / sub % sub + 0.5) / sub - 0.5,
                                   (c / (sub * sub) + 0.5) / sub_z - 0.5);
      sum += blurred(n.dot(centre + extents().cwiseProduct(offset)) - surface);
    }
    return sum / (sub * sub * sub_z);
  }
  imaging::Volume volume(unsigned seed) const {
    imaging::Volume v;
    v.geometry.size = size;
    v.geometry.spacing = spacings();
    if (thickness_stated) v.geometry.slice_thickness_mm = slice_thickness;
    v.geometry.origin = -0.5 * spacings().cwiseProduct(size.cast<double>() - Eigen::Vector3d::Ones());
    v.voxels.resize(static_cast<size_t>(v.geometry.voxelCount()));
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise_hu(0.0, noise);
    for (int k = 0; k < size.z(); ++k)
      for (int j = 0; j < size.y(); ++j)
        for (int i = 0; i < size.x(); ++i)
          v.at(i, j, k) = static_cast<float>(voxel(v.geometry.toPhysical(Eigen::Vector3d(i, j, k))));
    if (blur_on_grid) blurOnGrid(v);
    for (float& hu : v.voxels) hu += static_cast<float>(noise_hu(rng));
    return v;
  }
  /// The Gaussian's weights sampled at whole voxels to four widths (as
  /// image filters take it), applied along each axis, the edges clamped.
  void blurOnGrid(imaging::Volume& v) const {
    for (int axis = 0; axis < 3; ++axis) {
      const double width = (axis == 2 && slice_sigma > 0 ? slice_sigma : sigma) / spacings()[axis];
      const int reach = static_cast<int>(std::ceil(4 * width));
      std::vector<double> w;
      double sum = 0;
      for (int t = -reach; t <= reach; ++t) sum += w.emplace_back(std::exp(-0.5 * t * t / (width * width)));
      for (double& x : w) x /= sum;
      const imaging::Volume in = v;
      for (int k = 0; k < size.z(); ++k)
        for (int j = 0; j < size.y(); ++j)
          for (int i = 0; i < size.x(); ++i) {
            double hu = 0;
            for (int t = -reach; t <= reach; ++t) {
              Eigen::Vector3i at(i, j, k);
              at[axis] = std::clamp(at[axis] + t, 0, size[axis] - 1);
              hu += w[static_cast<size_t>(t + reach)] * in.at(at.x(), at.y(), at.z());
            }
            v.at(i, j, k) = static_cast<float>(hu);
          }
    }
  }
};

/// Lines across the plane at many places, each started on the steepest
/// fall as the mesh stage starts them (`starts`: that fall's offset), with
/// the mesh stage's window and radius for the line's direction (and the
/// CT's noise, `noise_hu`).
std::vector<imaging::LineVoxels> linesAcross(const FlatCortex& c, unsigned seed, std::vector<double>& starts,
                                             double noise_hu = 0) {
  const imaging::Volume v = c.volume(seed);
  const Eigen::Vector3d u = c.n;
  std::vector<imaging::LineVoxels> lines;
  for (double a = -8; a <= 8; a += 1.0)
    for (double b = -8; b <= 8; b += 1.0) {
      const Eigen::Vector3d p = (a + 0.13) * c.across1 + (b - 0.29) * c.across2;
      const Eigen::Vector3d x0 = p - (u.dot(p) - c.surface) * u;  // on the surface
      const imaging::Edge edge = imaging::locateEdge(v, x0, u, {});
      if (!edge.found) continue;
      starts.push_back(edge.offset_mm);
      const Eigen::Vector3d axis_extent = v.geometry.voxelExtent().cwiseProduct(u);
      const double further_in = imaging::cortexSearchMm(axis_extent) - imaging::cortexSearchMm(Eigen::Vector3d::Zero());
      lines.push_back(imaging::voxelsAboutLine(v, x0 + edge.offset_mm * u, u, -imaging::kCortexInwardMm - further_in,
                                               imaging::kCortexOutwardMm, imaging::lineRadiusFor(v.geometry, u, noise_hu)));
    }
  return lines;
}

/// The mean surface of `lines` by the model with `spread` (their starts added).
double meanModelSurface(const std::vector<imaging::LineVoxels>& lines, const std::vector<double>& starts,
                        const imaging::PointSpread& spread, int& found) {
  double sum = 0;
  found = 0;
  for (size_t i = 0; i < lines.size(); ++i) {
    const imaging::CortexFit f = imaging::fitCortex(lines[i], 0.0, imaging::StepResponse(lines[i], spread));
    if (!f.found) continue;
    sum += starts[i] + f.offset_mm;
    ++found;
  }
  return sum / std::max(found, 1);
}

struct Estimate {
  imaging::PointSpread spread;
  double mean_steepest = 0, mean_model = 0;
  int found = 0;
};

/// The point-spread estimated over lines across the plane; each line's
/// surface by the model with it.
Estimate measure(const FlatCortex& c, unsigned seed, double noise_hu = 0) {
  std::vector<double> starts;
  const std::vector<imaging::LineVoxels> lines = linesAcross(c, seed, starts, noise_hu);
  Estimate e;
  e.spread = imaging::estimatePointSpread(lines);
  for (const double start : starts) e.mean_steepest += start / static_cast<double>(starts.size());
  e.mean_model = meanModelSurface(lines, starts, e.spread, e.found);
  return e;
}

TEST(CortexEdge, PointSpreadAndSurfaceOfAThinCortexFromTheCtAlone) {
  FlatCortex thin;
  const Estimate e = measure(thin, 7);
  ASSERT_TRUE(e.spread.found);
  EXPECT_EQ(e.spread.kind, imaging::PointSpread::Kind::Scanner);
  EXPECT_NEAR(e.spread.sigma_mm, thin.sigma, 0.03);
  EXPECT_GT(e.found, 250);
  EXPECT_GT(e.mean_steepest - 0.0, 0.12);  // the steepest fall's outward pull ...
  EXPECT_NEAR(e.mean_model, 0.0, 0.05);    // ... which the model does not have
}

// Under low-dose noise (100 HU voxel to voxel) the fit of a line of a quiet
// CT's voxels reads the thin cortex thicker and the point-spread narrower,
// and puts the surface outside the bone; lines widened for the CT's noise
// (lineRadiusFor's noise_hu) hold as many more voxels as the noise's
// variance is larger, and read both as on a quiet CT.
TEST(CortexEdge, LinesWidenedForLowDoseNoise) {
  FlatCortex noisy;
  noisy.noise = 100;
  const Estimate quiet = measure(noisy, 7);
  const Estimate widened = measure(noisy, 7, noisy.noise);
  ASSERT_TRUE(quiet.spread.found && widened.spread.found);
  EXPECT_GT(quiet.mean_model, 0.1);  // 0.19 mm outside, the point-spread 0.46 mm
  EXPECT_NEAR(widened.spread.sigma_mm, noisy.sigma, 0.05);
  EXPECT_NEAR(widened.mean_model, 0.0, 0.05);
  EXPECT_GT(widened.found, 250);
}

// The same cortex blurred on the voxel grid at 0.8 mm voxels: the grid's
// three weights (0.18, 0.64, 0.18) are not the Gaussian the scanner's model
// has, which puts this surface 0.19 mm inside at the true width. The CT's
// profiles choose the grid's blur, and the surface is where it is.
TEST(CortexEdge, ABlurAppliedOnTheVoxelGrid) {
  FlatCortex filtered;
  filtered.blur_on_grid = true;
  filtered.spacing = 0.8;
  filtered.size = Eigen::Vector3i(22, 36, 36);
  std::vector<double> starts;
  const std::vector<imaging::LineVoxels> lines = linesAcross(filtered, 12, starts);
  const imaging::PointSpread spread = imaging::estimatePointSpread(lines);
  ASSERT_TRUE(spread.found);
  EXPECT_EQ(spread.kind, imaging::PointSpread::Kind::VoxelGrid);
  EXPECT_NEAR(spread.sigma_mm, filtered.sigma, 0.03);
  int found = 0;
  EXPECT_NEAR(meanModelSurface(lines, starts, spread, found), 0.0, 0.05);
  EXPECT_GT(found, 250);
  // Had the blur been taken for the scanner's at the true width:
  imaging::PointSpread scanner;
  scanner.sigma_mm = scanner.slice_sigma_mm = filtered.sigma;
  EXPECT_LT(meanModelSurface(lines, starts, scanner, found), -0.08);
}

// Under noise each line's own cortex and socket step fit part of it, and on
// lines oblique to the grid the width comes out wide (here 0.625 mm for a
// true 0.6 at 22.5 degrees with 15 HU, the surface 0.046 mm inside). With
// the CT's noise given, the lean is measured on lines made again from their
// fits with that noise and taken off (0.600 mm).
TEST(CortexEdge, WidthsLeanUnderNoiseTakenOff) {
  FlatCortex oblique;
  oblique.blur_on_grid = true;
  oblique.spacing = 0.6;
  oblique.sigma = 0.6;
  oblique.thickness = 1.2;
  oblique.cortical = 1100;
  oblique.cancellous = 280;
  oblique.noise = 15;
  oblique.size = Eigen::Vector3i(30, 30, 40);
  oblique.face(Eigen::Vector3d(std::cos(M_PI / 8), std::sin(M_PI / 8), 0));
  std::vector<double> starts;
  const std::vector<imaging::LineVoxels> lines = linesAcross(oblique, 3, starts);
  const imaging::PointSpread spread = imaging::estimatePointSpread(lines, 1, {}, oblique.noise);
  ASSERT_TRUE(spread.found);
  EXPECT_EQ(spread.kind, imaging::PointSpread::Kind::VoxelGrid);
  EXPECT_NEAR(spread.sigma_mm, oblique.sigma, 0.02);
  int found = 0;
  EXPECT_NEAR(meanModelSurface(lines, starts, spread, found), 0.0, 0.03);
  EXPECT_GT(found, 250);
}

TEST(CortexEdge, ThickCortexAndCoarseVoxels) {
  FlatCortex thick;
  thick.cortical = 1300;
  thick.cancellous = 350;
  thick.thickness = 2.0;
  thick.spacing = 1.0;
  thick.sigma = 0.7;
  const Estimate e = measure(thick, 8);
  ASSERT_TRUE(e.spread.found);
  EXPECT_NEAR(e.spread.sigma_mm, thick.sigma, 0.05);
  EXPECT_NEAR(e.mean_model, 0.0, 0.05);
}

// A socket 2 mm beyond a thin cortex, its own cortex as thin, faces half
// the lines (as a congruent socket faces a femoral head's articular part).
// The model's one step beyond the gap does not describe a socket that falls
// again to its cancellous bone: the lines that face it would pull the
// point-spread narrow (0.38 mm for the true 0.5 mm), and fitted over that
// fall their surfaces lie 0.13 mm out. The estimate leaves them out, and
// their fits end within the socket's rise.
TEST(CortexEdge, PointSpreadBesideASocket) {
  FlatCortex open, facing;
  facing.gap = 2.0;
  std::vector<double> starts, facing_starts;
  std::vector<imaging::LineVoxels> lines = linesAcross(open, 9, starts);
  const std::vector<imaging::LineVoxels> more = linesAcross(facing, 10, facing_starts);
  const std::vector<imaging::LineVoxels> own = lines;
  lines.insert(lines.end(), more.begin(), more.end());
  const imaging::PointSpread spread = imaging::estimatePointSpread(lines);
  ASSERT_TRUE(spread.found);
  EXPECT_NEAR(spread.sigma_mm, open.sigma, 0.03);
  int found = 0;
  // Within 0.07 mm: the width's 0.03 mm alone moves a cortex this thin by 0.06 mm.
  EXPECT_NEAR(meanModelSurface(own, starts, spread, found), 0.0, 0.07);
  EXPECT_GT(found, 250);
  EXPECT_NEAR(meanModelSurface(more, facing_starts, spread, found), 0.0, 0.07);
  EXPECT_GT(found, 250);
}

// A CT's slices blur more across than within them: three planes facing
// within the slices, across them and in between, each blurred by the
// Gaussian's spread along its normal (0.4 mm within, 0.8 mm across). Both
// widths come from the lines together, and each plane's surface is found.
TEST(CortexEdge, WiderPointSpreadAcrossTheSlices) {
  constexpr double kWithin = 0.4, kAcross = 0.8;
  std::vector<FlatCortex> planes(3);
  planes[0].n = Eigen::Vector3d(1, 0.21, -0.13).normalized();
  planes[1].n = Eigen::Vector3d(0.13, -0.2, 1).normalized();
  planes[2].n = Eigen::Vector3d(0.7, 0.1, 0.7).normalized();
  std::vector<imaging::LineVoxels> lines;
  std::vector<double> starts;
  std::vector<size_t> first;
  unsigned seed = 11;
  for (FlatCortex& plane : planes) {
    const double across = plane.n.z() * plane.n.z();
    plane.sigma = std::sqrt(kWithin * kWithin * (1 - across) + kAcross * kAcross * across);
    plane.thickness = 1.2;
    plane.spacing = 0.6;
    plane.size = Eigen::Vector3i::Constant(40);
    plane.across1 = plane.n.unitOrthogonal();
    plane.across2 = plane.n.cross(plane.across1);
    first.push_back(lines.size());
    const auto more = linesAcross(plane, seed++, starts);
    lines.insert(lines.end(), more.begin(), more.end());
  }
  first.push_back(lines.size());
  const imaging::PointSpread spread = imaging::estimatePointSpread(lines);
  ASSERT_TRUE(spread.found);
  EXPECT_NEAR(spread.sigma_mm, kWithin, 0.05);
  EXPECT_NEAR(spread.slice_sigma_mm, kAcross, 0.08);
  for (size_t p = 0; p < planes.size(); ++p) {
    const std::vector<imaging::LineVoxels> own(lines.begin() + static_cast<long>(first[p]),
                                               lines.begin() + static_cast<long>(first[p + 1]));
    const std::vector<double> own_starts(starts.begin() + static_cast<long>(first[p]),
                                         starts.begin() + static_cast<long>(first[p + 1]));
    int found = 0;
    EXPECT_NEAR(meanModelSurface(own, own_starts, spread, found), 0.0, 0.06) << "plane " << p;
    EXPECT_GT(found, 200) << "plane " << p;
  }
}

// A line from a CT phantom that runs through cortical bone for most of its
// window (a surface met at a slant, falling only near the window's outer
// end), on which NLopt's search ends at some widths (0.45 and 0.5 mm) with a
// roundoff error. The fit keeps the best point it met, so its
// residual, the least over the model's surfaces, changes smoothly with the
// width; a search's end counted as a perfect fit would weigh as thousands of
// well-fitted lines in the point-spread's likelihood.
TEST(CortexEdge, ResidualIsTheBestMetWhereTheSearchEndsEarly) {
  const std::vector<std::pair<double, double>> voxels = {
      {2.37422, 95}, {2.38604, 119}, {2.12490, 213}, {2.09880, 300}, {2.11084, 515}, {1.85499, 882},
      {1.86727, 944}, {1.38295, 388}, {1.39567, 648}, {1.14517, 785}, {1.11998, 923}, {1.13293, 1014},
      {0.88863, 1083}, {0.90181, 1098}, {0.39660, 920}, {0.41023, 1037}, {0.17036, 1055}, {0.14608, 1083},
      {0.15994, 1116}, {-0.07282, 1105}, {-0.05872, 1078}, {-0.31516, 927}, {-0.30085, 1068}, {-0.56123, 1078},
      {-0.58483, 1119}, {-0.57029, 1104}, {-0.82289, 1091}, {-0.80812, 1089}, {-1.30411, 1099}, {-1.28890, 1078},
      {-1.53864, 1093}, {-1.56133, 1095}, {-1.54589, 1111}, {-1.78694, 1101}, {-1.77126, 1079}, {-2.01177, 1087},
      {-1.99588, 1101}, {-2.26613, 1112}, {-2.28815, 1112}, {-2.27203, 1109}, {-2.51112, 1132}, {-2.53291, 1116},
      {-2.51656, 1060}, {-3.00333, 1073}, {-2.98654, 1073}, {-3.24614, 1092}, {-3.26726, 1118}, {-3.25023, 1037}};
  imaging::LineVoxels line;
  line.box_variance_mm2 = 0.049332;
  line.slice_share = 0.828526;
  for (const auto& [offset, hu] : voxels) {
    line.offset_mm.push_back(offset);
    line.value_hu.push_back(hu);
  }
  double previous = 0;
  for (double sigma = 0.30; sigma <= 0.601; sigma += 0.05) {
    const double residual = imaging::fitCortex(line, 0.0, sigma).sum_squares;
    EXPECT_GT(residual, 1e5) << "sigma " << sigma;  // about 65 HU rms over its voxels
    if (previous > 0) {
      EXPECT_NEAR(residual / previous, 1.0, 0.2) << "sigma " << sigma;
    }
    previous = residual;
  }
}

// Across 3 mm slices (0.8 mm within them) a thin cortex's thickness trades
// against the blur along the line, three voxels' worth of the slice's
// extent: fitted freely, at the true point-spread, the lines take an 0.8 mm
// cortex for 2-3 mm and leave the surface 0.7 mm out, on the steepest fall.
// Held to the cortex that lines within the slices show
// (imaging::CortexTissue), each line's surface is where it is.
TEST(CortexEdge, ThinCortexAcrossLongSlicesHeldToItsTissue) {
  FlatCortex across;
  across.spacing = 0.8;
  across.slice_spacing = 3.0;
  across.face(Eigen::Vector3d(0.3, 0.1, 1));  // a slice share of 0.91
  across.size = Eigen::Vector3i(44, 44, 12);
  std::vector<double> starts;
  const std::vector<imaging::LineVoxels> lines = linesAcross(across, 21, starts);
  ASSERT_GT(lines.size(), 100U);
  imaging::PointSpread spread;
  spread.sigma_mm = spread.slice_sigma_mm = across.sigma;
  const imaging::CortexTissue tissue = across.tissue();
  double free_sum = 0, held_sum = 0, steepest = 0;
  int free_found = 0, held_found = 0;
  std::vector<double> thickness;
  for (size_t i = 0; i < lines.size(); ++i) {
    const imaging::StepResponse response(lines[i], spread);
    const imaging::CortexFit free = imaging::fitCortex(lines[i], 0.0, response);
    const imaging::CortexFit held = imaging::fitCortex(lines[i], 0.0, response, 150, &tissue);
    steepest += starts[i] / static_cast<double>(lines.size());
    if (free.found) free_sum += starts[i] + free.offset_mm, ++free_found, thickness.push_back(free.thickness_mm);
    if (held.found) held_sum += starts[i] + held.offset_mm, ++held_found;
    EXPECT_EQ(held.thickness_mm, across.thickness);
  }
  EXPECT_GT(steepest, 0.5) << "the steepest fall's outward pull across the slices";
  ASSERT_GT(free_found, 100);
  std::sort(thickness.begin(), thickness.end());
  EXPECT_GT(thickness[thickness.size() / 2], 1.5) << "the free fits' median thickness";
  EXPECT_GT(free_sum / free_found, 0.5) << "fitted freely";
  ASSERT_GT(held_found, 100);
  EXPECT_NEAR(held_sum / held_found, 0.0, 0.05) << "held to the cortex's tissue";
}

// Synthetic CTs take a voxel's partial volume from a few samples across
// its slice (two here, 1.5 mm apart in a 3 mm slice) and blur on the grid,
// hardly at all across slices this long: the lines across the slices see a
// profile unlike the model's box. Three planes, the first facing within the
// slices, the others across them; each plane's lines and their starts.
constexpr double kLongSlicesSigma = 0.6;
std::vector<std::vector<imaging::LineVoxels>> linesOfPlanesInLongSlices(std::vector<std::vector<double>>& starts) {
  const Eigen::Vector3d normals[] = {Eigen::Vector3d(1, 0.21, 0.02), Eigen::Vector3d(0.8, -0.2, 0.3),
                                     Eigen::Vector3d(0.6, 0.3, 0.6)};
  std::vector<std::vector<imaging::LineVoxels>> lines;
  starts.clear();
  unsigned seed = 31;
  for (const Eigen::Vector3d& n : normals) {
    FlatCortex plane;
    plane.n = n.normalized();
    plane.spacing = 0.6;
    plane.sigma = kLongSlicesSigma;
    plane.slice_spacing = 3.0;
    plane.slice_samples = 2;
    plane.blur_on_grid = true;
    plane.size = Eigen::Vector3i(44, 44, 12);
    plane.across1 = plane.n.unitOrthogonal();
    plane.across2 = plane.n.cross(plane.across1);
    starts.emplace_back();
    lines.push_back(linesAcross(plane, seed++, starts.back()));
  }
  return lines;
}

// Fitted with every line, the width within the slices came out short and
// the surface facing within them outside; the lines within the slices tell it.
TEST(CortexEdge, WidthWithinLongSlicesFromTheLinesWithinThem) {
  std::vector<std::vector<double>> starts;
  const auto planes = linesOfPlanesInLongSlices(starts);
  std::vector<imaging::LineVoxels> lines;
  for (const auto& own : planes) lines.insert(lines.end(), own.begin(), own.end());
  const imaging::PointSpread spread = imaging::estimatePointSpread(lines);
  ASSERT_TRUE(spread.found);
  EXPECT_TRUE(spread.held_across);
  EXPECT_NEAR(spread.sigma_mm, kLongSlicesSigma, 0.03);
  int found = 0;
  EXPECT_NEAR(meanModelSurface(planes[0], starts[0], spread, found), 0.0, 0.05);
  EXPECT_GT(found, 250);
}

// The same planes with a sample that has too few lines within the slices
// for their width (a hip's socket takes many out): further lines from the
// band within the slices tell it, and lines given as such that cross the
// slices are not taken.
TEST(CortexEdge, MoreLinesWithinLongSlicesTellTheWidthWithinThem) {
  std::vector<std::vector<double>> starts;
  const auto planes = linesOfPlanesInLongSlices(starts);
  ASSERT_GT(planes[0].size(), 220u);
  std::vector<imaging::LineVoxels> lines = planes[1], across = planes[1];
  lines.insert(lines.end(), planes[2].begin(), planes[2].end());
  across.insert(across.end(), planes[2].begin(), planes[2].end());
  constexpr size_t kFewWithin = 20;  // fewer than the 30 a width needs
  lines.insert(lines.end(), planes[0].begin(), planes[0].begin() + kFewWithin);
  const std::vector<imaging::LineVoxels> more(planes[0].begin() + kFewWithin, planes[0].end());
  const std::vector<double> more_starts(starts[0].begin() + kFewWithin, starts[0].end());

  const imaging::PointSpread alone = imaging::estimatePointSpread(lines);
  const imaging::PointSpread told = imaging::estimatePointSpread(lines, 1, more);
  ASSERT_TRUE(alone.found);
  ASSERT_TRUE(told.found);
  EXPECT_GT(std::abs(alone.sigma_mm - told.sigma_mm), 0.005) << "every line's width, kept alone";
  EXPECT_NEAR(told.sigma_mm, kLongSlicesSigma, 0.03);
  int found = 0;
  EXPECT_NEAR(meanModelSurface(more, more_starts, told, found), 0.0, 0.05);
  EXPECT_GT(found, 200);
  const imaging::PointSpread crossing = imaging::estimatePointSpread(lines, 1, across);
  EXPECT_EQ(crossing.sigma_mm, alone.sigma_mm);
  EXPECT_EQ(crossing.slice_sigma_mm, alone.slice_sigma_mm);
}

// Slices a quarter longer than the in-plane voxels, blurred on the grid
// twice as wide across them as within them (a generator's 0.4 and 0.8 mm at
// 0.8 x 0.8 x 1 mm). One width for both directions misfits that blur, and
// the kind chosen with it was the scanner's (0.34 mm, the surface facing
// within the slices 0.15 mm inside); the lines within the slices, whose
// blur is one width, choose the kind again.
TEST(CortexEdge, KindWithinLongSlicesFromTheLinesWithinThem) {
  constexpr double kWithin = 0.4, kAcross = 0.8;
  const Eigen::Vector3d normals[] = {Eigen::Vector3d(1, 0.21, 0.02), Eigen::Vector3d(0.8, -0.2, 0.5),
                                     Eigen::Vector3d(0.2, 0.3, 1)};
  std::vector<imaging::LineVoxels> lines, within;
  std::vector<double> within_starts;
  unsigned seed = 41;
  for (const Eigen::Vector3d& n : normals) {
    FlatCortex plane;
    plane.face(n);
    plane.spacing = 0.8;
    plane.slice_spacing = 1.0;
    plane.sigma = kWithin;
    plane.slice_sigma = kAcross;
    plane.thickness = 0.8;
    plane.blur_on_grid = true;
    plane.size = Eigen::Vector3i(34, 34, 28);
    std::vector<double> own_starts;
    const std::vector<imaging::LineVoxels> own = linesAcross(plane, seed++, own_starts);
    for (size_t i = 0; i < own.size(); i += 3) {  // a third of the lines: enough, in a third of the time
      lines.push_back(own[i]);
      if (&n != &normals[0]) continue;
      within.push_back(own[i]);
      within_starts.push_back(own_starts[i]);
    }
  }
  const imaging::PointSpread spread = imaging::estimatePointSpread(lines);
  ASSERT_TRUE(spread.found);
  EXPECT_EQ(spread.kind, imaging::PointSpread::Kind::VoxelGrid);
  EXPECT_NEAR(spread.sigma_mm, kWithin, 0.03);
  int found = 0;
  EXPECT_NEAR(meanModelSurface(within, within_starts, spread, found), 0.0, 0.04);
  EXPECT_GT(found, 80);
}

// Slices reconstructed twice as thick as their spacing (2 mm every 1 mm),
// blurred on the grid as the phantom's are: each voxel averages the bone
// over its thickness. Where the CT states it (a DICOM series' Slice
// Thickness), the model's box across the slices is that thickness, and a
// surface facing across them lies on the bone (0.003 mm); with the box
// taken as the spacing, the wider profile puts it outside (0.073 mm).
TEST(CortexEdge, SlicesThickerThanTheirSpacingAveragedOverTheirThickness) {
  const auto heldSurface = [](bool stated) {
    FlatCortex across;
    across.spacing = 0.6;
    across.slice_spacing = 1.0;
    across.slice_thickness = 2.0;
    across.thickness_stated = stated;
    across.blur_on_grid = true;
    across.face(Eigen::Vector3d(0.3, 0.1, 1));  // a slice share of 0.91
    across.size = Eigen::Vector3i(44, 44, 24);
    std::vector<double> starts;
    const std::vector<imaging::LineVoxels> lines = linesAcross(across, 43, starts);
    imaging::PointSpread spread;
    spread.sigma_mm = spread.slice_sigma_mm = across.sigma;
    spread.kind = imaging::PointSpread::Kind::VoxelGrid;
    const imaging::CortexTissue tissue = across.tissue();
    double sum = 0;
    int found = 0;
    for (size_t i = 0; i < lines.size(); ++i) {
      const imaging::CortexFit held =
          imaging::fitCortex(lines[i], 0.0, imaging::StepResponse(lines[i], spread), 150, &tissue);
      if (held.found) sum += starts[i] + held.offset_mm, ++found;
    }
    EXPECT_GT(found, 100) << (stated ? "stated" : "not stated");
    return sum / std::max(found, 1);
  };
  EXPECT_NEAR(heldSurface(true), 0.0, 0.05) << "the box the slices' thickness";
  EXPECT_GT(heldSurface(false), 0.05) << "the box the slices' spacing";
}

// A small convex head: a ball's cortex (outer radius 8 mm, 1.5 mm thick)
// under a scanner's Gaussian of 0.7 mm, its voxels averaged (closed form of
// the blurred ball). The blur averages the bone over a patch of the curved
// surface, which lies deeper the further out, so the model's flat step
// finds it about s^2 / R inside (0.061 mm); allowed for, on the surface.
// Lines along the radii, started 0.2 mm out, with the ball's curvature.
TEST(CortexEdge, ConvexSurfaceUnderTheBlurWhereItIs) {
  constexpr double kRadius = 8, kThickness = 1.5, kSigma = 0.7, kSpacing = 0.5, kStart = 0.2;
  // The share of a ball of radius `radius` at distance r from its centre
  // under an isotropic Gaussian of width kSigma.
  const auto blurredBall = [](double r, double radius) {
    const auto g = [](double x) { return std::exp(-0.5 * x * x / (kSigma * kSigma)) / (kSigma * std::sqrt(2 * M_PI)); };
    if (r < 1e-9) return Phi(radius / kSigma) - Phi(-radius / kSigma) - 2 * radius * g(radius);
    return Phi((radius - r) / kSigma) + Phi((radius + r) / kSigma) - 1 - kSigma * kSigma / r * (g(r - radius) - g(r + radius));
  };
  imaging::Volume v;
  v.geometry.size = Eigen::Vector3i::Constant(48);
  v.geometry.spacing = Eigen::Vector3d::Constant(kSpacing);
  v.geometry.origin = Eigen::Vector3d::Constant(-0.5 * kSpacing * 47) + Eigen::Vector3d(0.11, -0.07, 0.05);
  v.voxels.resize(static_cast<size_t>(v.geometry.voxelCount()));
  constexpr int kSub = 4;  // samples per voxel edge (partial volume)
  for (int k = 0; k < 48; ++k)
    for (int j = 0; j < 48; ++j)
      for (int i = 0; i < 48; ++i) {
        const Eigen::Vector3d centre = v.geometry.toPhysical(Eigen::Vector3d(i, j, k));
        double sum = 0;
        for (int c = 0; c < kSub * kSub * kSub; ++c) {
          const Eigen::Vector3d at =
              centre + kSpacing * Eigen::Vector3d((c % kSub + 0.5) / kSub - 0.5, (c / kSub % kSub + 0.5) / kSub - 0.5,
                                                  (c / (kSub * kSub) + 0.5) / kSub - 0.5);
          const double r = at.norm();
          sum += 40 + 660 * blurredBall(r, kRadius) - 510 * blurredBall(r, kRadius - kThickness);
        }
        v.at(i, j, k) = static_cast<float>(sum / (kSub * kSub * kSub));
      }
  imaging::PointSpread spread;
  spread.sigma_mm = spread.slice_sigma_mm = kSigma;
  double flat = 0, allowed = 0;
  int found = 0;
  constexpr int kLines = 60;
  for (int l = 0; l < kLines; ++l) {  // directions spread over the sphere (a Fibonacci lattice)
    const double z = 1 - (l + 0.5) * 2.0 / kLines, phi = l * M_PI * (3 - std::sqrt(5.0));
    const Eigen::Vector3d u(std::sqrt(1 - z * z) * std::cos(phi), std::sqrt(1 - z * z) * std::sin(phi), z);
    const imaging::LineVoxels line = imaging::voxelsAboutLine(v, (kRadius + kStart) * u, u, -imaging::kCortexInwardMm,
                                                              imaging::kCortexOutwardMm,
                                                              imaging::lineRadiusFor(v.geometry, u), 1 / kRadius);
    const imaging::CortexFit fit = imaging::fitCortex(line, 0.0, imaging::StepResponse(line, spread));
    if (!fit.found) continue;
    flat += kStart + fit.offset_mm;
    allowed += kStart + fit.offset_mm + imaging::curvatureShiftMm(line, spread);
    ++found;
  }
  ASSERT_GT(found, kLines * 9 / 10);
  EXPECT_LT(flat / found, -0.04) << "the flat step's surface, inside";  // -0.053
  EXPECT_NEAR(allowed / found, 0.0, 0.02);                              // +0.008
  // Blurred on the grid, the Gaussian's weights at whole voxels spread
  // less than the Gaussian below a voxel: at 0.4 of one, 0.081 voxels^2 (the
  // weights e^-3.125 either side of 1), not 0.16.
  imaging::PointSpread grid;
  grid.kind = imaging::PointSpread::Kind::VoxelGrid;
  grid.sigma_mm = grid.slice_sigma_mm = 0.4 * kSpacing;
  imaging::LineVoxels along_x;
  along_x.spacing_mm = v.geometry.spacing;
  along_x.axis_step_mm = Eigen::Vector3d(kSpacing, 0, 0);
  along_x.curvature_per_mm = 0.1;
  const double side = std::exp(-3.125), voxels2 = 2 * side / (1 + 2 * side);
  EXPECT_NEAR(imaging::curvatureShiftMm(along_x, grid), 0.5 * 0.1 * 2 * voxels2 * kSpacing * kSpacing, 1e-5);
}

TEST(CortexEdge, NothingFoundWithoutABrightLayerOrVoxels) {
  FlatCortex flat;
  flat.cortical = flat.soft + 50;
  flat.cancellous = flat.soft + 50;
  const imaging::Volume v = flat.volume(3);
  const auto line = imaging::voxelsAboutLine(v, flat.surface * flat.n, flat.n, -3.5, 2.5, 0.8);
  EXPECT_FALSE(imaging::fitCortex(line, 0.0, 0.5).found);
  EXPECT_FALSE(imaging::fitCortex(imaging::LineVoxels{}, 0.0, 0.5).found);
  EXPECT_FALSE(imaging::estimatePointSpread({line}).found);  // one line is not enough
}

}  // namespace
}  // namespace articula
