// `articula surface`: writes a shape model of the hierarchy as an exactly
// sampled triangle mesh (PLY, LPS mm, with outward unit normals and the
// principal curvatures at every vertex), for 3D Slicer or ParaView.
#include <cmath>
#include <limits>

#include "articula/cli/command.hpp"
#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/log.hpp"
#include "articula/core/provenance.hpp"
#include "articula/geometry/curvature.hpp"
#include "articula/geometry/surface.hpp"
#include "articula/points/ply_writer.hpp"

namespace articula::apps {
namespace {

using geometry::ShapeModel;

Eigen::Vector3d threeValues(const std::vector<double>& v, const std::string& option, int allow_one) {
  if (v.size() == 3) return {v[0], v[1], v[2]};
  if (allow_one && v.size() == 1) return Eigen::Vector3d::Constant(v[0]);
  throw UsageError(option + ": expected 3 comma-separated numbers, found " + std::to_string(v.size()));
}

Eigen::Vector4d fourValues(const std::vector<double>& v, const std::string& option) {
  if (v.size() != 4) throw UsageError(option + ": expected 4 comma-separated numbers, found " + std::to_string(v.size()));
  return {v[0], v[1], v[2], v[3]};
}

class SurfaceCommand : public cli::Command {
 public:
  std::string name() const override { return "surface"; }
  std::string description() const override {
    return "Write a shape model (sphere ... superovoid) as an exact triangle mesh (PLY, LPS mm) "
           "with normals and principal curvatures";
  }
  std::string example() const override {
    return "articula surface --model superovoid --radii 24,23,22 --exponents 2.4,2.2,2.1 "
           "--cx 1,0.05,0,0 --cy 1,0.05,0,0 --center 10,-20,30 --angles-deg 10,0,30 -o head.ply";
  }
  void declare(CLI::App& app) override {
    app.add_option("--model", model_, "Shape model: sphere, ellipsoid, superellipsoid, ovoid, superovoid")
        ->capture_default_str();
    app.add_option("--radii", radii_, "a or a,b,c in mm")->delimiter(',')->capture_default_str();
    app.add_option("--exponents", exponents_, "gamma1,gamma2,gamma3 (>= 2)")->delimiter(',');
    app.add_option("--cx", cx_, "c0x,c1x,c2x,c3x (ovoid models)")->delimiter(',');
    app.add_option("--cy", cy_, "c0y,c1y,c2y,c3y (ovoid models)")->delimiter(',');
    app.add_option("--center", center_, "t1,t2,t3 in LPS mm")->delimiter(',');
    app.add_option("--angles-deg", angles_deg_, "phi,theta,psi in degrees, R = Rx(phi) Ry(theta) Rz(psi)")
        ->delimiter(',');
    app.add_option("--resolution", resolution_, "Steps around the local z axis (half as many pole to pole)")
        ->check(CLI::Range(8, 4096))
        ->capture_default_str();
    app.add_option("-o,--output", output_, "Output mesh (.ply)")->required();
  }

  int run(const cli::CommonOptions& common) override {
    geometry::ShapeParameters p;
    p.model = geometry::modelFromName(model_);
    p.radii = threeValues(radii_, "--radii", true);
    if (!exponents_.empty()) p.exponents = threeValues(exponents_, "--exponents", true);
    if (!cx_.empty()) p.cx = fourValues(cx_, "--cx");
    if (!cy_.empty()) p.cy = fourValues(cy_, "--cy");
    if (!center_.empty()) p.center = threeValues(center_, "--center", false);
    if (!angles_deg_.empty()) p.angles = threeValues(angles_deg_, "--angles-deg", false) * (M_PI / 180.0);
    if (output_.extension() != ".ply") throw UsageError("--output: expected a .ply file, found '" + output_.string() + "'");
    cli::refuseExistingOutputs({output_, output_.string() + ".json"}, common.force);

    const auto surface = geometry::makeSurface(p);
    const geometry::SurfaceMesh mesh = surface->sample(resolution_, resolution_ / 2);
    log::info("sampled " + geometry::modelName(p.model) + ": " + std::to_string(mesh.vertices.rows()) +
              " vertices, " + std::to_string(mesh.triangles.rows()) + " triangles");

    double max_abs_f = 0.0, k_min = std::numeric_limits<double>::infinity(), k_max = -k_min;
    points::PlyData ply;
    ply.comments = {"articula " + geometry::modelName(p.model) + " surface"};
    for (const char* name : {"x", "y", "z", "nx", "ny", "nz", "k1", "k2"}) ply.vertex_properties.push_back({name});
    ply.vertex_values.resize(mesh.vertices.rows(), 8);
    ply.faces = mesh.triangles;
    for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i) {
      const Eigen::Vector3d x = mesh.vertices.row(i).transpose();
      const geometry::Evaluation e = surface->evaluate(x, 1);
      const geometry::PrincipalCurvatures pc = geometry::principalCurvatures(*surface, x);
      max_abs_f = std::max(max_abs_f, std::fabs(e.value));
      k_min = std::min(k_min, pc.k2);
      k_max = std::max(k_max, pc.k1);
      ply.vertex_values.row(i) << x.transpose(), e.gradient.normalized().transpose(), pc.k1, pc.k2;
    }
    writeFileAtomically(output_, points::plyText(ply, points::PlyFormat::Ascii), common.force);

    nlohmann::json params = {{"model", geometry::modelName(p.model)}, {"resolution", resolution_}};
    const auto names = geometry::parameterNames(p.model);
    const Eigen::VectorXd lambda = geometry::toVector(p);
    for (size_t i = 0; i < names.size(); ++i) params["lambda"][names[i]] = lambda[static_cast<Eigen::Index>(i)];
    nlohmann::json summary = {{"output", output_.string()},
                              {"vertices", mesh.vertices.rows()},
                              {"triangles", mesh.triangles.rows()},
                              {"max_abs_F_at_vertices", max_abs_f},
                              {"curvature_min_per_mm", k_min},
                              {"curvature_max_per_mm", k_max},
                              {"provenance", provenanceJson({params, {}, -1})}};
    writeFileAtomically(output_.string() + ".json", summary.dump(2) + "\n", true);
    if (common.json) cli::printJson(summary);
    return 0;
  }

 private:
  std::string model_ = "superovoid";
  std::vector<double> radii_ = {24.0, 23.0, 22.0};
  std::vector<double> exponents_, cx_, cy_, center_, angles_deg_;
  int resolution_ = 96;
  std::filesystem::path output_;
};


ARTICULA_REGISTER_COMMAND(SurfaceCommand)

}  // namespace

}  // namespace articula::apps
