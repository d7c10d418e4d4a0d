#pragma once
// Statistics of signed surface errors, as thesis tables 3.3 and 3.4.
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

namespace articula::report {

struct ErrorStatistics {
  std::string model;
  long n_points = 0;
  double min_mm = 0.0, max_mm = 0.0;        // of the signed distances d (table 3.3)
  double mean_abs_mm = 0.0, std_abs_mm = 0.0;  // of |d|; std with N - 1 (table 3.3)
  double rms_mm = 0.0;                       // sqrt(mean d^2) (table 3.3)
  double gauss_mu_mm = 0.0, gauss_sigma_mm = 0.0;  // normal fitted to d (table 3.4)
  double sse_mm2 = 0.0;                      // sum d^2
};

/// Statistics of the signed distances `d` (#P, mm). The Gaussian of table 3.4
/// is the maximum-likelihood normal with the unbiased sigma, which is what
/// MATLAB's histfit (normfit) draws over a histogram. Throws InputError if empty.
ErrorStatistics errorStatistics(const std::string& model, const Eigen::VectorXd& d);

/// Column names of summary.csv, in order.
const std::vector<std::string>& summaryColumns();
/// summary.csv: a header row then one row per model.
std::string summaryCsv(const std::vector<ErrorStatistics>& rows);

/// errors.csv: a row per point, x_mm,y_mm,z_mm and its signed distance to
/// each model (d_<model>_mm: `distances` holds a column per name of
/// `models`), written atomically to `path` (refused if it exists, unless
/// `overwrite`).
void writeErrorsCsv(const std::filesystem::path& path, const Eigen::MatrixX3d& points, const std::vector<std::string>& models,
                    const Eigen::MatrixXd& distances, bool overwrite);
/// One JSON object per row, keyed by summaryColumns().
nlohmann::json summaryJson(const std::vector<ErrorStatistics>& rows);

}  // namespace articula::report
