#include "articula/report/error_statistics.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/number_text.hpp"

namespace articula::report {

ErrorStatistics errorStatistics(const std::string& model, const Eigen::VectorXd& d) {
  if (d.size() == 0) throw InputError("error statistics for " + model + ": expected at least one distance, found none");
  ErrorStatistics s;
  s.model = model;
  const double n = static_cast<double>(d.size());
  s.n_points = static_cast<long>(d.size());
  s.min_mm = d.minCoeff();
  s.max_mm = d.maxCoeff();
  const Eigen::ArrayXd a = d.array().abs();
  s.mean_abs_mm = a.mean();
  s.sse_mm2 = d.squaredNorm();
  s.rms_mm = std::sqrt(s.sse_mm2 / n);
  s.gauss_mu_mm = d.mean();
  if (d.size() > 1) {
    s.std_abs_mm = std::sqrt((a - s.mean_abs_mm).square().sum() / (n - 1.0));
    s.gauss_sigma_mm = std::sqrt((d.array() - s.gauss_mu_mm).square().sum() / (n - 1.0));
  }
  return s;
}

const std::vector<std::string>& summaryColumns() {
  static const std::vector<std::string> columns = {"model",      "n_points",    "min_mm",         "max_mm",
                                                   "mean_abs_mm", "std_abs_mm", "rms_mm",         "gauss_mu_mm",
                                                   "gauss_sigma_mm", "sse_mm2"};
  return columns;
}

std::string summaryCsv(const std::vector<ErrorStatistics>& rows) {
  std::ostringstream out;
  const auto& columns = summaryColumns();
  for (size_t i = 0; i < columns.size(); ++i) out << (i ? "," : "") << columns[i];
  out << "\n" << std::setprecision(10);
  for (const auto& r : rows)
    out << r.model << ',' << r.n_points << ',' << r.min_mm << ',' << r.max_mm << ',' << r.mean_abs_mm << ','
        << r.std_abs_mm << ',' << r.rms_mm << ',' << r.gauss_mu_mm << ',' << r.gauss_sigma_mm << ',' << r.sse_mm2
        << "\n";
  return out.str();
}

nlohmann::json summaryJson(const std::vector<ErrorStatistics>& rows) {
  nlohmann::json array = nlohmann::json::array();
  for (const auto& r : rows)
    array.push_back({{"model", r.model},
                     {"n_points", r.n_points},
                     {"min_mm", r.min_mm},
                     {"max_mm", r.max_mm},
                     {"mean_abs_mm", r.mean_abs_mm},
                     {"std_abs_mm", r.std_abs_mm},
                     {"rms_mm", r.rms_mm},
                     {"gauss_mu_mm", r.gauss_mu_mm},
                     {"gauss_sigma_mm", r.gauss_sigma_mm},
                     {"sse_mm2", r.sse_mm2}});
  return array;
}

void writeErrorsCsv(const std::filesystem::path& path, const Eigen::MatrixX3d& points, const std::vector<std::string>& models,
                    const Eigen::MatrixXd& distances, bool overwrite) {
  AtomicFile file(path, overwrite);
  std::ostream& out = file.stream();
  out << "x_mm,y_mm,z_mm";
  for (const auto& name : models) out << ",d_" << name << "_mm";
  out << "\n";
  std::string row;
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    row.clear();
    for (int k = 0; k < 3; ++k) {
      if (k) row += ',';
      appendNumber(row, points(i, k));
    }
    for (Eigen::Index m = 0; m < distances.cols(); ++m) {
      row += ',';
      appendNumber(row, distances(i, m));
    }
    row += '\n';
    out << row;
  }
  file.commit();
}

}  // namespace articula::report
