#pragma once
// ASCII PLY files for ParaView and 3D Slicer (coordinates LPS, mm).
#include <string>

#include <Eigen/Core>

namespace articula::report {

/// Points (#P x 3) coloured by signed distance d (#P) as thesis fig. 3.4: red
/// inside (d < -band), green within the band, blue outside (d > band); d is
/// also a scalar property "signed_distance_mm".
std::string colouredPointsPly(const Eigen::MatrixX3d& points, const Eigen::VectorXd& d, double band_mm,
                              const std::string& comment);

/// A triangle mesh: vertices (#V x 3), triangles (#F x 3, 0-based).
std::string meshPly(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& triangles, const std::string& comment);

}  // namespace articula::report
