#include "arthritis.hpp"

#include "surface_search.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>

#include <Eigen/Geometry>


namespace articula::phantom {

using Eigen::Vector3d;

double Osteophytes::distance(const Vector3d& x) const {
  double nearest = std::numeric_limits<double>::infinity();
  for (size_t n = 0; n + 1 < path.size(); ++n) {
    const Vector3d a = path[n], ab = path[n + 1] - a;
    const double t = std::clamp((x - a).dot(ab) / std::max(ab.squaredNorm(), 1e-18), 0.0, 1.0);
    nearest = std::min(nearest, (x - a - t * ab).norm());
  }
  return nearest - radius_mm;
}

double NarrowGap::weight(const Vector3d& from_head_centre) const {
  const double norm = from_head_centre.norm();
  if (norm < 1e-12) return 0.0;
  const double deg = std::acos(std::clamp(from_head_centre.dot(direction) / norm, -1.0, 1.0)) * 180.0 / M_PI;
  if (deg <= full_deg) return 1.0;
  if (deg >= end_deg) return 0.0;
  return 0.5 * (1.0 + std::cos(M_PI * (deg - full_deg) / (end_deg - full_deg)));
}

namespace detail {
namespace {

nlohmann::json vec(const Vector3d& v) { return {v[0], v[1], v[2]}; }
Vector3d vec3(const nlohmann::json& j) { return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()}; }

}  // namespace

void addArthritis(const PhantomOptions& o, const geometry::PosedSurface& head, double r0, double neck_radius, Hip& hip) {
  const Vector3d c = hip.head.center;
  const double rmax = hip.head.radii.maxCoeff(), reach = 2.0 * rmax;
  const Inside model = [&head](const Vector3d& x) { return head.value(x) < 0; };
  const Vector3d superior = Vector3d::UnitZ();  // LPS: +z; the hip's weight-bearing direction
  std::mt19937_64 rng(o.seed ^ 0xa7541715ULL);
  const auto uniform = [&rng](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };

  if (o.flattened_dome > 0) {
    FlatDome f;
    f.normal = superior;
    f.top = support(model, c, superior, reach);
    f.fraction = o.flattened_dome;
    f.depth_mm = o.flattened_dome * r0;
    f.point = f.top - f.depth_mm * superior;
    // Surface points beyond the plane lie within acos(height / rmax) of the normal.
    const double height = (f.point - c).dot(superior);
    f.area_mm2 = modelArea(head, c, reach, superior, height / rmax - 1e-3,
                           [&f](const Vector3d& q) { return (q - f.point).dot(f.normal) > 0; });
    hip.flat_dome = f;
  }

  if (o.osteophytes_mm > 0) {
    // The head-neck junction: on each half-plane through the neck axis, the
    // model surface point at the neck's radius from the axis; the lip runs
    // along it over 150 degrees of the superior side (centred within +-30).
    const Vector3d a = hip.neck_axis;
    const Vector3d e1 = (superior - superior.dot(a) * a).normalized(), e2 = a.cross(e1);
    const double middle = uniform(-30.0, 30.0) * M_PI / 180.0;
    Osteophytes lip;
    lip.radius_mm = o.osteophytes_mm;
    constexpr int kPathPoints = 31;
    for (int k = 0; k < kPathPoints; ++k) {
      const double phi = middle + (-75.0 + 150.0 * k / (kPathPoints - 1)) * M_PI / 180.0;
      const Vector3d radial = std::cos(phi) * e1 + std::sin(phi) * e2;
      const auto direction = [&](double theta) { return Vector3d(std::cos(theta) * a + std::sin(theta) * radial); };
      double lo = 0.05, hi = 0.5 * M_PI;  // t(theta) sin(theta) grows from the axis outwards
      for (int n = 0; n < 60; ++n) {
        const double mid = 0.5 * (lo + hi);
        (along(model, c, direction(mid), reach) * std::sin(mid) < neck_radius ? lo : hi) = mid;
      }
      const Vector3d d = direction(0.5 * (lo + hi));
      lip.path.push_back(c + along(model, c, d, reach) * d);
    }
    Vector3d axis = Vector3d::Zero();
    for (const Vector3d& p : lip.path) axis += (p - c).normalized();
    axis.normalize();
    double widest = 0;
    for (const Vector3d& p : lip.path) widest = std::max(widest, std::acos(std::clamp((p - c).normalized().dot(axis), -1.0, 1.0)));
    const double margin = std::asin(std::min(1.0, lip.radius_mm / hip.head.radii.minCoeff())) + 0.05;
    lip.area_mm2 = modelArea(head, c, reach, axis, std::cos(std::min(M_PI, widest + margin)),
                             [&lip](const Vector3d& q) { return lip.distance(q) < 0; });
    hip.osteophytes = lip;
  }

  if (o.cysts) {
    // Three cysts, 2-5 mm across, under the cortex within 40 degrees of
    // superior (the weight-bearing zone), their walls 0.3 mm below it.
    const Vector3d e1 = perpendicular(superior), e2 = superior.cross(e1);
    const Inside bone = [&hip, &head](const Vector3d& x) {
      const geometry::Evaluation e = head.evaluate(x, 1);
      return headSurfaceDistance(hip, e.value / std::max(e.gradient.norm(), 1e-9), x) < 0;
    };
    for (int n = 0; n < 3; ++n) {
      const double cos_t = uniform(std::cos(40.0 * M_PI / 180.0), 1.0), phi = uniform(0.0, 2.0 * M_PI);
      const double sin_t = std::sqrt(1.0 - cos_t * cos_t);
      const Vector3d d = cos_t * superior + sin_t * (std::cos(phi) * e1 + std::sin(phi) * e2);
      const double radius = uniform(1.0, 2.5);
      const Vector3d q = c + along(bone, c, d, reach) * d;
      // The surface's normal there: the cut's plane or the head's.
      const bool on_cut = hip.flat_dome && std::abs((q - hip.flat_dome->point).dot(hip.flat_dome->normal)) < 1e-6;
      const Vector3d normal = on_cut ? hip.flat_dome->normal : head.evaluate(q, 1).gradient.normalized();
      const double depth = o.cortical_mm + radius + 0.3;
      hip.cysts.push_back({q - depth / std::max(normal.dot(d), 0.3) * d, radius});
    }
  }

  if (o.narrow_gap_mm > 0) {
    NarrowGap g;
    g.direction = superior;
    g.centre = c + along(model, c, superior, reach) * superior;
    g.gap_mm = o.narrow_gap_mm;
    const auto within = [&](double deg) {
      return modelArea(head, c, reach, superior, std::cos(deg * M_PI / 180.0),
                       [](const Vector3d&) { return true; });
    };
    g.area_mm2 = within(g.end_deg);
    g.full_area_mm2 = within(g.full_deg);
    hip.narrow_gap = g;
  }
}

nlohmann::json departuresJson(const Hip& hip, const PhantomOptions& o) {
  nlohmann::json out = nlohmann::json::array();
  const Vector3d c = hip.head.center;
  if (hip.flat_dome) {
    const FlatDome& f = *hip.flat_dome;
    out.push_back({{"kind", "flattened_dome"},
                   {"surface_change", "inward"},
                   {"area_mm2", f.area_mm2},
                   {"max_depth_mm", f.depth_mm},
                   {"centre_mm", vec(f.top)},
                   {"direction", vec((f.top - c).normalized())},
                   {"fraction_of_radius", f.fraction},
                   {"plane", {{"point_mm", vec(f.point)}, {"normal", vec(f.normal)}}}});
  }
  if (hip.osteophytes) {
    const Osteophytes& lip = *hip.osteophytes;
    const Vector3d middle = lip.path[lip.path.size() / 2];
    nlohmann::json path = nlohmann::json::array();
    for (const Vector3d& p : lip.path) path.push_back(vec(p));
    out.push_back({{"kind", "osteophytes"},
                   {"surface_change", "outward"},
                   {"area_mm2", lip.area_mm2},
                   {"max_depth_mm", lip.radius_mm},
                   {"centre_mm", vec(middle)},
                   {"direction", vec((middle - c).normalized())},
                   {"radius_mm", lip.radius_mm},
                   {"path_mm", path}});
  }
  if (!hip.cysts.empty()) {
    nlohmann::json cysts = nlohmann::json::array();
    Vector3d centroid = Vector3d::Zero();
    double area = 0;
    for (const Cyst& cyst : hip.cysts) {
      cysts.push_back({{"center_mm", vec(cyst.center)}, {"radius_mm", cyst.radius_mm}});
      centroid += cyst.center / static_cast<double>(hip.cysts.size());
      area += M_PI * cyst.radius_mm * cyst.radius_mm;
    }
    out.push_back({{"kind", "cysts"},
                   {"surface_change", "none"},
                   {"area_mm2", area},
                   {"max_depth_mm", 0.0},
                   {"centre_mm", vec(centroid)},
                   {"direction", vec((centroid - c).normalized())},
                   {"hu", o.cyst_hu},
                   {"cysts", cysts}});
  }
  if (hip.narrow_gap) {
    const NarrowGap& g = *hip.narrow_gap;
    out.push_back({{"kind", "narrow_gap"},
                   {"surface_change", "none"},
                   {"area_mm2", g.area_mm2},
                   {"full_area_mm2", g.full_area_mm2},
                   {"max_depth_mm", 0.0},
                   {"centre_mm", vec(g.centre)},
                   {"direction", vec(g.direction)},
                   {"gap_mm", g.gap_mm},
                   {"joint_gap_mm", o.gap_mm},
                   {"full_deg", g.full_deg},
                   {"end_deg", g.end_deg}});
  }
  return out;
}

void departuresFromJson(const nlohmann::json& departures, Hip& hip) {
  for (const nlohmann::json& d : departures) {
    const std::string kind = d.at("kind").get<std::string>();
    if (kind == "flattened_dome") {
      FlatDome f;
      f.point = vec3(d["plane"]["point_mm"]);
      f.normal = vec3(d["plane"]["normal"]);
      f.top = vec3(d["centre_mm"]);
      f.fraction = d["fraction_of_radius"].get<double>();
      f.depth_mm = d["max_depth_mm"].get<double>();
      f.area_mm2 = d["area_mm2"].get<double>();
      hip.flat_dome = f;
    } else if (kind == "osteophytes") {
      Osteophytes lip;
      for (const nlohmann::json& p : d["path_mm"]) lip.path.push_back(vec3(p));
      lip.radius_mm = d["radius_mm"].get<double>();
      lip.area_mm2 = d["area_mm2"].get<double>();
      hip.osteophytes = lip;
    } else if (kind == "cysts") {
      for (const nlohmann::json& cyst : d["cysts"]) hip.cysts.push_back({vec3(cyst["center_mm"]), cyst["radius_mm"].get<double>()});
    } else if (kind == "narrow_gap") {
      NarrowGap g;
      g.direction = vec3(d["direction"]);
      g.centre = vec3(d["centre_mm"]);
      g.gap_mm = d["gap_mm"].get<double>();
      g.full_deg = d["full_deg"].get<double>();
      g.end_deg = d["end_deg"].get<double>();
      g.area_mm2 = d["area_mm2"].get<double>();
      g.full_area_mm2 = d["full_area_mm2"].get<double>();
      hip.narrow_gap = g;
    }
  }
}

}  // namespace detail
}  // namespace articula::phantom
