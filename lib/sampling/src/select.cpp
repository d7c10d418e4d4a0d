#include "articula/sampling/select.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <sstream>

#include <Eigen/Dense>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Random.h>
#include <CGAL/version.h>
#include <CGAL/Shape_detection/Efficient_RANSAC.h>
#include <CGAL/property_map.h>

#include "articula/core/error.hpp"
#include "articula/core/log.hpp"
#include "articula/distance/signed_distance.hpp"
#include "articula/geometry/algebraic_fit.hpp"
#include "articula/geometry/pose.hpp"
#include "articula/geometry/mesh_components.hpp"
#include "articula/geometry/sphere_fit.hpp"

namespace articula::sampling {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using PointWithNormal = std::pair<Kernel::Point_3, Kernel::Vector_3>;
using Traits = CGAL::Shape_detection::Efficient_RANSAC_traits<Kernel, std::vector<PointWithNormal>,
                                                              CGAL::First_of_pair_property_map<PointWithNormal>,
                                                              CGAL::Second_of_pair_property_map<PointWithNormal>>;
using Ransac = CGAL::Shape_detection::Efficient_RANSAC<Traits>;
using RansacSphere = CGAL::Shape_detection::Sphere<Traits>;

/// The largest connected patch of `chosen` vertices, connected through triangle edges.
std::vector<int> largestPatch(const std::vector<char>& chosen, const Eigen::MatrixX3i& F) {
  const std::vector<int> part = geometry::connectedParts(chosen, F);
  std::vector<int> size(chosen.size(), 0);
  for (int p : part)
    if (p >= 0) ++size[static_cast<size_t>(p)];
  const int best = static_cast<int>(std::max_element(size.begin(), size.end()) - size.begin());
  std::vector<int> out;
  for (size_t v = 0; v < part.size(); ++v)
    if (part[v] == best) out.push_back(static_cast<int>(v));
  return out;
}

Eigen::MatrixX3d rowsOf(const Eigen::MatrixX3d& V, const std::vector<int>& rows) {
  Eigen::MatrixX3d P(static_cast<Eigen::Index>(rows.size()), 3);
  for (size_t i = 0; i < rows.size(); ++i) P.row(static_cast<Eigen::Index>(i)) = V.row(rows[i]);
  return P;
}

/// The least-squares sphere of the selection's vertices and their RMS about it.
void fitPatchSphere(const Eigen::MatrixX3d& V, Selection& patch) {
  const Eigen::MatrixX3d P = rowsOf(V, patch.indices);
  const geometry::Sphere sphere = geometry::fitSphere(P);
  patch.sphere_center = sphere.center;
  patch.sphere_radius = sphere.radius;
  patch.sphere_rms_mm = std::sqrt(
      ((P.rowwise() - patch.sphere_center.transpose()).rowwise().norm().array() - patch.sphere_radius).square().mean());
}

// Heads are not spheres (radii differ by up to about 10 %): a band around a
// sphere wide enough to hold such a cap also holds the first millimetre of
// the neck, the fovea's rim and the socket-side bulges of a coarse CT. The
// last pass therefore bands the patch's own ellipsoid (ellipsoid-specific
// algebraic fit, exact distances) at the surface's own scatter: three robust
// standard deviations of the patch's distances, between kMinEllipsoidBandMm
// and the sphere's band. The vertices' normals must still lie within the
// tolerance of the ellipsoid's normal.
constexpr double kMinEllipsoidBandMm = 0.4;

// The head is convex; the head-neck junction, the fovea's pit and a cyst's
// or a dent's rim are not. The bands above reach into the junction by up to
// a band's width (on the robustness matrix the articular points' error to
// the true surface was 0.2-0.6 mm RMS beyond 120 degrees from the cap's
// axis, 0.1-0.2 within), and a richer model bends to follow it. The chosen
// patch therefore keeps only the vertices where the surface, seen at
// kCurvatureScaleMm (a few voxels: a coarse CT's mesh is rough at one), is
// not concave: its mean curvature is positive. A model's flattest part
// (a superellipsoid's face) has low but positive curvature and stays.
constexpr double kCurvatureScaleMm = 3.0;

/// The mean curvature of the vertices `at` (NaN elsewhere) seen at
/// `scale_mm`: the mean over a vertex's mesh neighbours between half the
/// scale and the scale (reached through edges)
/// of 2 (x_v - x_w) . n_v / |x_w - x_v|^2, which is 1/R on a sphere of radius
/// R with outward normals and negative where the surface curves inwards;
/// then averaged over the same neighbourhood once more. Hand-written: VTK's
/// vtkCurvatures measures at one ring, where a CT's mesh is rough, and CGAL's
/// jet fitting (Monge_via_jet_fitting) fits a local surface per vertex; only
/// the sign of the mean curvature at one scale is needed, which the
/// neighbours' sag gives.
std::vector<double> meanCurvatureAtScale(const Eigen::MatrixX3d& V, const Eigen::MatrixX3d& N, const Eigen::MatrixX3i& F,
                                         const std::vector<int>& at, double scale_mm) {
  const Eigen::Index n = V.rows();
  std::vector<std::vector<int>> adjacent(static_cast<size_t>(n));
  for (Eigen::Index t = 0; t < F.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      adjacent[static_cast<size_t>(F(t, k))].push_back(F(t, (k + 1) % 3));
      adjacent[static_cast<size_t>(F(t, (k + 1) % 3))].push_back(F(t, k));
    }
  // Calls visit(w, x_v - x_w) for every vertex w within scale_mm of v that
  // edges reach without leaving that ball (v itself included).
  std::vector<long long> seen(static_cast<size_t>(n), -1);
  long long visit_id = 0;
  std::vector<int> todo;
  const double reach2 = scale_mm * scale_mm;
  const auto forNeighbourhood = [&](Eigen::Index v, const auto& visit) {
    const Eigen::Vector3d x = V.row(v).transpose();
    ++visit_id;
    todo.assign(1, static_cast<int>(v));
    seen[static_cast<size_t>(v)] = visit_id;
    while (!todo.empty()) {
      const int w = todo.back();
      todo.pop_back();
      visit(w, Eigen::Vector3d(x - V.row(w).transpose()));
      for (int u : adjacent[static_cast<size_t>(w)])
        if (seen[static_cast<size_t>(u)] != visit_id && (V.row(u).transpose() - x).squaredNorm() <= reach2)
          seen[static_cast<size_t>(u)] = visit_id, todo.push_back(u);
    }
  };
  // The sag-based curvature of the vertices the average reaches, each
  // computed once, when first needed (the patch is part of the mesh).
  std::vector<double> raw(static_cast<size_t>(n), NAN), smooth(static_cast<size_t>(n), NAN);
  std::vector<int> reached;
  for (int v : at)
    forNeighbourhood(v, [&](int w, const Eigen::Vector3d&) { reached.push_back(w); });
  std::sort(reached.begin(), reached.end());
  reached.erase(std::unique(reached.begin(), reached.end()), reached.end());
  for (int v : reached) {
    const Eigen::Vector3d normal = N.row(v).transpose();
    double sum = 0;
    int count = 0;
    forNeighbourhood(v, [&](int, const Eigen::Vector3d& d) {
      const double d2 = d.squaredNorm();
      if (d2 >= 0.25 * reach2) sum += 2 * d.dot(normal) / d2, ++count;
    });
    if (count > 0) raw[static_cast<size_t>(v)] = sum / count;
  }
  for (int v : at) {
    double sum = 0;
    int count = 0;
    forNeighbourhood(v, [&](int w, const Eigen::Vector3d&) {
      if (!std::isnan(raw[static_cast<size_t>(w)])) sum += raw[static_cast<size_t>(w)], ++count;
    });
    if (count > 0) smooth[static_cast<size_t>(v)] = sum / count;
  }
  return smooth;
}

/// The vertices within the patch's ellipsoid band, as the largest connected
/// patch; `patch` unchanged when no ellipsoid fits it (degenerate or flat).
std::vector<int> ellipsoidBand(const Eigen::MatrixX3d& V, const Eigen::MatrixX3d& N, const Eigen::MatrixX3i& F,
                               const std::vector<int>& patch, double band_mm, double cos_tol) {
  geometry::ShapeParameters ellipsoid;
  std::optional<distance::SignedDistance> fitted;
  try {
    ellipsoid = geometry::algebraicEllipsoid(rowsOf(V, patch));
    if (!(ellipsoid.radii.maxCoeff() < 4 * ellipsoid.radii.minCoeff())) return patch;  // not a head's shape
    fitted.emplace(ellipsoid);
  } catch (const Error&) {
    return patch;
  }
  const distance::SignedDistance& exact = *fitted;
  std::vector<double> scatter;
  scatter.reserve(patch.size());
  for (int v : patch) scatter.push_back(std::fabs(exact.closest(V.row(v).transpose()).distance));
  std::nth_element(scatter.begin(), scatter.begin() + static_cast<long>(scatter.size() / 2), scatter.end());
  const double robust_sd = 1.4826 * scatter[scatter.size() / 2];
  const double band = std::clamp(3.0 * robust_sd, kMinEllipsoidBandMm, band_mm);
  const Eigen::Matrix3d R = geometry::rotationFromAngles(ellipsoid.angles);
  const Eigen::Vector3d inverse_square = ellipsoid.radii.cwiseProduct(ellipsoid.radii).cwiseInverse();
  const double reach = ellipsoid.radii.maxCoeff() + band_mm;
  std::vector<char> chosen(static_cast<size_t>(V.rows()), 0);
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    const Eigen::Vector3d x = V.row(v).transpose();
    if ((x - ellipsoid.center).norm() > reach) continue;
    const Eigen::Vector3d local = R.transpose() * (x - ellipsoid.center);
    const Eigen::Vector3d normal = (R * local.cwiseProduct(inverse_square)).normalized();
    chosen[static_cast<size_t>(v)] =
        N.row(v).dot(normal) >= cos_tol && std::fabs(exact.closest(x).distance) <= band;
  }
  std::vector<int> out = largestPatch(chosen, F);
  std::ostringstream m;
  m << "ellipsoid band " << band << " mm: " << patch.size() << " -> " << out.size() << " vertices";
  log::debug(m.str());
  return out;
}

std::vector<double> parseNumbers(const std::string& text, const std::string& what) {
  std::vector<double> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      size_t used = 0;
      out.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw UsageError("--select " + what + ": expected numbers, found '" + item + "'");
    }
  }
  return out;
}

}  // namespace

void SelectOptions::validate() const {
  if (mode == Mode::Sphere && !(radius > 0)) throw UsageError("--select sphere: the radius must be > 0");
  if (mode == Mode::Box && (box_max.array() <= box_min.array()).any())
    throw UsageError("--select box: expected XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX with min < max");
  // Joint heads are 15-35 mm in radius; 200 mm and a 50 mm band leave room
  // for any anatomy while keeping RANSAC's search bounded.
  if (!(min_radius_mm > 0 && min_radius_mm < max_radius_mm && max_radius_mm <= 200))
    throw UsageError("--min-radius/--max-radius: expected 0 < min < max <= 200 mm, found " + std::to_string(min_radius_mm) +
                     " and " + std::to_string(max_radius_mm));
  if (!(band_mm > 0 && band_mm <= 50)) throw UsageError("--band: expected a band in (0, 50] mm, found " + std::to_string(band_mm));
  if (mode == Mode::Sphere && !(radius <= 1e5 && center.allFinite()))
    throw UsageError("--select sphere: expected a finite centre and a radius up to 1e5 mm");
  if (!(normal_deg > 0 && normal_deg <= 90)) throw UsageError("normal tolerance must be in (0, 90] degrees");
  if (min_points < 1) throw UsageError("minimum selected points must be >= 1");
}

void parseSelection(const std::string& text, SelectOptions& o) {
  if (text == "auto") {
    o.mode = SelectOptions::Mode::Auto;
  } else if (text.rfind("sphere:", 0) == 0) {
    const auto v = parseNumbers(text.substr(7), "sphere");
    if (v.size() != 4) throw UsageError("--select sphere:X,Y,Z,R: expected 4 numbers, found " + std::to_string(v.size()));
    o.mode = SelectOptions::Mode::Sphere;
    o.center = Eigen::Vector3d(v[0], v[1], v[2]);
    o.radius = v[3];
  } else if (text.rfind("box:", 0) == 0) {
    const auto v = parseNumbers(text.substr(4), "box");
    if (v.size() != 6) throw UsageError("--select box:XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX: expected 6 numbers, found " + std::to_string(v.size()));
    o.mode = SelectOptions::Mode::Box;
    o.box_min = Eigen::Vector3d(v[0], v[1], v[2]);
    o.box_max = Eigen::Vector3d(v[3], v[4], v[5]);
  } else {
    throw UsageError("--select: expected auto, sphere:X,Y,Z,R or box:XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX, found '" + text + "'");
  }
  o.validate();
}

Selection selectArticular(const Eigen::MatrixX3d& V, const Eigen::MatrixX3d& N, const Eigen::MatrixX3i& F,
                          const SelectOptions& o, const std::vector<unsigned char>& cut_through_bone) {
  o.validate();
  Selection sel;
  const Eigen::Index n = V.rows();
  if (o.mode == SelectOptions::Mode::Sphere || o.mode == SelectOptions::Mode::Box) {
    for (Eigen::Index v = 0; v < n; ++v) {
      const Eigen::Vector3d x = V.row(v).transpose();
      const bool in = o.mode == SelectOptions::Mode::Sphere
                          ? (x - o.center).norm() <= o.radius
                          : (x.array() >= o.box_min.array()).all() && (x.array() <= o.box_max.array()).all();
      if (in) sel.indices.push_back(static_cast<int>(v));
    }
  } else {
    if (N.rows() != n) throw InputError("--select auto needs vertex normals; the mesh has none");
    std::vector<PointWithNormal> points;
    points.reserve(static_cast<size_t>(n));
    for (Eigen::Index v = 0; v < n; ++v)
      points.emplace_back(Kernel::Point_3(V(v, 0), V(v, 1), V(v, 2)), Kernel::Vector_3(N(v, 0), N(v, 1), N(v, 2)));
    CGAL::get_default_random() = CGAL::Random(static_cast<unsigned>(o.seed));  // reproducible sampling
    Ransac ransac;
    ransac.set_input(points);
    ransac.add_shape_factory<RansacSphere>();
    Ransac::Parameters parameters;
    parameters.probability = 0.01;
    parameters.min_points = static_cast<std::size_t>(std::max<Eigen::Index>(50, n / 50));
    parameters.epsilon = o.band_mm;
    parameters.cluster_epsilon = 3.0 * o.band_mm;
    parameters.normal_threshold = std::cos(o.normal_deg * M_PI / 180.0);
    ransac.detect(parameters);
    // Every plausible RANSAC sphere is grown into its patch: the band around
    // it with radial normals, the largest connected part, then once more
    // around the least-squares sphere of that patch. The largest final patch
    // is the articular surface (RANSAC's own point count favours whichever
    // sphere it met first on a rough, clipped head).
    const double cos_tol = std::cos(o.normal_deg * M_PI / 180.0);
    auto grow = [&](Selection patch) {
      for (int pass = 0; pass < 2; ++pass) {
        std::vector<char> chosen(static_cast<size_t>(n), 0);
        for (Eigen::Index v = 0; v < n; ++v) {
          const Eigen::Vector3d d = V.row(v).transpose() - patch.sphere_center;
          const double r = d.norm();
          chosen[static_cast<size_t>(v)] =
              std::fabs(r - patch.sphere_radius) <= o.band_mm && N.row(v).dot(d.transpose()) >= cos_tol * r;
        }
        patch.indices = largestPatch(chosen, F);
        if (static_cast<int>(patch.indices.size()) < std::max(o.min_points, 4)) break;
        fitPatchSphere(V, patch);
      }
      if (static_cast<int>(patch.indices.size()) >= std::max(o.min_points, 10)) {
        std::vector<int> banded = ellipsoidBand(V, N, F, patch.indices, o.band_mm, cos_tol);
        if (static_cast<int>(banded.size()) >= std::max(o.min_points, 10)) {
          patch.indices = std::move(banded);
          fitPatchSphere(V, patch);
        }
      }
      return patch;
    };
    for (const auto& shape : ransac.shapes()) {
      const auto* sphere = dynamic_cast<const RansacSphere*>(shape.get());
      if (!sphere) continue;
      const double r = sphere->radius();
      if (r < o.min_radius_mm || r > o.max_radius_mm) continue;
      ++sel.ransac_spheres;
      Selection start;
      start.sphere_center = Eigen::Vector3d(sphere->center().x(), sphere->center().y(), sphere->center().z());
      start.sphere_radius = r;
      const Selection patch = grow(start);
      std::ostringstream m;
      m << "RANSAC sphere (" << start.sphere_center.transpose() << ") mm, radius " << r << " mm ("
        << shape->indices_of_assigned_points().size() << " points) -> patch of " << patch.indices.size()
        << " vertices, radius " << patch.sphere_radius << " mm";
      log::debug(m.str());
      if (patch.indices.size() > sel.indices.size()) {
        const int found = sel.ransac_spheres;
        sel = patch;
        sel.ransac_spheres = found;
      }
    }
    // Trimmed after the choice among the spheres' patches, which stays on
    // their bands' sizes: trimmed first, a neighbouring sphere's patch with
    // less of the junction could outgrow the head's own.
    if (static_cast<int>(sel.indices.size()) >= std::max(o.min_points, 10)) {
      const std::vector<double> curvature = meanCurvatureAtScale(V, N, F, sel.indices, kCurvatureScaleMm);
      std::vector<char> convex(static_cast<size_t>(n), 0);
      for (int v : sel.indices) convex[static_cast<size_t>(v)] = curvature[static_cast<size_t>(v)] > 0;
      std::vector<int> kept = largestPatch(convex, F);
      std::ostringstream m;
      m << "convex part of the patch: " << sel.indices.size() << " -> " << kept.size() << " vertices";
      log::debug(m.str());
      if (static_cast<int>(kept.size()) >= std::max(o.min_points, 10)) {
        sel.concave_left_out = static_cast<int>(sel.indices.size() - kept.size());
        sel.indices = std::move(kept);
        fitPatchSphere(V, sel);
      }
    }
    if (sel.ransac_spheres == 0) {
      std::ostringstream m;
      m << "no joint head found: RANSAC found no sphere of radius " << o.min_radius_mm << "-" << o.max_radius_mm
        << " mm on the mesh (" << n << " vertices); select the region by hand with --select sphere:X,Y,Z,R";
      throw ProcessingError(m.str());
    }
  }
  // Where the label ends inside bone (the mesh's marks: the cut between
  // head and neck, about a head's radius from its centre with normals along
  // the neck), the band and the normals' test pass; such a vertex is no
  // articular point. Where fewer than min_points vertices would remain (a
  // coarse CT that shows few edges), all stay, counted.
  if (cut_through_bone.size() == static_cast<size_t>(n)) {
    std::vector<int> kept;
    for (int v : sel.indices)
      if (cut_through_bone[static_cast<size_t>(v)] == 0) kept.push_back(v);
    const int cut = static_cast<int>(sel.indices.size() - kept.size());
    if (static_cast<int>(kept.size()) >= o.min_points) {
      sel.indices = std::move(kept);
      sel.cut_through_bone_left_out = cut;
      if (o.mode == SelectOptions::Mode::Auto) fitPatchSphere(V, sel);
    } else {
      sel.cut_through_bone_kept = cut;
    }
  }
  if (static_cast<int>(sel.indices.size()) < o.min_points)
    throw InputError("the selection holds " + std::to_string(sel.indices.size()) + " points; expected at least " +
                     std::to_string(o.min_points) + " to fit a surface");
  return sel;
}

#define ARTICULA_STRINGIFY_VALUE(x) ARTICULA_STRINGIFY(x)
#define ARTICULA_STRINGIFY(x) #x
std::string cgalVersion() { return ARTICULA_STRINGIFY_VALUE(CGAL_VERSION); }  // CGAL_VERSION is a bare 5.5.1

}  // namespace articula::sampling
