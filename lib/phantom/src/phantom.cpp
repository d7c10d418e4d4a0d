#include "articula/phantom/phantom.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <random>

#include <Eigen/Geometry>

#include "articula/core/error.hpp"
#include "articula/distance/signed_distance.hpp"
#include "articula/geometry/pose.hpp"
#include "articula/geometry/surface.hpp"
#include "artefacts.hpp"
#include "arthritis.hpp"
#include "surface_search.hpp"

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

struct Cylinder {
  Vector3d a, b;
  double radius;
  double depth(const Vector3d& x) const { return cylinderDepth(x, a, b, radius); }
};

/// An axis-aligned box: depth below its nearest face (positive inside).
struct Box {
  Vector3d center, half;
  double depth(const Vector3d& x) const { return (half - (x - center).cwiseAbs()).minCoeff(); }
};

/// One hip's tissues as functions of position.
struct HipAnatomy {
  Hip truth;
  std::unique_ptr<geometry::PosedSurface> head;
  std::unique_ptr<distance::SignedDistance> exact;
  Vector3d center, neck_end, shaft_top, shaft_bottom, trochanter, trochanter_axes;
  double r0 = 0, rmax = 0, neck_radius = 0, shaft_radius = 14.0;  // r0: the drawn mean radius
  // Approximate depths in [band_lo, band_hi] are replaced by the exact one;
  // beyond max_reach from the centre no tissue boundary depends on it.
  double band_lo = 0, band_hi = 0, max_reach = 0;
  bool exact_depth = false;
  mutable std::optional<Vector3d> last_foot;  // the previous exact closest point
  mutable Vector3d last_x = Vector3d::Zero();  // and its point

  /// Signed depth below the head surface (positive inside, mm): -F / |grad F|,
  /// exact to first order at the surface and of the right sign; with
  /// exact_depth, exact within the band where the cortex, the gap and the
  /// socket are drawn.
  double headDepth(const Vector3d& x) const {
    if ((x - center).norm() > max_reach) return rmax - (x - center).norm();
    const geometry::Evaluation e = head->evaluate(x, 1);
    const double approx = -e.value / std::max(e.gradient.norm(), 1e-9);
    if (!exact_depth || approx < band_lo || approx > band_hi) return approx;
    // Voxels are visited in order, so the previous foot point is a good start
    // for a local search when the previous point was near. Newton can also
    // land on a farther critical point, so its answer is kept only if it is
    // no farther than the start (a surface point) and of the sign of F.
    if (last_foot && (x - last_x).norm() < 3.0) {
      const distance::ClosestPoint c = exact->closestFrom(x, *last_foot);
      if (std::fabs(c.distance) <= (x - *last_foot).norm() + 1e-9 && (c.distance < 0) == (e.value < 0) &&
          (c.point - *last_foot).norm() < 3.0) {
        last_x = x;
        last_foot = c.point;
        return -c.distance;
      }
    }
    const distance::ClosestPoint c = exact->closest(x);
    last_x = x;
    last_foot = c.point;
    return -c.distance;
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

  /// Signed depth inside the femur (head less the fovea, neck, shaft,
  /// trochanter), given the head depth at x.
  double femurDepth(const Vector3d& x, double head_depth) const {
    return std::max({-headSurfaceDistance(truth, -head_depth, x), cylinderDepth(x, center, neck_end, neck_radius),
                     cylinderDepth(x, shaft_top, shaft_bottom, shaft_radius), trochanterDepth(x)});
  }
};

/// The whole field of view: the hips, their sockets and the pelvic frame.
struct Anatomy {
  std::vector<HipAnatomy> hips;
  std::vector<Cylinder> pelvis_bars;  // ilium and pubic rami (both hips)
  std::vector<Box> pelvis_blocks;     // sacrum and pubic symphysis (both hips)
  double socket_half_angle_cos = std::cos(80.0 * M_PI / 180.0);
  Vector3d wave_phase = Vector3d::Zero();
  std::vector<Cyst> cysts;  // of the requested side's head
  std::vector<Cylinder> metal;
  std::optional<Cylinder> vessel;
  /// The table's slab in the axial plane: radius to radius + thickness
  /// from an axis along z through (x, y) = table_axis; air beyond.
  std::optional<Eigen::Vector2d> table_axis;
  double table_radius = 400.0, table_thickness = 6.0, table_hu = 700.0, air_hu = -1000.0;
  const PhantomOptions* o = nullptr;

  /// Depth inside a hip's acetabulum: a shell of the wall's thickness,
  /// congruent (at the gap from the head) or spherical, within a cone of
  /// 80 degrees about the socket axis.
  double socketDepth(const HipAnatomy& h, const Vector3d& x, double head_depth) const {
    const Vector3d from_pole_centre = x - h.truth.socket_center;
    const double r = from_pole_centre.norm();
    const double cone = r * (from_pole_centre.dot(h.truth.socket_axis) / std::max(r, 1e-12) - socket_half_angle_cos);
    const double outside = -head_depth;
    const double inner = h.truth.socket_inner_radius_mm;
    const double depth = o->congruent_socket ? std::min({outside - o->gap_mm, o->gap_mm + o->socket_wall_mm - outside, cone})
                                             : std::min({r - inner, inner + o->socket_wall_mm - r, cone});
    if (!h.truth.narrow_gap) return depth;
    // A narrowed joint: the socket's inner surface advances from its own
    // distance to the head to the narrow gap over the patch (its outer
    // surface stays), smoothly back at the patch's edge.
    const double w = h.truth.narrow_gap->weight(x - h.center);
    if (w <= 0) return depth;
    const double own_gap = o->congruent_socket ? o->gap_mm : outside + inner - r;
    const double gap = own_gap - w * (own_gap - h.truth.narrow_gap->gap_mm);
    const double outer = o->congruent_socket ? o->gap_mm + o->socket_wall_mm - outside : inner + o->socket_wall_mm - r;
    return std::max(depth, std::min({outside - gap, outer, cone}));
  }

  /// Cancellous HU at x: uniform, or varying smoothly (wavelength 30 mm).
  double cancellous(double base, const Vector3d& x) const {
    if (o->cancellous_variation_hu <= 0) return base;
    const Vector3d w = x * (2.0 * M_PI / 30.0) + wave_phase;
    return base + o->cancellous_variation_hu * std::sin(w[0]) * std::sin(w[1]) * std::sin(w[2]);
  }

  /// Depth inside the metal (positive inside, mm).
  double metalDepth(const Vector3d& x) const {
    double depth = -std::numeric_limits<double>::infinity();
    for (const Cylinder& c : metal) depth = std::max(depth, c.depth(x));
    return depth;
  }

  /// HU at x and the distance to the nearest interface: the tissues, with
  /// what lies in them (metal).
  double hu(const Vector3d& x, double& interface, int* femur_label = nullptr) const {
    bool in_bone = false;
    const double tissue = tissueHu(x, interface, femur_label, &in_bone);
    if (metal.empty() && !vessel && !table_axis) return tissue;
    double value = tissue;
    if (table_axis) {
      // Posterior of the body's back: the table's slab, then air.
      const double r = (x.head<2>() - *table_axis).norm();
      interface = std::min({interface, std::fabs(r - table_radius), std::fabs(r - table_radius - table_thickness)});
      if (r > table_radius + table_thickness) return air_hu;
      if (r > table_radius) return table_hu;
    }
    if (vessel) {
      const double depth = vessel->depth(x);
      interface = std::min(interface, std::fabs(depth));
      if (depth > 0 && !in_bone) value = o->vessel_hu;
    }
    if (!metal.empty()) {
      const double depth = metalDepth(x);
      interface = std::min(interface, std::fabs(depth));
      if (depth > 0) value = o->metal_hu;
    }
    return value;
  }

  /// The tissues' HU at x and the distance to the nearest tissue interface
  /// (mm); `femur` gets the label of the femur containing x (0: none).
  double tissueHu(const Vector3d& x, double& interface, int* femur_label = nullptr, bool* in_bone = nullptr) const {
    double femur = -std::numeric_limits<double>::infinity(), pelvis = femur, clearance = -femur;
    for (size_t n = 0; n < hips.size(); ++n) {
      const HipAnatomy& h = hips[n];
      const double head_depth = h.headDepth(x);
      const double f = h.femurDepth(x, head_depth);
      if (f > femur) {
        femur = f;
        if (femur_label) *femur_label = f > 0 ? static_cast<int>(n) + 1 : 0;
      }
      pelvis = std::max(pelvis, socketDepth(h, x, head_depth));
      clearance = std::min(clearance, (x - h.center).norm() - h.rmax - o->gap_mm - 1.0);
    }
    // The frame keeps clear of the joints (the sockets alone face the heads).
    for (const Cylinder& c : pelvis_bars) pelvis = std::max(pelvis, std::min(c.depth(x), clearance));
    for (const Box& b : pelvis_blocks) pelvis = std::max(pelvis, std::min(b.depth(x), clearance));
    const double cortex = o->cortical_mm;
    interface = std::min({std::fabs(femur), std::fabs(femur - cortex), std::fabs(pelvis), std::fabs(pelvis - cortex)});
    const double bone = std::max(femur, pelvis);
    if (in_bone) *in_bone = bone > 0;
    if (bone <= 0) return o->soft_tissue_hu;
    if (femur >= pelvis) {
      // Subchondral cysts: fluid balls in the cancellous bone.
      for (const Cyst& cyst : cysts) {
        const double depth = cyst.radius_mm - (x - cyst.center).norm();
        interface = std::min(interface, std::fabs(depth));
        if (depth > 0 && bone >= cortex) return o->cyst_hu;
      }
      return bone < cortex ? o->cortical_hu : cancellous(o->cancellous_hu, x);
    }
    return bone < cortex ? o->socket_cortical_hu.value_or(o->cortical_hu)
                         : cancellous(o->socket_cancellous_hu.value_or(o->cancellous_hu), x);
  }
};

nlohmann::json vec(const Vector3d& v) { return {v[0], v[1], v[2]}; }

/// Draws one head (the order of draws is that of the original single-hip
/// phantom, so a seed keeps its head).
geometry::ShapeParameters drawHead(const PhantomOptions& o, geometry::ShapeModel model, double s,
                                   const std::function<double(double, double)>& uniform, double& r0) {
  geometry::ShapeParameters p;
  p.model = model;
  r0 = uniform(o.head_radius_range_mm[0], o.head_radius_range_mm[1]);
  if (o.head_radius_mm) r0 = *o.head_radius_mm;
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
  return p;
}

/// Distance from the centre to the surface along unit direction d (bisection on F).
double surfaceAlong(const geometry::PosedSurface& head, const Vector3d& center, const Vector3d& d, double rmax) {
  double lo = 0, hi = 2 * rmax;
  while (hi - lo > 1e-9) (head.value(center + 0.5 * (lo + hi) * d) < 0 ? lo : hi) = 0.5 * (lo + hi);
  return 0.5 * (lo + hi);
}

/// The hip's femur and socket around a drawn head.
HipAnatomy makeHip(const PhantomOptions& o, const geometry::ShapeParameters& p, double r0, bool right) {
  const double s = right ? -1.0 : 1.0;  // LPS: the right side is -x; lateral is s * x
  HipAnatomy h;
  h.truth.right = right;
  h.truth.head = p;
  h.head = geometry::makeSurface(p);
  h.exact = std::make_unique<distance::SignedDistance>(p);
  h.center = p.center;
  h.rmax = p.radii.maxCoeff();
  h.r0 = r0;
  // Neck: lateral, inferior and a little anterior (LPS: anterior is -y).
  const Vector3d neck_axis = Vector3d(s * 1.0, -0.25, -0.8).normalized();
  h.truth.neck_axis = neck_axis;
  h.neck_radius = 0.68 * r0;
  h.neck_end = h.center + 1.9 * r0 * neck_axis;
  h.shaft_top = h.neck_end + Vector3d(s * 6.0, 0.0, 10.0);
  h.shaft_bottom = h.shaft_top - Vector3d(0, 0, 400.0);
  h.trochanter = h.shaft_top + Vector3d(s * 4.0, 0.0, 0.0);
  h.trochanter_axes = Vector3d(13.0, 15.0, 20.0);  // lateral, anterior-posterior, vertical (mm)
  h.truth.socket_axis = (-neck_axis + Vector3d(0, 0, 0.3)).normalized();
  h.truth.socket_center = h.center;
  if (!o.congruent_socket) {
    // The pole of the socket lies gap_mm beyond the head's bounding sphere,
    // so the joint space is gap_mm at least and widens towards the rim.
    h.truth.socket_inner_radius_mm = h.rmax + o.gap_mm + o.socket_excess_mm;
    h.truth.socket_center = h.center - o.socket_excess_mm * h.truth.socket_axis;
  }
  if (o.fovea) {
    const Vector3d d = Vector3d(-s, 0.15, -0.2).normalized();  // medial, a little posterior and inferior
    const double t = surfaceAlong(*h.head, h.center, d, h.rmax);
    h.truth.fovea = true;
    h.truth.fovea_radius_mm = o.fovea_radius_mm;
    h.truth.fovea_center = h.center + (t + o.fovea_radius_mm - o.fovea_depth_mm) * d;
  }
  const double outer = o.gap_mm + o.socket_wall_mm + (o.congruent_socket ? 0.0 : o.socket_excess_mm);
  h.band_lo = -1.5 * outer - 3.0;
  h.band_hi = 1.5 * (o.cortical_mm + (o.fovea ? o.fovea_depth_mm : 0.0)) + 3.0;
  h.max_reach = h.rmax + 1.5 * outer + 10.0;
  h.exact_depth = o.exact_depth;
  return h;
}

/// The tissues on grid g, each voxel the mean of 3 x 3 x 3 samples where an
/// interface passes within half its diagonal (partial volume), and the femur
/// label of its centre.
void render(const Anatomy& a, const imaging::ImageGeometry& g, imaging::Volume& ct, imaging::Label& femur) {
  ct.geometry = g;
  ct.voxels.resize(static_cast<size_t>(g.voxelCount()));
  femur.geometry = g;
  femur.voxels.assign(ct.voxels.size(), 0);
  const double half_diagonal = 0.5 * g.spacing.norm();
  const int sub = 3;  // partial volume: 3 x 3 x 3 samples in voxels near an interface
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        const Vector3d x = g.toPhysical(Vector3d(i, j, k));
        double interface = 0;
        int label = 0;
        double value = a.hu(x, interface, &label);
        if (interface < half_diagonal) {
          value = 0;
          double ignored = 0;
          for (int c = 0; c < sub * sub * sub; ++c) {
            const Vector3d offset((c % sub + 0.5) / sub - 0.5, (c / sub % sub + 0.5) / sub - 0.5, (c / (sub * sub) + 0.5) / sub - 0.5);
            value += a.hu(g.toPhysical(Vector3d(i, j, k) + offset), ignored);
          }
          value /= sub * sub * sub;
        }
        ct.at(i, j, k) = static_cast<float>(value);
        femur.at(i, j, k) = static_cast<std::uint8_t>(label);
      }
}

/// Slices thicker than their spacing: the tissues rendered on slices m
/// times finer (0.5 mm or a quarter of the thickness at most), each output
/// slice their mean over a box `thickness` wide about it (the fine slices
/// weighted by their overlap with the box); the label of its centre.
void renderThickSlices(const Anatomy& a, const imaging::ImageGeometry& g, double thickness, imaging::Volume& ct,
                       imaging::Label& femur) {
  const int m = std::max(2, static_cast<int>(std::ceil(g.spacing[2] / std::min(0.5, 0.25 * thickness))));
  const double fine_mm = g.spacing[2] / m, half = 0.5 * thickness / fine_mm;  // the box's half width in fine slices
  const int pad = static_cast<int>(std::ceil(half)) + 1;
  imaging::ImageGeometry fine = g;
  fine.spacing[2] = fine_mm;
  fine.size[2] = (g.size[2] - 1) * m + 1 + 2 * pad;
  fine.origin = g.toPhysical(Vector3d(0, 0, -static_cast<double>(pad) / m));
  imaging::Volume fine_ct;
  imaging::Label fine_label;
  render(a, fine, fine_ct, fine_label);
  ct.geometry = g;
  ct.voxels.assign(static_cast<size_t>(g.voxelCount()), 0.0f);
  femur.geometry = g;
  femur.voxels.assign(ct.voxels.size(), 0);
  for (int k = 0; k < g.size[2]; ++k) {
    const int centre = m * k + pad;
    for (int q = -pad; q <= pad; ++q) {
      const double w = std::max(0.0, std::min(q + 0.5, half) - std::max(q - 0.5, -half)) / (2.0 * half);
      if (w <= 0) continue;
      for (int j = 0; j < g.size[1]; ++j)
        for (int i = 0; i < g.size[0]; ++i) ct.at(i, j, k) += static_cast<float>(w * fine_ct.at(i, j, centre + q));
    }
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) femur.at(i, j, k) = fine_label.at(i, j, centre);
  }
}

/// Where a clipped field of view ends: the voxel centres along index axis
/// `axis` beyond `plane` (a coordinate along the face's direction u) go.
struct FovCrop {
  Vector3d u;
  int axis = 2;
  double plane = 0, head_extent = 0, r0 = 0;  // head_extent: the head's support coordinate along u
};

/// Plans the crop for the requested head and moves the grid along the face's
/// axis (by under a voxel) so that a layer of voxel centres lies on the plane.
FovCrop planFovCrop(const PhantomOptions& o, const HipAnatomy& h, imaging::ImageGeometry& g) {
  FovCrop crop;
  crop.u = o.fov_face;
  crop.r0 = h.r0;
  for (int a = 0; a < 3; ++a)
    if (std::abs(g.direction.col(a).dot(crop.u)) > 0.5) crop.axis = a;
  const detail::Inside model = [&h](const Vector3d& x) { return h.head->value(x) < 0; };
  crop.head_extent = detail::support(model, h.center, crop.u, 2.0 * h.rmax).dot(crop.u);
  crop.plane = crop.head_extent - o.fov_cut * h.r0;
  const double step = g.direction.col(crop.axis).dot(crop.u) * g.spacing[crop.axis];  // along u per index
  const double from_origin = crop.plane - g.origin.dot(crop.u);
  g.origin += (from_origin - step * std::round(from_origin / step)) * crop.u;
  return crop;
}

/// The volume and the label with the voxels beyond the crop's plane removed.
void applyFovCrop(const FovCrop& crop, Phantom& out) {
  const imaging::ImageGeometry& g = out.ct.geometry;
  const double step = g.direction.col(crop.axis).dot(crop.u) * g.spacing[crop.axis];
  const int at = static_cast<int>(std::lround((crop.plane - g.origin.dot(crop.u)) / step));
  const int last = g.size[crop.axis] - 1;
  const int lo = step > 0 ? 0 : std::clamp(at, 0, last), hi = step > 0 ? std::clamp(at, 0, last) : last;
  out.ct = detail::cropAxis(out.ct, crop.axis, lo, hi);
  out.femur = detail::cropAxis(out.femur, crop.axis, lo, hi);
}

nlohmann::json hipTruth(const Hip& hip, const PhantomOptions& o) {
  const geometry::ShapeParameters& p = hip.head;
  nlohmann::json lambda;
  const auto names = geometry::parameterNames(p.model);
  const Eigen::VectorXd values = geometry::toVector(p);
  for (size_t n = 0; n < names.size(); ++n) lambda[names[n]] = values[static_cast<Eigen::Index>(n)];
  nlohmann::json t = {
      {"side", hip.right ? "right" : "left"},
      {"model", geometry::modelName(p.model)},
      {"parameters", lambda},
      {"radii_mm", vec(p.radii)},
      {"exponents", vec(p.exponents)},
      {"cx", {p.cx[0], p.cx[1], p.cx[2], p.cx[3]}},
      {"cy", {p.cy[0], p.cy[1], p.cy[2], p.cy[3]}},
      {"angles_rad", vec(p.angles)},
      {"head_center_mm", vec(p.center)},
      {"head_max_radius_mm", p.radii.maxCoeff()},
      {"neck_axis", vec(hip.neck_axis)},
      {"socket_axis", vec(hip.socket_axis)},
      {"socket",
       {{"shape", o.congruent_socket ? "congruent" : "spherical"},
        {"wall_mm", o.socket_wall_mm},
        {"center_mm", vec(hip.socket_center)},
        {"inner_radius_mm", hip.socket_inner_radius_mm}}},
  };
  if (hip.fovea)
    t["fovea"] = {{"center_mm", vec(hip.fovea_center)}, {"radius_mm", hip.fovea_radius_mm}, {"depth_mm", o.fovea_depth_mm}};
  const nlohmann::json departures = detail::departuresJson(hip, o);
  if (!departures.empty()) t["departures"] = departures;
  return t;
}

Vector3d vec3(const nlohmann::json& j) { return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()}; }

}  // namespace

double headSurfaceDistance(const Hip& hip, double head_distance_mm, const Eigen::Vector3d& x) {
  double d = head_distance_mm;
  // The head less the pit's ball: max(d_head, -d_ball), exact away from the pit's rim.
  if (hip.fovea) d = std::max(d, hip.fovea_radius_mm - (x - hip.fovea_center).norm());
  // Less the half-space beyond a flattened dome's plane; with the lip added.
  if (hip.flat_dome) d = std::max(d, (x - hip.flat_dome->point).dot(hip.flat_dome->normal));
  if (hip.osteophytes) d = std::min(d, hip.osteophytes->distance(x));
  return d;
}

Hip hipFromTruth(const nlohmann::json& t) {
  Hip hip;
  hip.right = t.at("side") == "right";
  geometry::ShapeParameters& p = hip.head;
  p.model = geometry::modelFromName(t.at("model").get<std::string>());
  p.radii = vec3(t.at("radii_mm"));
  p.exponents = vec3(t.at("exponents"));
  for (int n = 0; n < 4; ++n) p.cx[n] = t.at("cx")[n].get<double>(), p.cy[n] = t.at("cy")[n].get<double>();
  p.center = vec3(t.at("head_center_mm"));
  p.angles = vec3(t.at("angles_rad"));
  if (t.contains("neck_axis")) hip.neck_axis = vec3(t["neck_axis"]);
  if (t.contains("socket_axis")) hip.socket_axis = vec3(t["socket_axis"]);
  if (t.contains("fovea")) {
    hip.fovea = true;
    hip.fovea_center = vec3(t["fovea"]["center_mm"]);
    hip.fovea_radius_mm = t["fovea"]["radius_mm"].get<double>();
  }
  if (t.contains("departures")) detail::departuresFromJson(t["departures"], hip);
  return hip;
}

void PhantomOptions::makeOsteoporotic() {
  cortical_mm = 0.8;
  cortical_hu = 700;
  cancellous_hu = 190;
  cancellous_variation_hu = 90;
}

void PhantomOptions::validate() const {
  if (!(spacing.minCoeff() >= 0.2 && spacing.maxCoeff() <= 4.0))
    throw UsageError("phantom spacing: expected 0.2 to 4 mm per axis");
  if (!(gap_mm >= 0.5 && gap_mm <= 8.0)) throw UsageError("phantom --gap: expected 0.5 to 8 mm");
  if (!(noise_hu >= 0) || !(blur_mm >= 0)) throw UsageError("phantom noise and blur must be >= 0");
  if (!(cortical_mm > 0 && cortical_mm <= 5)) throw UsageError("phantom cortical thickness: expected > 0 and <= 5 mm");
  if (!(cancellous_variation_hu >= 0)) throw UsageError("phantom cancellous variation: expected >= 0 HU");
  if (!(head_radius_range_mm[0] >= 10 && head_radius_range_mm[1] <= 40 && head_radius_range_mm[0] <= head_radius_range_mm[1]))
    throw UsageError("phantom --radius-range: expected 10 <= LO <= HI <= 40 mm");
  if (head_radius_mm && !(*head_radius_mm >= 10 && *head_radius_mm <= 40))
    throw UsageError("phantom --radius: expected 10 to 40 mm");
  if (!(socket_wall_mm >= 2 && socket_wall_mm <= 30)) throw UsageError("phantom --socket-wall: expected 2 to 30 mm");
  if (!(socket_excess_mm >= 0 && socket_excess_mm <= 15)) throw UsageError("phantom --socket-excess: expected 0 to 15 mm");
  if (!(fovea_radius_mm > 0 && fovea_depth_mm > 0 && fovea_depth_mm < fovea_radius_mm && fovea_radius_mm <= 10))
    throw UsageError("phantom fovea: expected 0 < depth < radius <= 10 mm");
  if (!(flattened_dome >= 0 && flattened_dome <= 0.5)) throw UsageError("phantom --flattened-dome: expected 0 to 0.5 of the radius");
  if (!(osteophytes_mm >= 0 && osteophytes_mm <= 6)) throw UsageError("phantom --osteophytes: expected 0 to 6 mm");
  if (!(narrow_gap_mm == 0 || (narrow_gap_mm >= 0.3 && narrow_gap_mm < gap_mm)))
    throw UsageError("phantom --narrow-gap: expected 0.3 mm to less than the joint's --gap");
  if (!(slice_thickness_mm >= 0 && slice_thickness_mm <= 10)) throw UsageError("phantom --slice-thickness: expected 0 to 10 mm");
  if (fov_cut >= 0 && !(fov_cut <= 0.9)) throw UsageError("phantom --fov-cut: expected 0 to 0.9 of the radius");
  if (fov_cut >= 0 && !(std::abs(fov_face.norm() - 1) < 1e-9 && fov_face.cwiseAbs().maxCoeff() > 1 - 1e-9))
    throw UsageError("phantom --fov-face: expected a unit axis direction");
}

PhantomOptions::Metal metalFromName(const std::string& name) {
  if (name == "none") return PhantomOptions::Metal::None;
  if (name == "screw") return PhantomOptions::Metal::Screw;
  if (name == "stem") return PhantomOptions::Metal::Stem;
  throw UsageError("--metal '" + name + "': expected screw or stem");
}

PhantomOptions::Kernel kernelFromName(const std::string& name) {
  if (name == "standard") return PhantomOptions::Kernel::Standard;
  if (name == "soft") return PhantomOptions::Kernel::Soft;
  if (name == "sharp") return PhantomOptions::Kernel::Sharp;
  throw UsageError("--kernel '" + name + "': expected standard, soft or sharp");
}

Vector3d faceDirection(const std::string& face) {
  static const std::vector<std::pair<std::string, Vector3d>> faces = {
      {"+x", Vector3d::UnitX()}, {"-x", -Vector3d::UnitX()}, {"+y", Vector3d::UnitY()}, {"-y", -Vector3d::UnitY()},
      {"+z", Vector3d::UnitZ()}, {"-z", -Vector3d::UnitZ()}, {"L", Vector3d::UnitX()},  {"R", -Vector3d::UnitX()},
      {"P", Vector3d::UnitY()},  {"A", -Vector3d::UnitY()}, {"S", Vector3d::UnitZ()},  {"I", -Vector3d::UnitZ()}};
  for (const auto& [name, u] : faces)
    if (face == name) return u;
  throw UsageError("--fov-face '" + face + "': expected +x, -x, +y, -y, +z, -z (or L, R, P, A, S, I)");
}

Phantom makePhantom(const PhantomOptions& o) {
  o.validate();
  std::mt19937_64 rng(o.seed);
  const std::function<double(double, double)> uniform = [&rng](double a, double b) {
    return std::uniform_real_distribution<double>(a, b)(rng);
  };
  const auto& models = geometry::allModels();

  // The requested side first (its head is the single-hip phantom's), then the other.
  Anatomy a;
  a.o = &o;
  std::vector<bool> sides = {o.right};
  if (o.both_hips) sides.push_back(!o.right);
  for (size_t n = 0; n < sides.size(); ++n) {
    const geometry::ShapeModel model = o.model ? *o.model : models[(o.seed + n) % models.size()];
    double r0 = 0;
    const geometry::ShapeParameters head = drawHead(o, model, sides[n] ? -1.0 : 1.0, uniform, r0);
    a.hips.push_back(makeHip(o, head, r0, sides[n]));
  }
  HipAnatomy& requested = a.hips[0];
  detail::addArthritis(o, *requested.head, requested.r0, requested.neck_radius, requested.truth);
  a.cysts = requested.truth.cysts;
  if (o.metal == PhantomOptions::Metal::Screw) {
    // A lag screw along the neck from beyond the lateral cortex to 6 mm under the dome.
    const Vector3d axis = requested.truth.neck_axis;
    const detail::Inside model = [&requested](const Vector3d& x) { return requested.head->value(x) < 0; };
    const double to_dome = detail::along(model, requested.center, -axis, 2.0 * requested.rmax);
    a.metal.push_back({requested.center - (to_dome - 6.0) * axis, requested.center + (1.9 * requested.r0 + 30.0) * axis, 3.25});
  } else if (o.metal == PhantomOptions::Metal::Stem) {
    a.metal.push_back({requested.shaft_top + Vector3d(0, 0, 5.0), requested.shaft_top - Vector3d(0, 0, 140.0), 6.0});
  }
  if (o.contrast_vessel) {
    // Anterior (LPS -y) and a little medial of the head, its wall 5 mm off
    // the bounding sphere, running down and a little laterally.
    const double s = requested.truth.right ? -1.0 : 1.0, radius = 3.0;
    const Vector3d offset = Vector3d(-s * 0.35, -1.0, 0.0).normalized() * (requested.rmax + 5.0 + radius);
    const Vector3d along = Vector3d(-s * 0.15, 0.0, 1.0).normalized();
    const Vector3d at = requested.center + offset;
    a.vessel = Cylinder{at - 400.0 * along, at + 400.0 * along, radius};
  }
  if (o.cancellous_variation_hu > 0) a.wave_phase = Vector3d(uniform(0, 2 * M_PI), uniform(0, 2 * M_PI), uniform(0, 2 * M_PI));

  // The grid: head, socket and pelvis medially, neck and shaft laterally.
  // Lateral 60 mm (more for heads above 25 mm, whose necks are longer),
  // medial 80 mm: a single head lies on its side of the grid's centre.
  Vector3d lo = Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const HipAnatomy& h : a.hips) {
    const double s = h.truth.right ? -1.0 : 1.0;
    const double lateral = 60.0 + std::max(0.0, 1.9 * (h.r0 - 25.0) * 0.8);
    const Vector3d c = h.center;
    lo = lo.cwiseMin(Vector3d(std::min(c[0] + s * lateral, c[0] - s * 80.0), c[1] - 55.0, c[2] - 75.0));
    hi = hi.cwiseMax(Vector3d(std::max(c[0] + s * lateral, c[0] - s * 80.0), c[1] + 55.0, c[2] + 50.0));
  }
  if (o.both_hips) {
    // A pelvis-like frame: each socket joins the sacrum by an ilium (superior,
    // posterior) and the pubic symphysis by a pubic ramus (medial, anterior).
    const Vector3d mid = 0.5 * (a.hips[0].center + a.hips[1].center);
    a.pelvis_blocks.push_back({Vector3d(0, mid[1] + 65.0, mid[2] + 30.0), Vector3d(40, 15, 45)});  // sacrum
    a.pelvis_blocks.push_back({Vector3d(0, mid[1] - 45.0, mid[2] - 20.0), Vector3d(9, 8, 22)});    // symphysis
    for (const HipAnatomy& h : a.hips) {
      const double s = h.truth.right ? -1.0 : 1.0;
      const double at = h.rmax + o.gap_mm + 0.6 * o.socket_wall_mm;
      a.pelvis_bars.push_back({h.center + at * Vector3d(0, 0.3, 1).normalized(),
                               Vector3d(s * 38.0, mid[1] + 58.0, mid[2] + 45.0), 12.0});  // ilium
      a.pelvis_bars.push_back({h.center + at * Vector3d(-s * 0.85, -0.45, -0.2).normalized(),
                               Vector3d(s * 6.0, mid[1] - 45.0, mid[2] - 20.0), 8.0});   // pubic ramus
    }
    hi[1] = std::max(hi[1], mid[1] + 82.0);
  }
  if (o.table) {
    // The table's trough 5 mm beyond the field's back, under the body's
    // middle (x = 0), rising towards the sides; the grid holds it and 15 mm of air.
    a.table_axis = Eigen::Vector2d(0.0, hi[1] + 5.0 - a.table_radius);
    hi[1] += 5.0 + a.table_thickness + 15.0;
  }
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
  std::optional<FovCrop> crop;
  if (o.fov_cut >= 0) crop = planFovCrop(o, a.hips[0], g);

  Phantom out;
  for (const HipAnatomy& h : a.hips) out.hips.push_back(h.truth);
  out.head = out.hips[0].head;
  out.neck_axis = out.hips[0].neck_axis;
  if (o.slice_thickness_mm > g.spacing[2]) {
    renderThickSlices(a, g, o.slice_thickness_mm, out.ct, out.femur);
    out.ct.geometry.slice_thickness_mm = o.slice_thickness_mm;  // its DICOM states it
  } else {
    render(a, g, out.ct, out.femur);
  }
  detail::blur(out.ct, Vector3d::Constant(o.blur_mm));
  if (!a.metal.empty())
    detail::addMetalStreaks(out.ct, [&a](const Vector3d& x) { return a.metalDepth(x) > 0; }, o.seed ^ 0x3e7a1c5ULL);
  std::normal_distribution<double> noise(0.0, o.noise_hu);
  if (o.noise_hu > 0)
    for (float& v : out.ct.voxels) v += static_cast<float>(noise(rng));
  // The kernel filters the tissues and their noise together, within the slices.
  if (o.kernel == PhantomOptions::Kernel::Soft) detail::blur(out.ct, Vector3d(0.6, 0.6, 0.0));
  if (o.kernel == PhantomOptions::Kernel::Sharp) detail::sharpenInPlane(out.ct, 0.8, 1.0);
  if (!a.metal.empty() || a.table_axis) detail::clipToScannerRange(out.ct);
  if (crop) applyFovCrop(*crop, out);

  // Top level: the requested side's head, as in the single-hip phantom; `hips`: every head.
  out.truth = hipTruth(out.hips[0], o);
  out.truth["hips"] = nlohmann::json::array();
  for (const Hip& h : out.hips) out.truth["hips"].push_back(hipTruth(h, o));
  out.truth.update({
      {"coordinate_system", "LPS"},
      {"units", "mm"},
      {"seed", o.seed},
      {"joint", "hip"},
      {"both_hips", o.both_hips},
      {"joint_gap_mm", o.gap_mm},
      {"cortical_mm", o.cortical_mm},
      {"hu",
       {{"cortical", o.cortical_hu},
        {"cancellous", o.cancellous_hu},
        {"cancellous_variation", o.cancellous_variation_hu},
        {"soft_tissue", o.soft_tissue_hu},
        {"socket_cortical", o.socket_cortical_hu.value_or(o.cortical_hu)},
        {"socket_cancellous", o.socket_cancellous_hu.value_or(o.cancellous_hu)}}},
      {"noise_hu", o.noise_hu},
      {"blur_mm", o.blur_mm},
      {"grid",
       {{"size", {out.ct.geometry.size[0], out.ct.geometry.size[1], out.ct.geometry.size[2]}},
        {"spacing_mm", vec(g.spacing)},
        {"origin_mm", vec(out.ct.geometry.origin)},
        {"direction_row_major",
         {g.direction(0, 0), g.direction(0, 1), g.direction(0, 2), g.direction(1, 0), g.direction(1, 1),
          g.direction(1, 2), g.direction(2, 0), g.direction(2, 1), g.direction(2, 2)}}}},
  });
  if (!a.metal.empty()) {
    const Cylinder& m = a.metal.front();
    out.truth["metal"] = {{"kind", o.metal == PhantomOptions::Metal::Screw ? "screw" : "stem"},
                          {"from_mm", vec(m.a)},
                          {"to_mm", vec(m.b)},
                          {"radius_mm", m.radius},
                          {"hu", o.metal_hu},
                          {"clipped_to_hu", {-1024, 3071}}};
  }
  if (o.kernel != PhantomOptions::Kernel::Standard) out.truth["kernel"] = o.kernel == PhantomOptions::Kernel::Soft ? "soft" : "sharp";
  if (o.slice_thickness_mm > g.spacing[2]) out.truth["slice_thickness_mm"] = o.slice_thickness_mm;
  if (a.vessel)
    out.truth["contrast_vessel"] = {{"point_mm", vec(0.5 * (a.vessel->a + a.vessel->b))},
                                    {"direction", vec((a.vessel->b - a.vessel->a).normalized())},
                                    {"radius_mm", a.vessel->radius},
                                    {"hu", o.vessel_hu}};
  if (a.table_axis)
    out.truth["table"] = {{"axis_xy_mm", {(*a.table_axis)[0], (*a.table_axis)[1]}},
                          {"radius_mm", a.table_radius},
                          {"thickness_mm", a.table_thickness},
                          {"hu", a.table_hu},
                          {"air_hu", a.air_hu}};
  if (crop) {
    const double beyond = crop->head_extent - crop->plane;
    out.truth["fov_cut"] = {{"face", vec(crop->u)},
                            {"fraction_of_radius", beyond / crop->r0},
                            {"head_beyond_mm", beyond},
                            {"radius_mm", crop->r0},
                            {"plane_mm", crop->plane},
                            {"head_extent_mm", crop->head_extent}};
  }
  return out;
}

}  // namespace articula::phantom
