// bench-coverage CASES.json [METHOD ...]: how often the 95 % intervals of a run's fits
// hold the true head, for each way of computing them (fit/uncertainty.hpp).
// CASES.json is a list of {"id", "points" (points.ply), "fits" (fits.json),
// "truth": {"model" (optional, default ellipsoid), "center_mm", "radii_mm",
// "angles_rad" or "axes_columns" (3 x 3, the axes as columns), "exponents",
// "cx", "cy" (optional)}} made by bench/coverage.py. For every model of
// fits.json that contains the true model (a superellipsoid holds an
// ellipsoid's centre and radii) and every method, prints one JSON line with
// the errors in standard errors (z) of the centre (t1, t2, t3) and of the
// semi-axes, each matched to the true axis it lies along, against the true
// semi-axes and against them moved by the shared offset (the points' median
// signed distance to the true surface, which no interval holds), and the
// residual correlation. Used by bench/coverage.py.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "articula/distance/signed_distance.hpp"
#include "articula/fit/fit_hierarchy.hpp"
#include "articula/fit/fits_json.hpp"
#include "articula/fit/uncertainty.hpp"
#include "articula/geometry/pose.hpp"
#include "articula/points/point_io.hpp"
#include "articula/testsupport/interval_errors.hpp"

namespace {

using articula::geometry::ShapeModel;
using articula::geometry::ShapeParameters;

Eigen::Vector3d vec3(const nlohmann::json& j) { return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()}; }

ShapeParameters truthShape(const nlohmann::json& t) {
  ShapeParameters p;
  p.model = articula::geometry::modelFromName(t.value("model", std::string("ellipsoid")));
  if (p.model == ShapeModel::Sphere) p.model = ShapeModel::Ellipsoid;  // one radius, three axes to match
  p.center = vec3(t.at("center_mm"));
  p.radii = vec3(t.at("radii_mm"));
  if (t.contains("angles_rad")) p.angles = vec3(t.at("angles_rad"));
  if (t.contains("axes_columns")) {
    Eigen::Matrix3d A;
    for (int c = 0; c < 3; ++c) A.col(c) = vec3(t.at("axes_columns")[static_cast<size_t>(c)]);
    if (A.determinant() < 0) A.col(2) *= -1;
    p.angles = articula::geometry::anglesFromRotation(A);
  }
  if (t.contains("exponents")) p.exponents = vec3(t.at("exponents"));
  for (int k = 0; k < 4 && t.contains("cx"); ++k) p.cx[k] = t.at("cx")[static_cast<size_t>(k)].get<double>();
  for (int k = 0; k < 4 && t.contains("cy"); ++k) p.cy[k] = t.at("cy")[static_cast<size_t>(k)].get<double>();
  return p;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: bench-coverage CASES.json [METHOD ...]\n";
    return 2;
  }
  using articula::fit::UncertaintyMethod;
  std::vector<UncertaintyMethod> methods = {UncertaintyMethod::Independent, UncertaintyMethod::SpatialModel,
                                            UncertaintyMethod::SpatialHac, UncertaintyMethod::PatchBootstrap};
  if (argc > 2) methods.clear();
  for (int a = 2; a < argc; ++a) methods.push_back(articula::fit::uncertaintyMethodFromName(argv[a]));
  const nlohmann::json cases = nlohmann::json::parse(std::ifstream(argv[1]));
  for (const auto& c : cases) {
    try {
      const ShapeParameters truth = truthShape(c.at("truth"));
      const ShapeModel true_model = articula::geometry::modelFromName(c.at("truth").value("model", std::string("ellipsoid")));
      const Eigen::MatrixX3d points = articula::points::readPoints(c.at("points").get<std::string>()).positions;
      const nlohmann::json fits = nlohmann::json::parse(std::ifstream(c.at("fits").get<std::string>()));
      const auto shapes = articula::fit::shapesFromFitsJson(fits, c.at("fits").get<std::string>());
      // The shared offset: the points' median signed distance to the true surface.
      Eigen::VectorXd d;
      Eigen::MatrixX3d feet;
      articula::distance::SignedDistance(truth).evaluate(points, d, feet);
      std::vector<double> sorted(d.data(), d.data() + d.size());
      std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
      const double offset = sorted[sorted.size() / 2];
      for (const auto& shape : shapes) {
        if (!articula::geometry::contains(shape.model, true_model)) continue;
        for (auto method : methods) {
          articula::fit::EdgeOffsetField field;
          if (c.contains("spacing_mm"))
            field = articula::fit::edgeOffsetField(vec3(c.at("spacing_mm")), vec3(c.at("slice_axis")));
          auto u = articula::fit::parameterUncertainty(shape, points, {}, method, field);
          // An egg's intervals take in its other optima, as the fit's do.
          const auto ellipsoid = std::find_if(shapes.begin(), shapes.end(), [](const ShapeParameters& s) { return s.model == ShapeModel::Ellipsoid; });
          if (articula::geometry::contains(shape.model, ShapeModel::Ovoid) && ellipsoid != shapes.end()) {
            articula::fit::Options o;
            o.uncertainty = method;
            o.edge_offset = field;
            articula::fit::spanEggOptima(*ellipsoid, shape, points, o, u);
          }
          const articula::fit::IntervalErrors z = articula::fit::intervalErrors(shape, u, truth, offset);
          auto list = [](const Eigen::Vector3d& v) { return nlohmann::json{v[0], v[1], v[2]}; };
          const auto& r = u.correlation;
          std::cout << nlohmann::json{{"id", c.at("id")},
                                      {"true_model", articula::geometry::modelName(true_model)},
                                      {"model", articula::geometry::modelName(shape.model)},
                                      {"method", u.method},
                                      {"offset_mm", offset},
                                      {"edge_offset_sd_mm", {field.linear_sd_mm, field.across_slices_sd_mm, field.odd_across_slices_sd_mm}},
                                      {"centre_z", list(z.centre_z)},
                                      {"radius_z", list(z.semi_axis_z)},
                                      {"radius_less_offset_z", list(z.semi_axis_less_offset_z)},
                                      {"n", r.n},
                                      {"n_eff", r.n_eff},
                                      {"lengths_mm", {r.length_mm[0], r.length_mm[1]}},
                                      {"correlated_share", r.correlatedShare()}}
                           .dump()
                    << "\n";
        }
      }
    } catch (const std::exception& e) {
      std::cerr << c.value("id", std::string("?")) << ": " << e.what() << "\n";
    }
  }
  return 0;
}
