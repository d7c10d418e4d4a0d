#include "articula/phantom/phantom.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Geometry>

#include "articula/core/error.hpp"
#include "articula/geometry/pose.hpp"
#include "articula/geometry/surface.hpp"

namespace articula::phantom {
namespace {

using Eigen::Vector3d;

/// Depth below the surface of a capped cylinder (positive inside, mm).
double cylinderDepth(const Vector3d& x, const Vector3d& a, const Vector3d& b, double radius) {
  const Vector3d axis = (b - a).normalized();
  const double t = (x - a).dot(axis), length = (b - a).norm();
  const double radial = radius - (x - a - t * axis).norm();
  return std::min({radial, t, length - t});
}

/// The phantom's tissues as a function of position.
struct Anatomy {
  std::unique_ptr<geometry::PosedSurface> head;
  Vector3d center, neck_end, shaft_top, shaft_bottom, trochanter, trochanter_axes, socket_axis;
  double neck_radius, shaft_radius, gap, socket_wall = 12.0, socket_half_angle_cos;
  const PhantomOptions* o;

  /// Approximate signed depth below the head surface, -F / |grad F| (exact to
  /// first order at the surface, which is all the cortex and gap need).
  double headDepth(const Vector3d& x) const {
    const geometry::Evaluation e = head->evaluate(x, 1);
    return -e.value / std::max(e.gradient.norm(), 1e-9);
  }

  /// Approximate signed depth inside the greater trochanter: an elongated
  /// ellipsoidal prominence (not a sphere, which no real trochanter is).
  double trochanterDepth(const Vector3d& x) const {
    const Vector3d u = (x - trochanter).cwiseQuotient(trochanter_axes);
    const double q = u.norm();
    if (q < 1e-12) return trochanter_axes.minCoeff();
    const Vector3d grad = u.cwiseQuotient(trochanter_axes) / q;
    return (1.0 - q) / grad.norm();
  }

  /// Signed depth inside the femur: head, neck, shaft and trochanter.
  double femurDepth(const Vector3d& x) const {
    return std::max({headDepth(x), cylinderDepth(x, center, neck_end, neck_radius),
                     cylinderDepth(x, shaft_top, shaft_bottom, shaft_radius), trochanterDepth(x)});
  }

  /// HU at x and the distance to the nearest tissue interface (mm).
  double hu(const Vector3d& x, double& interface) const {
    const double femur = femurDepth(x);
    // The acetabulum: a shell from gap to gap + wall outside the head, within a cone about the socket axis.
    const double outside = -headDepth(x);
    const Vector3d u = (x - center).normalized();
    const double cone = ((x - center).norm()) * (u.dot(socket_axis) - socket_half_angle_cos);
    const double socket = std::min({outside - gap, gap + socket_wall - outside, cone});
    interface = std::min({std::fabs(femur), std::fabs(femur - o->cortical_mm), std::fabs(socket),
                          std::fabs(socket - o->cortical_mm)});
    const double bone = std::max(femur, socket);
    if (bone <= 0) return o->soft_tissue_hu;
    return bone < o->cortical_mm ? o->cortical_hu : o->cancellous_hu;
  }
};

/// Separable Gaussian blur of an i-fastest buffer, sigma in mm per axis;
/// hand-written so that this module stays free of ITK.
void blur(imaging::Volume& v, double sigma_mm) {
  const imaging::ImageGeometry& g = v.geometry;
  for (int axis = 0; axis < 3; ++axis) {
    const double s = sigma_mm / g.spacing[axis];
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

nlohmann::json vec(const Vector3d& v) { return {v[0], v[1], v[2]}; }

}  // namespace

void PhantomOptions::validate() const {
  if (!(spacing.minCoeff() >= 0.2 && spacing.maxCoeff() <= 4.0))
    throw UsageError("phantom spacing: expected 0.2 to 4 mm per axis");
  if (!(gap_mm >= 0.5 && gap_mm <= 8.0)) throw UsageError("phantom --gap: expected 0.5 to 8 mm");
  if (!(noise_hu >= 0) || !(blur_mm >= 0)) throw UsageError("phantom noise and blur must be >= 0");
  if (!(cortical_mm > 0)) throw UsageError("phantom cortical thickness must be > 0");
}

Phantom makePhantom(const PhantomOptions& o) {
  o.validate();
  std::mt19937_64 rng(o.seed);
  auto uniform = [&rng](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  const double s = o.right ? -1.0 : 1.0;  // LPS: the right side is -x; lateral is s * x

  // The head: a member of the hierarchy, near-spherical like real femoral heads.
  geometry::ShapeParameters p;
  p.model = o.model ? *o.model : geometry::allModels()[o.seed % geometry::allModels().size()];
  const double r0 = uniform(20.0, 25.0);
  p.radii = Vector3d::Constant(r0);
  if (p.model != geometry::ShapeModel::Sphere)
    p.radii = Vector3d(r0 * uniform(0.94, 1.06), r0 * uniform(0.94, 1.06), r0 * uniform(0.94, 1.06));
  if (p.model == geometry::ShapeModel::Superellipsoid || p.model == geometry::ShapeModel::Superovoid)
    p.exponents = Vector3d(uniform(2.0, 2.6), uniform(2.0, 2.6), uniform(2.0, 2.6));
  if (p.model == geometry::ShapeModel::Ovoid || p.model == geometry::ShapeModel::Superovoid) {
    p.cx = Eigen::Vector4d(1.0, uniform(0.0, 0.08), 0.0, 0.0);
    p.cy = Eigen::Vector4d(1.0, uniform(0.0, 0.08), 0.0, 0.0);
  }
  p.center = Vector3d(s * 95.0 + uniform(-3, 3), -12.0 + uniform(-3, 3), 35.0 + uniform(-3, 3));
  if (p.model != geometry::ShapeModel::Sphere)
    p.angles = Vector3d(uniform(-0.3, 0.3), uniform(-0.3, 0.3), uniform(-0.3, 0.3));
  geometry::validate(p);

  Anatomy a;
  a.o = &o;
  a.head = geometry::makeSurface(p);
  a.center = p.center;
  const double rmax = p.radii.maxCoeff();
  // Neck: lateral, inferior and a little anterior (LPS: anterior is -y).
  const Vector3d neck_axis = Vector3d(s * 1.0, -0.25, -0.8).normalized();
  a.neck_radius = 0.68 * r0;
  a.neck_end = a.center + 1.9 * r0 * neck_axis;
  a.shaft_radius = 14.0;
  a.shaft_top = a.neck_end + Vector3d(s * 6.0, 0.0, 10.0);
  a.shaft_bottom = a.shaft_top - Vector3d(0, 0, 400.0);
  a.trochanter = a.shaft_top + Vector3d(s * 4.0, 0.0, 0.0);
  a.trochanter_axes = Vector3d(13.0, 15.0, 20.0);  // lateral, anterior-posterior, vertical (mm)
  a.socket_axis = (-neck_axis + Vector3d(0, 0, 0.3)).normalized();
  a.socket_half_angle_cos = std::cos(80.0 * M_PI / 180.0);
  a.gap = o.gap_mm;

  // The grid: head, socket and pelvis medially, neck and shaft laterally.
  // Lateral 60 mm, medial 80 mm: the head lies on its side of the grid's centre.
  const Vector3d lo(std::min(a.center[0] + s * 60.0, a.center[0] - s * 80.0), a.center[1] - 55.0, a.center[2] - 75.0);
  const Vector3d hi(std::max(a.center[0] + s * 60.0, a.center[0] - s * 80.0), a.center[1] + 55.0, a.center[2] + 50.0);
  imaging::ImageGeometry g;
  g.spacing = o.spacing;
  for (int ax = 0; ax < 3; ++ax) g.size[ax] = static_cast<int>(std::ceil((hi[ax] - lo[ax]) / o.spacing[ax])) + 1;
  if (o.ras_storage) {
    // Stored RAS: index i runs to patient left-to-right (-x), j anterior-to... (-y).
    g.direction = Eigen::Vector3d(-1, -1, 1).asDiagonal();
    g.origin = Vector3d(hi[0], hi[1], lo[2]);
  } else {
    g.origin = lo;
  }

  Phantom out;
  out.head = p;
  out.neck_axis = neck_axis;
  out.ct.geometry = g;
  out.ct.voxels.resize(static_cast<size_t>(g.voxelCount()));
  out.femur.geometry = g;
  out.femur.voxels.assign(out.ct.voxels.size(), 0);
  const double half_diagonal = 0.5 * o.spacing.norm();
  const int sub = 3;  // partial volume: 3 x 3 x 3 samples in voxels near an interface
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        const Vector3d x = g.toPhysical(Vector3d(i, j, k));
        double interface = 0;
        double value = a.hu(x, interface);
        if (interface < half_diagonal) {
          value = 0;
          double ignored = 0;
          for (int c = 0; c < sub * sub * sub; ++c) {
            const Vector3d offset((c % sub + 0.5) / sub - 0.5, (c / sub % sub + 0.5) / sub - 0.5, (c / (sub * sub) + 0.5) / sub - 0.5);
            value += a.hu(g.toPhysical(Vector3d(i, j, k) + offset), ignored);
          }
          value /= sub * sub * sub;
        }
        out.ct.at(i, j, k) = static_cast<float>(value);
        out.femur.at(i, j, k) = a.femurDepth(x) > 0 ? 1 : 0;
      }
  blur(out.ct, o.blur_mm);
  std::normal_distribution<double> noise(0.0, o.noise_hu);
  if (o.noise_hu > 0)
    for (float& v : out.ct.voxels) v += static_cast<float>(noise(rng));

  nlohmann::json lambda;
  const auto names = geometry::parameterNames(p.model);
  const Eigen::VectorXd values = geometry::toVector(p);
  for (size_t n = 0; n < names.size(); ++n) lambda[names[n]] = values[static_cast<Eigen::Index>(n)];
  out.truth = {
      {"coordinate_system", "LPS"},
      {"units", "mm"},
      {"seed", o.seed},
      {"side", o.right ? "right" : "left"},
      {"joint", "hip"},
      {"model", geometry::modelName(p.model)},
      {"parameters", lambda},
      {"radii_mm", vec(p.radii)},
      {"exponents", vec(p.exponents)},
      {"cx", {p.cx[0], p.cx[1], p.cx[2], p.cx[3]}},
      {"cy", {p.cy[0], p.cy[1], p.cy[2], p.cy[3]}},
      {"angles_rad", vec(p.angles)},
      {"head_center_mm", vec(p.center)},
      {"head_max_radius_mm", rmax},
      {"neck_axis", vec(neck_axis)},
      {"socket_axis", vec(a.socket_axis)},
      {"joint_gap_mm", o.gap_mm},
      {"cortical_mm", o.cortical_mm},
      {"hu", {{"cortical", o.cortical_hu}, {"cancellous", o.cancellous_hu}, {"soft_tissue", o.soft_tissue_hu}}},
      {"noise_hu", o.noise_hu},
      {"blur_mm", o.blur_mm},
      {"grid",
       {{"size", {g.size[0], g.size[1], g.size[2]}},
        {"spacing_mm", vec(g.spacing)},
        {"origin_mm", vec(g.origin)},
        {"direction_row_major",
         {g.direction(0, 0), g.direction(0, 1), g.direction(0, 2), g.direction(1, 0), g.direction(1, 1),
          g.direction(1, 2), g.direction(2, 0), g.direction(2, 1), g.direction(2, 2)}}}},
  };
  return out;
}

}  // namespace articula::phantom
