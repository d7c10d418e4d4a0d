// bench-score-head TRUTH.json SIDE POINTS.ply [RESULTS.json]: scores a run's
// articular points against a phantom's true head of the given side (the
// exact signed distance of lib/distance to the head less its fovea pit, with
// its arthritic departures: a flattened dome's cut, osteophytes).
// Prints one JSON line: n_points, rms_mm, mean_signed_mm (positive outside),
// share_within_1p5_mm, max_abs_mm, model_rms_mm (to the head's model alone:
// differs from rms_mm where the head departs from its model) and, with
// RESULTS.json, centre_error_mm (results' head_center_mm to the true centre).
// Used by bench/robustness.py and bench/clinical.py.
// ARTICULA_SCORE_POINTS=FILE also writes each point's x,y,z,signed distance
// (mm) as CSV, to see where a head goes wrong; ARTICULA_SCORE_TRUE_POINTS=FILE
// writes each point's closest point on the head's model as x,y,z CSV (exact
// data on the run's cap: what the true shape differs from simpler models by).
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "articula/distance/signed_distance.hpp"
#include "articula/phantom/phantom.hpp"
#include "articula/points/point_io.hpp"

int main(int argc, char** argv) {
  if (argc < 4) {
    std::cerr << "usage: bench-score-head TRUTH.json right|left POINTS.ply [RESULTS.json]\n";
    return 2;
  }
  try {
    const nlohmann::json truth = nlohmann::json::parse(std::ifstream(argv[1]));
    const std::string side = argv[2];
    const nlohmann::json* head = nullptr;
    if (truth.contains("hips")) {
      for (const auto& h : truth["hips"])
        if (h["side"] == side) head = &h;
    } else if (truth["side"] == side) {
      head = &truth;  // a phantom from before hips[]
    }
    if (!head) {
      std::cerr << argv[1] << ": no " << side << " hip in hips[]\n";
      return 3;
    }
    const articula::phantom::Hip hip = articula::phantom::hipFromTruth(*head);
    const articula::distance::SignedDistance exact(hip.head);
    const articula::points::PointCloud cloud = articula::points::readPoints(argv[3]);
    const Eigen::Index n = cloud.positions.rows();
    std::ofstream per_point, true_points;
    if (const char* file = std::getenv("ARTICULA_SCORE_POINTS")) {
      per_point.open(file);
      per_point << "x,y,z,signed_mm\n";
    }
    if (const char* file = std::getenv("ARTICULA_SCORE_TRUE_POINTS")) {
      true_points.open(file);
      true_points.precision(17);
      true_points << "x,y,z\n";
    }
    double sum = 0, sum2 = 0, max_abs = 0, model2 = 0;
    long within = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Vector3d x = cloud.positions.row(i).transpose();
      const articula::distance::ClosestPoint closest = exact.closest(x);
      const double to_model = closest.distance;
      if (true_points.is_open())
        true_points << closest.point.x() << ',' << closest.point.y() << ',' << closest.point.z() << '\n';
      const double d = articula::phantom::headSurfaceDistance(hip, to_model, x);
      model2 += to_model * to_model;
      if (per_point.is_open()) per_point << x.x() << ',' << x.y() << ',' << x.z() << ',' << d << '\n';
      sum += d;
      sum2 += d * d;
      max_abs = std::max(max_abs, std::fabs(d));
      within += std::fabs(d) <= 1.5;
    }
    nlohmann::json out = {{"n_points", n},
                          {"rms_mm", n ? std::sqrt(sum2 / n) : NAN},
                          {"mean_signed_mm", n ? sum / n : NAN},
                          {"share_within_1p5_mm", n ? double(within) / n : 0.0},
                          {"max_abs_mm", max_abs},
                          {"model_rms_mm", n ? std::sqrt(model2 / n) : NAN}};
    if (argc > 4) {
      const nlohmann::json results = nlohmann::json::parse(std::ifstream(argv[4]));
      const nlohmann::json& c = results["head_center_mm"];
      out["centre_error_mm"] = (Eigen::Vector3d(c[0].get<double>(), c[1].get<double>(), c[2].get<double>()) - hip.head.center).norm();
    }
    std::cout << out.dump() << "\n";
  } catch (const std::exception& e) {
    std::cerr << "bench-score-head: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
