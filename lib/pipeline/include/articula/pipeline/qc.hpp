#pragma once
// Checks that reveal a wrong structure taken for a joint head: the fitted
// head's radius against plausible heads, the angular extent of the
// articular cap, the share of point normals pointing away from the head's
// centre (a socket's inner surface points towards it), the points' spread
// about their sphere, the agreement of the head search with the fit, and
// whether the search could tell the joint's side.
// Each check passes, warns (doubtful) or fails (the result is not a head).
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

namespace articula::pipeline {

struct HeadQcInput {
  Eigen::MatrixX3d points;                   // articular points (LPS mm)
  Eigen::MatrixX3d normals;                  // their outward normals (may be empty: that check is skipped)
  Eigen::Vector3d sphere_center = Eigen::Vector3d::Zero();  // the fitted sphere
  double sphere_radius_mm = 0;
  std::optional<Eigen::Vector3d> search_center;  // the segmentation's head, if it searched
  double search_radius_mm = 0;
  std::optional<bool> side_verified;             // the search's side check, if it searched
  double min_radius_mm = 15, max_radius_mm = 35;  // plausible joint heads
};

struct QcCheck {
  std::string name, status;  // status: pass, warn or fail
  double value = 0;
  std::string rule, reason;  // the limits; why it warned or failed (empty on pass)
};

struct QcReport {
  std::string status = "pass";  // the worst of the checks
  std::vector<QcCheck> checks;
  std::vector<std::string> reasons() const;  // of every check that did not pass
  nlohmann::json toJson() const;
};

/// Runs every check that its inputs allow; throws InputError for fewer than 4 points.
QcReport checkHead(const HeadQcInput& input);

}  // namespace articula::pipeline
