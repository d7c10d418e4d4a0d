#include "articula/mesh/mesh.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>

#include <vtkCellArray.h>
#include <vtkCleanPolyData.h>
#include <vtkFlyingEdges3D.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkMatrix3x3.h>
#include <vtkNew.h>
#include <vtkPLYWriter.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataConnectivityFilter.h>
#include <vtkPolyDataNormals.h>
#include <vtkQuadricDecimation.h>
#include <vtkSTLWriter.h>
#include <vtkSmartPointer.h>
#include <vtkSmoothPolyDataFilter.h>
#include <vtkStringArray.h>
#include <vtkFieldData.h>
#include <vtkDoubleArray.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowedSincPolyDataFilter.h>
#include <vtkXMLPolyDataWriter.h>

#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/parallel.hpp"
#include "articula/imaging/cortex_edge.hpp"
#include "articula/imaging/edges.hpp"
#include "articula/imaging/noise.hpp"
#include "articula/points/mesh_file.hpp"
#include "articula/points/vtk_mesh.hpp"

namespace articula::mesh {
namespace fs = std::filesystem;
namespace {

std::string extensionOf(const fs::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

/// The label, padded by one empty voxel on every side so that the surface
/// closes where the label touches the grid's edge, with ITK's geometry: the
/// direction matrix puts the mesh in physical LPS (flying edges honour it).
// The label's set voxels within their bounding box, padded by one unset
// voxel on every side (a closed surface where the label touches the grid's
// edge): a clinical CT's grid is mostly far from the bone, and iso-surfacing
// it whole costs its full size.
vtkSmartPointer<vtkImageData> toVtk(const imaging::Label& label) {
  const imaging::ImageGeometry& g = label.geometry;
  Eigen::Vector3i lo(g.size[0], g.size[1], g.size[2]), hi(-1, -1, -1);
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i)
        if (label.at(i, j, k)) {
          lo = lo.cwiseMin(Eigen::Vector3i(i, j, k));
          hi = hi.cwiseMax(Eigen::Vector3i(i, j, k));
        }
  if (hi.x() < 0) lo = hi = Eigen::Vector3i::Zero();
  const Eigen::Vector3i size = hi - lo + Eigen::Vector3i::Constant(3);
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(size[0], size[1], size[2]);
  image->SetSpacing(g.spacing[0], g.spacing[1], g.spacing[2]);
  const Eigen::Vector3d origin = g.toPhysical((lo - Eigen::Vector3i::Ones()).cast<double>());
  image->SetOrigin(origin[0], origin[1], origin[2]);
  double direction[9];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) direction[3 * r + c] = g.direction(r, c);  // row-major
  image->SetDirectionMatrix(direction);
  image->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  auto* buffer = static_cast<unsigned char*>(image->GetScalarPointer());
  std::fill(buffer, buffer + static_cast<long long>(size[0]) * size[1] * size[2], 0);
  for (int k = lo[2]; k <= hi[2]; ++k)
    for (int j = lo[1]; j <= hi[1]; ++j)
      for (int i = lo[0]; i <= hi[0]; ++i)
        buffer[(i - lo[0] + 1) + static_cast<long long>(size[0]) * ((j - lo[1] + 1) + static_cast<long long>(size[1]) * (k - lo[2] + 1))] =
            label.at(i, j, k) ? 1 : 0;
  return image;
}

// The volume the triangles enclose, signed: positive when they wind
// counter-clockwise seen from outside (their normals point out).
double signedVolume(vtkPolyData* poly) {
  double volume = 0;
  vtkCellArray* polys = poly->GetPolys();
  vtkIdType count = 0;
  const vtkIdType* ids = nullptr;
  for (polys->InitTraversal(); polys->GetNextCell(count, ids);) {
    if (count != 3) continue;
    double a[3], b[3], c[3];
    poly->GetPoint(ids[0], a);
    poly->GetPoint(ids[1], b);
    poly->GetPoint(ids[2], c);
    volume += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return volume / 6.0;
}

vtkSmartPointer<vtkPolyData> withNormals(vtkPolyData* input) {
  auto oriented = [input](bool flip) {
    vtkNew<vtkPolyDataNormals> normals;
    normals->SetInputData(input);
    normals->ComputePointNormalsOn();
    normals->ComputeCellNormalsOff();
    normals->SplittingOff();
    normals->ConsistencyOn();
    normals->AutoOrientNormalsOn();
    normals->SetFlipNormals(flip);
    normals->Update();
    return vtkSmartPointer<vtkPolyData>(normals->GetOutput());
  };
  // VTK's auto-orientation starts from the leftmost vertex, which a
  // non-manifold corner of marching cubes can leave pointing in: then
  // every normal points in (seen on a 0.6 mm head). The enclosed volume's
  // sign tells which way the consistent winding faces.
  vtkSmartPointer<vtkPolyData> out = oriented(false);
  if (signedVolume(out) < 0) out = oriented(true);
  return out;
}

TriangleMesh fromVtk(vtkPolyData* poly) {
  points::MeshFile m = points::meshFromPolyData(poly);
  for (Eigen::Index v = 0; v < m.normals.rows(); ++v) m.normals.row(v) = Eigen::RowVector3d(m.normals.row(v)).normalized();
  return {std::move(m.vertices), std::move(m.normals), std::move(m.triangles), std::move(m.cut_through_bone)};
}

vtkSmartPointer<vtkPolyData> toVtk(const TriangleMesh& mesh) {
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v)
    points->InsertNextPoint(mesh.vertices(v, 0), mesh.vertices(v, 1), mesh.vertices(v, 2));
  poly->SetPoints(points);
  vtkNew<vtkCellArray> cells;
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    const vtkIdType ids[3] = {mesh.triangles(t, 0), mesh.triangles(t, 1), mesh.triangles(t, 2)};
    cells->InsertNextCell(3, ids);
  }
  poly->SetPolys(cells);
  if (mesh.normals.rows() == mesh.vertices.rows()) {
    vtkNew<vtkFloatArray> normals;
    normals->SetNumberOfComponents(3);
    normals->SetName("Normals");
    for (Eigen::Index v = 0; v < mesh.normals.rows(); ++v)
      normals->InsertNextTuple3(mesh.normals(v, 0), mesh.normals(v, 1), mesh.normals(v, 2));
    poly->GetPointData()->SetNormals(normals);
  }
  if (mesh.cut_through_bone.size() == static_cast<size_t>(mesh.vertices.rows())) {
    vtkNew<vtkUnsignedCharArray> cut;
    cut->SetName(points::kCutThroughBoneArray);
    for (const unsigned char c : mesh.cut_through_bone) cut->InsertNextValue(c);
    poly->GetPointData()->AddArray(cut);
  }
  return poly;
}

}  // namespace

void MeshOptions::validate() const {
  if (smooth_iterations < 0 || smooth_iterations > 10000) throw UsageError("--smooth-iterations: expected 0 to 10000");
  if (!(relaxation > 0 && relaxation <= 1)) throw UsageError("--relaxation: expected a value in (0, 1]");
  if (!(passband > 0 && passband <= 2)) throw UsageError("--passband: expected a value in (0, 2]");
  if (!(decimate >= 0 && decimate < 1)) throw UsageError("--decimate: expected a fraction in [0, 1)");
}

namespace {

/// Per vertex, 1 where the label voxel nearest to it is on the
/// segmentation's cut through bone (imaging::kLabelCutThroughBone); empty
/// when the label marks no cut.
std::vector<unsigned char> cutMarksOfLabel(const imaging::Label& label, const Eigen::MatrixX3d& vertices) {
  if (std::find(label.voxels.begin(), label.voxels.end(), imaging::kLabelCutThroughBone) == label.voxels.end()) return {};
  const imaging::ImageGeometry& g = label.geometry;
  std::vector<unsigned char> marks(static_cast<size_t>(vertices.rows()), 0);
  for (Eigen::Index v = 0; v < vertices.rows(); ++v) {
    const Eigen::Vector3d x = vertices.row(v).transpose();
    const Eigen::Vector3i voxel = g.toIndex(x).array().round().cast<int>();
    double nearest = INFINITY;
    // The smoothed surface lies within about a voxel of the label's voxels.
    for (int dk = -1; dk <= 1; ++dk)
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          const Eigen::Vector3i ijk = voxel + Eigen::Vector3i(di, dj, dk);
          if ((ijk.array() < 0).any() || (ijk.array() >= g.size.array()).any()) continue;
          const std::uint8_t value = label.at(ijk[0], ijk[1], ijk[2]);
          if (value == 0) continue;
          const double d = (g.toPhysical(ijk.cast<double>()) - x).norm();
          if (d < nearest) nearest = d, marks[static_cast<size_t>(v)] = value == imaging::kLabelCutThroughBone;
        }
  }
  return marks;
}

}  // namespace

TriangleMesh extractSurface(const imaging::Label& label, const MeshOptions& options, MeshSummary* summary) {
  options.validate();
  long long voxels = 0;
  for (auto v : label.voxels) voxels += v ? 1 : 0;
  if (voxels == 0) throw InputError("the label has no voxel set: nothing to mesh");

  vtkNew<vtkFlyingEdges3D> iso;
  iso->SetInputData(toVtk(label));
  iso->SetValue(0, 0.5);
  iso->ComputeNormalsOff();
  iso->ComputeGradientsOff();
  iso->ComputeScalarsOff();
  iso->Update();
  vtkSmartPointer<vtkPolyData> poly = iso->GetOutput();
  const long long raw = poly->GetNumberOfPolys();

  if (options.largest_component) {
    vtkNew<vtkPolyDataConnectivityFilter> largest;
    largest->SetInputData(poly);
    largest->SetExtractionModeToLargestRegion();
    vtkNew<vtkCleanPolyData> clean;  // drops the points of the other regions
    clean->SetInputConnection(largest->GetOutputPort());
    clean->Update();
    poly = clean->GetOutput();
  }
  if (options.smoothing == Smoothing::Laplacian && options.smooth_iterations > 0) {
    vtkNew<vtkSmoothPolyDataFilter> smooth;
    smooth->SetInputData(poly);
    smooth->SetNumberOfIterations(options.smooth_iterations);
    smooth->SetRelaxationFactor(options.relaxation);
    smooth->FeatureEdgeSmoothingOff();
    smooth->BoundarySmoothingOn();
    smooth->Update();
    poly = smooth->GetOutput();
  } else if (options.smoothing == Smoothing::WindowedSinc && options.smooth_iterations > 0) {
    vtkNew<vtkWindowedSincPolyDataFilter> smooth;
    smooth->SetInputData(poly);
    smooth->SetNumberOfIterations(options.smooth_iterations);
    smooth->SetPassBand(options.passband);
    smooth->NormalizeCoordinatesOn();
    smooth->FeatureEdgeSmoothingOff();
    smooth->BoundarySmoothingOn();
    smooth->NonManifoldSmoothingOn();
    smooth->Update();
    poly = smooth->GetOutput();
  }
  if (options.decimate > 0) {
    vtkNew<vtkQuadricDecimation> decimate;
    decimate->SetInputData(poly);
    decimate->SetTargetReduction(options.decimate);
    decimate->Update();
    poly = decimate->GetOutput();
  }
  TriangleMesh mesh = fromVtk(withNormals(poly));
  if (mesh.triangles.rows() == 0) throw ProcessingError("the iso-surface has no triangles");
  mesh.cut_through_bone = cutMarksOfLabel(label, mesh.vertices);
  if (summary) {
    summary->label_voxels = voxels;
    summary->raw_triangles = raw;
    summary->triangles = mesh.triangles.rows();
    summary->vertices = mesh.vertices.rows();
  }
  return mesh;
}

void EdgeSnapOptions::validate() const {
  if (!(search_mm >= 0 && search_mm <= 10)) throw UsageError("edge search: expected 0 to 10 mm, found " + std::to_string(search_mm));
  if (!(min_contrast_hu > 0)) throw UsageError("edge contrast must be > 0 HU");
  if (smoothing_passes < 0 || smoothing_passes > 100) throw UsageError("edge smoothing passes: expected 0 to 100");
  if (!(point_spread_mm >= 0 && point_spread_mm <= 3))
    throw UsageError("point-spread: expected 0 (estimate) to 3 mm, found " + std::to_string(point_spread_mm));
  if (!(slice_point_spread_mm >= 0 && slice_point_spread_mm <= 3))
    throw UsageError("slice point-spread: expected 0 (as within the slices) to 3 mm, found " +
                     std::to_string(slice_point_spread_mm));
  if (slice_point_spread_mm > 0 && point_spread_mm <= 0)
    throw UsageError("slice point-spread: give the point-spread within the slices too (--point-spread)");
  if (!(slice_thickness_mm >= 0 && slice_thickness_mm <= 20))
    throw UsageError("slice thickness: expected 0 (the CT's) to 20 mm, found " + std::to_string(slice_thickness_mm));
}

namespace {

/// The bone's edge along the normal u at x: the steepest fall within the
/// search window. Where the window holds no fall, or its steepest at its
/// outer end, the label may end inside the bone (a cortex so faint that the
/// bone window cuts it millimetres inside its edge); with `look_further`,
/// the first fall met going out within 3 mm (1.5 voxels) is taken then, if
/// the way to it stays in bone (above the middle of that fall), and before a
/// joint gap's valley, so that a socket's cortex beyond a joint gap is never
/// taken. Where the window holds no fall at all, the label may also end
/// outside the bone: a flattened or eroded dome whose gap to the socket the
/// segmentation's closing bridged (the label keeps the round head there, up
/// to a quarter of its radius above the bone). The first fall met going out from kLabelOutsideReachMm
/// inside is taken then, if the way from it to x and a millimetre beyond
/// stays out of bone (below the middle of that fall), so that no edge within
/// the bone is taken.
imaging::Edge boneEdge(const imaging::Volume& ct, const Eigen::Vector3d& x, const Eigen::Vector3d& u,
                       const imaging::EdgeSearch& search, bool look_further) {
  constexpr double kLabelOutsideReachMm = 7.0, kBeyondLabelMm = 1.0;
  const imaging::Edge e = imaging::locateEdge(ct, x, u, search);
  if (!look_further || (e.found && e.offset_mm <= search.outward_mm - 0.15)) return e;
  const double reach_mm = std::max(3.0, 1.5 * ct.geometry.spacing.maxCoeff());
  // Before a joint gap's valley, not beyond it: a narrow gap between faint
  // cortices blurs to a valley above the middle of the socket cortex's far fall.
  imaging::Edge further =
      imaging::firstEdgeBeforeAGap(ct, x - search.inward_mm * u, u, 0.0, search.inward_mm + reach_mm, search);
  further.offset_mm -= search.inward_mm;
  if (further.found && !(e.found && further.offset_mm <= e.offset_mm)) {
    const double middle = 0.5 * (further.inside_hu + further.outside_hu);
    for (double t = 0; t <= further.offset_mm - 0.5; t += 0.1)
      if (!(imaging::interpolate(ct, x + t * u) >= middle)) return e;
    return further;
  }
  if (e.found) return e;
  imaging::Edge below = imaging::firstEdgeAlongRay(ct, x - kLabelOutsideReachMm * u, u, 0.0, kLabelOutsideReachMm, search);
  below.offset_mm -= kLabelOutsideReachMm;
  if (!below.found || below.offset_mm > -search.inward_mm) return e;
  // Out of bone from the fall to x and a millimetre beyond: a label cut
  // inside a faint cortex lies in textured cancellous bone, whose small falls
  // this would take, with the cortex just outside.
  const double middle = 0.5 * (below.inside_hu + below.outside_hu);
  for (double t = below.offset_mm + 0.5; t <= kBeyondLabelMm; t += 0.1)
    if (!(imaging::interpolate(ct, x + t * u) < middle)) return e;
  return below;
}

/// What one voxel averages over along each axis: the CT's (its slices'
/// thickness where it states one), or the thickness the options give.
Eigen::Vector3d voxelExtent(const imaging::Volume& ct, const EdgeSnapOptions& options) {
  Eigen::Vector3d extent = ct.geometry.voxelExtent();
  if (options.slice_thickness_mm > 0) extent[2] = options.slice_thickness_mm;
  return extent;
}

/// Neighbour averages over the triangles' edges: the found shifts smoothed
/// (`passes` times), the others taken from found neighbours (repeatedly, as
/// far as eight more passes reach); `found` then marks every vertex reached.
void averageShifts(const std::vector<std::vector<int>>& neighbours, int passes, std::vector<double>& shift,
                   std::vector<char>& found) {
  for (int pass = 0; pass < passes + 8; ++pass) {
    std::vector<double> next = shift;
    std::vector<char> next_found = found;
    for (size_t v = 0; v < shift.size(); ++v) {
      if (pass >= passes && found[v]) continue;  // later passes only reach the vertices without an edge
      double sum = found[v] ? shift[v] : 0.0;
      int count = found[v] ? 1 : 0;
      for (int w : neighbours[v])
        if (found[static_cast<size_t>(w)]) sum += shift[static_cast<size_t>(w)], ++count;
      if (count > 0) next[v] = sum / count, next_found[v] = 1;
    }
    shift.swap(next);
    found.swap(next_found);
  }
}

/// The mean length of the mesh's edges (mm).
double meanEdgeLength(const TriangleMesh& mesh, const std::vector<std::vector<int>>& neighbours) {
  double length = 0;
  long edges = 0;
  for (size_t i = 0; i < neighbours.size(); ++i)
    for (const int j : neighbours[i]) {
      length += (mesh.vertices.row(j) - mesh.vertices.row(static_cast<Eigen::Index>(i))).norm();
      ++edges;
    }
  return edges ? length / static_cast<double>(edges) : 0.0;
}

/// Neighbour-average passes that reach about `reach_mm` over a surface of
/// edges `edge_mm` long: a pass spreads by about an edge, k passes by about
/// sqrt(k) edges.
int passesToReach(double edge_mm, double reach_mm) {
  return std::clamp(static_cast<int>(std::ceil(std::pow(reach_mm / std::max(edge_mm, 1e-3), 2))), 1, 200);
}

/// Each vertex's mean curvature (1/mm, positive where convex): the normal
/// curvature along each edge, (n_j - n_i).(x_j - x_i) / |x_j - x_i|^2,
/// averaged over the edges, then over neighbours out to about 2 mm (normals
/// are noisy from edge to edge, and a joint's curvature changes over
/// centimetres; each spread of a line's voxels about their true depths
/// reads as blur), within +-1/5 mm.
std::vector<double> meanCurvature(const TriangleMesh& mesh, const std::vector<std::vector<int>>& neighbours,
                                  double edge_mm, double reach_mm) {
  const size_t n = neighbours.size();
  std::vector<double> curvature(n, 0.0);
  for (size_t i = 0; i < n; ++i) {
    double sum = 0;
    for (const int j : neighbours[i]) {
      const Eigen::Vector3d dx = (mesh.vertices.row(j) - mesh.vertices.row(static_cast<Eigen::Index>(i))).transpose();
      const Eigen::Vector3d dn = (mesh.normals.row(j) - mesh.normals.row(static_cast<Eigen::Index>(i))).transpose();
      if (dx.squaredNorm() > 0) sum += dn.dot(dx) / dx.squaredNorm();
    }
    if (!neighbours[i].empty()) curvature[i] = sum / static_cast<double>(neighbours[i].size());
  }
  for (int pass = passesToReach(edge_mm, reach_mm); pass > 0; --pass) {
    std::vector<double> next(n, 0.0);
    for (size_t i = 0; i < n; ++i) {
      double sum = curvature[i];
      for (const int j : neighbours[i]) sum += curvature[static_cast<size_t>(j)];
      next[i] = sum / static_cast<double>(neighbours[i].size() + 1);
    }
    curvature.swap(next);
  }
  for (double& k : curvature) k = std::clamp(k, -0.2, 0.2);
  return curvature;
}

/// The mesh's normals averaged over neighbours out to about 1 mm: a
/// surface moved onto a CT's edges tilts its vertex normals by 6-8 degrees
/// rms (0.7 mm voxels), and each degree of tilt spreads a line's voxels
/// about their depths like blur.
Eigen::MatrixX3d smoothedNormals(const TriangleMesh& mesh, const std::vector<std::vector<int>>& neighbours,
                                 double edge_mm, double reach_mm) {
  Eigen::MatrixX3d normals = mesh.normals;
  for (int pass = passesToReach(edge_mm, reach_mm); pass > 0; --pass) {
    Eigen::MatrixX3d next = normals;
    for (size_t i = 0; i < neighbours.size(); ++i) {
      Eigen::RowVector3d sum = normals.row(static_cast<Eigen::Index>(i));
      for (const int j : neighbours[i]) sum += normals.row(j);
      if (sum.squaredNorm() > 0) next.row(static_cast<Eigen::Index>(i)) = sum.normalized();
    }
    normals.swap(next);
  }
  return normals;
}

/// Each vertex's cortex from the `known` ones' (the fits of the lines
/// within the slices): spread ring by ring over the mesh to the others
/// (each the mean of its reached neighbours), then averaged over about
/// 3 mm (a single line's thickness and levels are noisy). `known` then
/// marks every vertex reached.
void tissueOverMesh(const std::vector<std::vector<int>>& neighbours, double edge_mm,
                    std::vector<imaging::CortexTissue>& tissue, std::vector<char>& known) {
  constexpr double kReachMm = 3.0;
  const auto add = [](imaging::CortexTissue& sum, const imaging::CortexTissue& t) {
    sum.thickness_mm += t.thickness_mm;
    sum.outside_hu += t.outside_hu;
    sum.cortex_hu += t.cortex_hu;
    sum.inside_hu += t.inside_hu;
  };
  const auto divide = [](imaging::CortexTissue t, double n) {
    t.thickness_mm /= n, t.outside_hu /= n, t.cortex_hu /= n, t.inside_hu /= n;
    return t;
  };
  for (bool spreading = true; spreading;) {
    spreading = false;
    std::vector<char> next_known = known;
    std::vector<imaging::CortexTissue> next = tissue;
    for (size_t v = 0; v < tissue.size(); ++v) {
      if (known[v]) continue;
      imaging::CortexTissue sum;
      int count = 0;
      for (const int w : neighbours[v])
        if (known[static_cast<size_t>(w)]) add(sum, tissue[static_cast<size_t>(w)]), ++count;
      if (count == 0) continue;
      next[v] = divide(sum, count);
      next_known[v] = 1;
      spreading = true;
    }
    tissue.swap(next);
    known.swap(next_known);
  }
  for (int pass = passesToReach(edge_mm, kReachMm); pass > 0; --pass) {
    std::vector<imaging::CortexTissue> next = tissue;
    for (size_t v = 0; v < tissue.size(); ++v) {
      if (!known[v]) continue;
      imaging::CortexTissue sum = tissue[v];
      int count = 1;
      for (const int w : neighbours[v])
        if (known[static_cast<size_t>(w)]) add(sum, tissue[static_cast<size_t>(w)]), ++count;
      next[v] = divide(sum, count);
    }
    tissue.swap(next);
  }
}

/// Moves the found steepest falls (`shift` along the normals) onto the
/// outer surface of the blurred-cortex model, with one point-spread for the
/// whole CT (given, or estimated on up to 600 of the found edges spread over
/// the surface: with 300, about 170 of them facing no socket, the kind of
/// blur was taken wrongly at 0.6 mm voxels). A vertex whose model does not
/// fit keeps its steepest fall.
void placeOnCortexModel(const TriangleMesh& mesh, const std::vector<std::vector<int>>& neighbours,
                        const imaging::Volume& ct, const Eigen::Vector3d& extent, const std::vector<char>& found,
                        std::vector<double>& shift, const EdgeSnapOptions& options, EdgeSnapSummary& s) {
  constexpr size_t kPointSpreadLines = 600;
  constexpr size_t kMoreLinesWithinSlices = 300;  // across long slices, for the width within them
  constexpr double kTypicalCortexRatio = 1.5;  // a line within the slices tells the cortex when within this factor of the median
  constexpr double kTissueTellingShare = 0.01;  // of a line's direction across the slices (within about 6 degrees of their plane) ...
  constexpr size_t kMinTissueTellingLines = 30;  // ... where at least this many such lines fit (else the whole band within the slices)
  // The lines run along the normals of the surface moved onto the steepest
  // falls (their shifts averaged as the final surface's are), averaged over
  // about a millimetre: the label's smoothed voxel surface tilts them by
  // about 8 degrees rms from the bone's at 0.7 mm voxels, which widens
  // every profile the model sees.
  std::vector<double> averaged = shift;
  std::vector<char> reached = found;
  averageShifts(neighbours, std::max(options.smoothing_passes, 1), averaged, reached);
  TriangleMesh on_falls = mesh;
  for (Eigen::Index v = 0; v < on_falls.vertices.rows(); ++v) {
    const auto at = static_cast<size_t>(v);
    if (reached[at]) on_falls.vertices.row(v) += averaged[at] * mesh.normals.row(v);
  }
  on_falls.normals = fromVtk(withNormals(toVtk(on_falls))).normals;
  const double edge_mm = meanEdgeLength(on_falls, neighbours);
  const double slices_mm = imaging::tissueHeldAcrossSlices(extent) ? extent[2] : 0.0;
  on_falls.normals = smoothedNormals(on_falls, neighbours, edge_mm, std::max(1.0, slices_mm));
  const std::vector<double> curvature = meanCurvature(on_falls, neighbours, edge_mm, std::max(2.0, 2 * slices_mm));

  // `covering`: with the radius that lets a line across long slices see its
  // surface at every depth (the fits); without, the common radius (the
  // point-spread's estimate, which the wider lines' geometry would widen).
  const auto lineAt = [&](Eigen::Index v, bool covering) {
    const Eigen::Vector3d n = on_falls.normals.row(v).transpose();
    const Eigen::Vector3d axis_extent = extent.cwiseProduct(ct.geometry.direction.transpose() * n);
    const double further_in = imaging::cortexSearchMm(axis_extent) - imaging::cortexSearchMm(Eigen::Vector3d::Zero());
    return imaging::voxelsAboutLine(ct, on_falls.vertices.row(v).transpose(), n, -imaging::kCortexInwardMm - further_in,
                                    imaging::kCortexOutwardMm,
                                    covering ? imaging::lineRadiusFor(ct.geometry, n, s.ct_noise_hu)
                                             : imaging::lineRadiusFor(ct.geometry, s.ct_noise_hu),
                                    curvature[static_cast<size_t>(v)], extent);
  };
  std::vector<Eigen::Index> on_edge;
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v)
    if (found[static_cast<size_t>(v)]) on_edge.push_back(v);
  // The squared share of a vertex's normal across the slices (below
  // imaging::kWithinSlicesShare its line lies within them).
  const Eigen::Vector3d slice_axis = ct.geometry.direction.col(2);
  const auto shareAcrossSlices = [&](Eigen::Index v) {
    const double across = on_falls.normals.row(v).dot(slice_axis.transpose());
    return across * across;
  };
  imaging::PointSpread spread;
  spread.sigma_mm = options.point_spread_mm;
  spread.slice_sigma_mm = options.slice_point_spread_mm > 0 ? options.slice_point_spread_mm : options.point_spread_mm;
  if (options.point_spread_mm <= 0) {
    std::vector<imaging::LineVoxels> lines;
    const size_t stride = std::max<size_t>(1, on_edge.size() / kPointSpreadLines);
    for (size_t i = 0; i < on_edge.size(); i += stride) lines.push_back(lineAt(on_edge[i], false));
    // Across long slices the width within them comes from the lines within
    // them alone, a fifth of the sample, less where the socket takes lines
    // out: 46 lines of 2 mm slices gave a likelihood flat from 0.56 to 0.70
    // mm and a surface 0.22 mm inside. More are taken from the band within
    // the slices, for that width only.
    std::vector<imaging::LineVoxels> band_lines;
    if (imaging::tissueHeldAcrossSlices(extent)) {
      std::vector<size_t> band;
      for (size_t i = 0; i < on_edge.size(); ++i)
        if (i % stride != 0 && shareAcrossSlices(on_edge[i]) < imaging::kWithinSlicesShare) band.push_back(i);
      const size_t band_stride = std::max<size_t>(1, band.size() / kMoreLinesWithinSlices);
      for (size_t j = 0; j < band.size(); j += band_stride) band_lines.push_back(lineAt(on_edge[band[j]], false));
    }
    spread = imaging::estimatePointSpread(lines, options.threads, band_lines, s.ct_noise_hu);
    if (!spread.found) {
      s.cortex_model_note = "the CT's point-spread could not be estimated from " + std::to_string(spread.profiles) +
                            " edges; the edges are the steepest falls";
      return;
    }
    s.point_spread_estimated = true;
  }
  const bool held_across = s.point_spread_estimated ? spread.held_across
                                                    : imaging::tissueHeldAcrossSlices(extent, spread.sigma_mm,
                                                                                      spread.slice_sigma_mm);
  std::vector<char> within(static_cast<size_t>(mesh.vertices.rows()), 1);
  if (held_across)
    for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v)
      within[static_cast<size_t>(v)] = shareAcrossSlices(v) < imaging::kWithinSlicesShare;
  s.cortex_held_across_slices = held_across;
  s.point_spread_mm = spread.sigma_mm;
  s.slice_point_spread_mm = spread.slice_sigma_mm;
  s.point_spread_on_voxel_grid = spread.kind == imaging::PointSpread::Kind::VoxelGrid;
  // With slices much longer than the in-plane voxels or blurred much more
  // across than within, the lines within the slices tell the cortex's
  // thickness and levels, and the lines across them are fitted with those
  // of their neighbourhood (imaging::fitCortex).
  std::vector<imaging::CortexFit> fits(on_edge.size());
  const auto fitLines = [&](bool which, const std::vector<imaging::CortexTissue>* held) {
    parallelFor(static_cast<std::ptrdiff_t>(on_edge.size()), 64, options.threads, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
      for (auto i = static_cast<size_t>(begin); i < static_cast<size_t>(end); ++i) {
        const auto v = static_cast<size_t>(on_edge[i]);
        if (static_cast<bool>(within[v]) != which) continue;
        const imaging::LineVoxels line = lineAt(on_edge[i], true);
        fits[i] = imaging::fitCortex(line, 0.0, imaging::StepResponse(line, spread), options.min_contrast_hu,
                                     held ? &(*held)[v] : nullptr);
        // The model blurs a flat step; the head's convex surface lies that much further out.
        fits[i].offset_mm += imaging::curvatureShiftMm(line, spread);
      }
    });
  };
  fitLines(true, nullptr);
  if (held_across) {
    // Only lines whose cortex is like most lines' within the slices tell
    // it: about a pole at 3 mm slices the surface on the steepest falls
    // climbs in terraces, and a riser's line, level with the slices, meets
    // the bone aslant (its cortex came out 2.1 mm thick for 0.8).
    std::vector<double> thickness;
    for (size_t i = 0; i < on_edge.size(); ++i)
      if (fits[i].found && within[static_cast<size_t>(on_edge[i])]) thickness.push_back(fits[i].thickness_mm);
    std::nth_element(thickness.begin(), thickness.begin() + static_cast<long>(thickness.size() / 2), thickness.end());
    const double typical = thickness.empty() ? 0.0 : thickness[thickness.size() / 2];
    // Of those, the lines nearest the slices' plane tell it, where enough
    // of them fit: within the band the voxel's extent across the slices
    // still lies along a line by up to 0.22 of it, and the fits trade
    // thickness against that blur (a 0.8 mm cortex at 700 HU came out
    // 0.77 mm at 730 HU within 3 degrees of the plane, 1.0 mm at 595 HU at
    // 12 degrees, at 0.6 x 0.6 x 3 mm with 4 mm slices); held on the lines
    // across the slices, a cortex too thick and dim put their surface 0.1-
    // 0.17 mm outside.
    const auto typicalFit = [&](size_t i) {
      return fits[i].found && std::abs(std::log(fits[i].thickness_mm / typical)) < std::log(kTypicalCortexRatio);
    };
    size_t nearest_plane = 0;
    for (size_t i = 0; i < on_edge.size(); ++i)
      nearest_plane += typicalFit(i) && shareAcrossSlices(on_edge[i]) < kTissueTellingShare;
    const double telling_share =
        nearest_plane >= kMinTissueTellingLines ? kTissueTellingShare : imaging::kWithinSlicesShare;
    std::vector<imaging::CortexTissue> tissue(static_cast<size_t>(mesh.vertices.rows()));
    std::vector<char> known(tissue.size(), 0);
    for (size_t i = 0; i < on_edge.size(); ++i)
      if (typicalFit(i) && shareAcrossSlices(on_edge[i]) < telling_share) {
        tissue[static_cast<size_t>(on_edge[i])] = fits[i];
        known[static_cast<size_t>(on_edge[i])] = 1;
      }
    tissueOverMesh(neighbours, edge_mm, tissue, known);
    fitLines(false, &tissue);
    for (size_t i = 0; i < on_edge.size(); ++i)
      if (!known[static_cast<size_t>(on_edge[i])]) fits[i].found = false;  // no tissue reached it
  }
  // From the averaged fall the model's surface lies offset_mm along the
  // line; the vertex moves along the label's normal, so it goes to where
  // that normal meets the model's tangent plane (the two normals part by
  // a few degrees at fine voxels, by up to 30 about a pole's terrace at
  // 3 mm slices).
  std::vector<double> correction(shift.size(), 0.0);
  std::vector<char> corrected(shift.size(), 0);
  for (size_t i = 0; i < on_edge.size(); ++i) {
    if (!fits[i].found) continue;
    const auto v = static_cast<size_t>(on_edge[i]);
    const double cosine = std::max(0.5, mesh.normals.row(on_edge[i]).dot(on_falls.normals.row(on_edge[i])));
    correction[v] = averaged[v] + fits[i].offset_mm / cosine - shift[v];
    corrected[v] = 1;
  }
  // Where the lines across the slices hold the tissue, each correction is
  // averaged once with its neighbours': their fits scatter more (a faint
  // cortex, 0.6 mm at 500 HU over textured bone at 100 HU, at 0.8 x 0.8 x
  // 1.25 mm: the points' RMS 0.42 mm against 0.32 averaged).
  if (held_across) {
    std::vector<double> next = correction;
    for (size_t v = 0; v < correction.size(); ++v) {
      if (!corrected[v]) continue;
      double sum = correction[v];
      int count = 1;
      for (const int w : neighbours[v])
        if (corrected[static_cast<size_t>(w)]) sum += correction[static_cast<size_t>(w)], ++count;
      next[v] = sum / count;
    }
    correction.swap(next);
  }
  double moved = 0;
  for (size_t v = 0; v < shift.size(); ++v) {
    if (!corrected[v]) continue;
    shift[v] += correction[v];
    moved += correction[v];
    ++s.on_cortex_model;
  }
  s.cortex_model = true;
  s.mean_model_shift_mm = s.on_cortex_model ? moved / static_cast<double>(s.on_cortex_model) : 0.0;
}

}  // namespace

void snapToEdges(TriangleMesh& mesh, const imaging::Volume& ct, const EdgeSnapOptions& options,
                 EdgeSnapSummary* summary) {
  constexpr double kMinShareOnEdge = 0.25;
  options.validate();
  const Eigen::Index n = mesh.vertices.rows();
  if (mesh.normals.rows() != n) throw ProcessingError("snapping to the CT's edges needs vertex normals");
  imaging::EdgeSearch search;
  // Inwards by a voxel and a half (a label ends where the HU window does,
  // outside the edge by up to a voxel); outwards by little: beyond a narrow
  // joint gap lies the socket, whose outer fall must not be taken.
  search.inward_mm = options.search_mm > 0 ? options.search_mm : std::max(1.5, 1.5 * ct.geometry.spacing.maxCoeff());
  search.outward_mm = options.search_mm > 0 ? options.search_mm : std::max(0.75, 0.25 * ct.geometry.spacing.maxCoeff());
  search.min_contrast_hu = options.min_contrast_hu;
  search.min_inside_hu = options.min_inside_hu;
  std::vector<double> shift(static_cast<size_t>(n), 0.0);
  std::vector<char> found(static_cast<size_t>(n), 0);
  EdgeSnapSummary s;
  s.vertices = n;
  const bool look_further = ct.geometry.spacing.maxCoeff() <= imaging::kSeparateEdgesMaxVoxelMm + 1e-6;
  // Across long slices a line's trilinear profile is straight between them:
  // its steepest fall keeps to the middle between two slices (a flat
  // terrace about a head's pole at 3 mm slices) unless the profile is
  // smoothed over about a third of the voxel's extent along the line.
  // Only where the model follows: its lines start on these falls, and a
  // smoothed profile's steepest fall lies further out on a thin cortex.
  const bool cortex_model =
      options.edge_model == EdgeModel::Cortex ||
      (options.edge_model == EdgeModel::Automatic &&
       std::max(ct.geometry.spacing[0], ct.geometry.spacing[1]) <= kCortexModelMaxInPlaneMm + 1e-6 &&
       ct.geometry.spacing[2] <= kCortexModelMaxSliceMm + 1e-6);
  const Eigen::Vector3d extent = voxelExtent(ct, options);
  s.slice_thickness_mm = extent[2];
  const bool long_slices = imaging::tissueHeldAcrossSlices(extent);
  if (cortex_model) {
    s.ct_noise_hu = imaging::noiseHu(ct);
    s.line_radius_mm = imaging::lineRadiusFor(ct.geometry, s.ct_noise_hu);
  }
  for (Eigen::Index v = 0; v < n; ++v) {
    imaging::EdgeSearch along = search;
    if (cortex_model && long_slices && options.search_mm <= 0) {
      const Eigen::Vector3d u = mesh.normals.row(v).transpose();
      const double reach = extent.cwiseProduct(ct.geometry.direction.transpose() * u).norm();
      along.smoothing_mm = std::max(std::max(0.15, 0.25 * ct.geometry.spacing.minCoeff()), 0.3 * reach);
    }
    const imaging::Edge e =
        boneEdge(ct, mesh.vertices.row(v).transpose(), mesh.normals.row(v).transpose(), along, look_further);
    if (!e.found) continue;
    shift[static_cast<size_t>(v)] = e.offset_mm;
    found[static_cast<size_t>(v)] = 1;
    ++s.on_edge;
  }
  // Too few edges (coarse or lossy CT, or another CT than the label's): the
  // shifts would be guesses from far neighbours; the surface stays the label's.
  if (static_cast<double>(s.on_edge) < kMinShareOnEdge * static_cast<double>(n)) {
    if (summary) *summary = s;
    return;
  }
  std::vector<std::vector<int>> neighbours(static_cast<size_t>(n));
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t)
    for (int e = 0; e < 3; ++e) {
      const int a = mesh.triangles(t, e), b = mesh.triangles(t, (e + 1) % 3);
      neighbours[static_cast<size_t>(a)].push_back(b);
      neighbours[static_cast<size_t>(b)].push_back(a);
    }
  // Without an edge the label ends inside bone: the cut between head and
  // neck (on 29 of 128 phantom heads, 10-50 articular vertices 2.5-4 mm
  // inside the femur, every one without an edge). On coarser voxels the
  // lack of an edge tells nothing (a gap the CT does not resolve shows none
  // either), and the label's own marks of its cut stay instead. Not on finer
  // ones: those also take in a dome the segmentation could not cut from a
  // socket bridged across a narrow gap, which has its edge (an osteoporotic
  // head at 1 x 1 x 2 mm, its gap 1.5 mm: 242 vertices, the socket-facing
  // check failed). Set on the mesh last, so that the copies and VTK round
  // trips for normals below do not carry them.
  std::vector<unsigned char> cut = std::move(mesh.cut_through_bone);
  mesh.cut_through_bone.clear();
  if (look_further) {
    cut.assign(static_cast<size_t>(n), 0);
    for (Eigen::Index v = 0; v < n; ++v) cut[static_cast<size_t>(v)] = !found[static_cast<size_t>(v)];
  }
  if (cortex_model) placeOnCortexModel(mesh, neighbours, ct, extent, found, shift, options, s);
  averageShifts(neighbours, std::max(options.smoothing_passes, 1), shift, found);
  for (Eigen::Index v = 0; v < n; ++v) {
    const double d = found[static_cast<size_t>(v)] ? shift[static_cast<size_t>(v)] : 0.0;
    mesh.vertices.row(v) += d * mesh.normals.row(v);
    s.mean_shift_mm += d / static_cast<double>(n);
    s.mean_abs_shift_mm += std::abs(d) / static_cast<double>(n);
  }
  mesh.normals = fromVtk(withNormals(toVtk(mesh))).normals;
  mesh.cut_through_bone = std::move(cut);
  s.moved = true;
  if (summary) *summary = s;
}

namespace {

// Writes `poly` as .vtp, .stl or .ply (by extension) atomically, with its
// frame stated; a .vtp zlib-compressed, or raw when not `compress`.
void writePolyData(const fs::path& path, vtkPolyData* poly, bool overwrite, bool compress = true) {
  if (!overwrite && fs::exists(path)) throw UsageError("refusing to overwrite " + path.string() + " (use --force)");
  const std::string ext = extensionOf(path);
  const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::error_code ec;
  fs::create_directories(folder, ec);
  const fs::path temp = temporaryPathFor(path);
  // How 3D Slicer learns a mesh's frame: "SPACE=LPS" in an STL header or a
  // PLY comment, a string array SPACE in VTK field data (without it Slicer
  // assumes LPS too, but says so only in its log).
  vtkNew<vtkStringArray> space;
  space->SetName("SPACE");
  space->InsertNextValue("LPS");
  poly->GetFieldData()->AddArray(space);
  int ok = 0;
  if (ext == ".vtp") {
    vtkNew<vtkXMLPolyDataWriter> w;
    w->SetInputData(poly);
    w->SetFileName(temp.c_str());
    w->SetDataModeToBinary();
    if (!compress) {
      w->SetCompressorTypeToNone();
      w->SetDataModeToAppended();
      w->EncodeAppendedDataOff();
    }
    ok = w->Write();
  } else if (ext == ".stl") {
    vtkNew<vtkSTLWriter> w;
    w->SetInputData(poly);
    w->SetFileName(temp.c_str());
    w->SetFileTypeToBinary();
    w->SetHeader("articula mesh SPACE=LPS; coordinates LPS, units mm");
    ok = w->Write();
  } else if (ext == ".ply") {
    vtkNew<vtkPLYWriter> w;
    w->SetInputData(poly);
    w->SetFileName(temp.c_str());
    w->SetFileTypeToBinary();
    w->AddComment("SPACE=LPS");
    w->AddComment("articula mesh; coordinates LPS, units mm");
    ok = w->Write();
  } else {
    throw UsageError("expected a mesh file ending in .vtp, .stl or .ply, found '" + path.string() + "'");
  }
  if (!ok || !fs::exists(temp)) {
    fs::remove(temp, ec);
    throw InputError("could not write " + path.string());
  }
  fs::rename(temp, path, ec);
  if (ec) throw InputError("could not rename the finished mesh to " + path.string());
}

}  // namespace

void writeMesh(const fs::path& path, const TriangleMesh& mesh, bool overwrite) {
  writePolyData(path, toVtk(mesh), overwrite);
}

void writePointValues(const fs::path& path, const Eigen::MatrixX3d& points, const std::string& name,
                      const Eigen::VectorXd& values, bool overwrite) {
  if (extensionOf(path) != ".vtp") throw UsageError("expected a .vtp file for point values, found '" + path.string() + "'");
  if (values.size() != points.rows())
    throw ProcessingError("writePointValues: " + std::to_string(values.size()) + " values for " +
                          std::to_string(points.rows()) + " points");
  vtkNew<vtkPoints> vtk_points;
  vtkNew<vtkCellArray> vertices;
  vtkNew<vtkDoubleArray> array;
  array->SetName(name.c_str());
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const vtkIdType id = vtk_points->InsertNextPoint(points(i, 0), points(i, 1), points(i, 2));
    vertices->InsertNextCell(1, &id);
    array->InsertNextValue(values[i]);
  }
  vtkNew<vtkPolyData> poly;
  poly->SetPoints(vtk_points);
  poly->SetVerts(vertices);
  poly->GetPointData()->SetScalars(array);
  // Raw, not zlib: compressing took 60 % of articula errors' time at 10^6
  // points (five clouds), for files a quarter smaller.
  writePolyData(path, poly, overwrite, false);
}

TriangleMesh readMesh(const fs::path& path) {
  points::MeshFile file = points::readMeshFile(path);
  if (file.triangles.rows() == 0)
    throw InputError("expected a triangle mesh in " + path.string() + ", found no triangles (" +
                     std::to_string(file.vertices.rows()) + " points)");
  TriangleMesh mesh;
  mesh.vertices = std::move(file.vertices);
  mesh.triangles = std::move(file.triangles);
  mesh.cut_through_bone = std::move(file.cut_through_bone);
  mesh.normals = file.normals.rows() == mesh.vertices.rows() ? std::move(file.normals)
                                                             : fromVtk(withNormals(toVtk(mesh))).normals;
  return mesh;
}

}  // namespace articula::mesh
