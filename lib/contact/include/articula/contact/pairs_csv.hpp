#pragma once
// The CSV files of `articula contact` (docs/formats.md): its results, a row
// per query, and its --pairs input: a header row, then
// one query per row: cx_a,cy_a,cz_a,qw_a,qx_a,qy_a,qz_a,ra_a,rb_a,rc_a,
// g1_a,g2_a,g3_a and the same with _b (quaternion w,x,y,z; exponents 2 =
// ellipsoid); an optional column shape_b: 'plane' takes b as the plane
// through cx_b,cy_b,cz_b with normal nx_b,ny_b,nz_b; 'sphere' or 'ellipsoid'
// may leave g1_b,g2_b,g3_b empty (and a sphere needs equal radii).
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "articula/contact/common_normal.hpp"
#include "articula/contact/convex_shape.hpp"

namespace articula::contact {

/// One non-blank data row of a pairs file. A row that cannot be used is
/// kept (valid false, with the reason), so that outputs stay row for row.
struct PairRow {
  int line = 0;             // 1-based line in the file
  bool valid = false;
  std::string reason;       // why the row is invalid
  ConvexShape a;
  bool plane = false;       // b is the plane (plane_point, plane_normal)
  ConvexShape b;            // when !plane
  Eigen::Vector3d plane_point = Eigen::Vector3d::Zero();
  Eigen::Vector3d plane_normal = Eigen::Vector3d::UnitZ();  // as given, not normalised
  std::vector<std::string> warnings;  // e.g. "line 3: quaternion a has length 2; normalised"
};

/// Reads a pairs file. Throws InputError for a file that cannot be read, is
/// empty, or whose header lacks a column every row needs (centres of a and b;
/// quaternion, radii and exponents of a). Any other problem makes its row
/// invalid: a cell count other than the header's, a non-numeric or
/// non-finite number, a zero quaternion, an unknown shape_b, values outside
/// makeConvexShape's range.
std::vector<PairRow> readPairsCsv(const std::filesystem::path& path);

/// The results' columns: the signed distance, the closest points of a and
/// b, the common normal, the solver's iterations and status.
inline constexpr const char* kResultsCsvHeader = "distance,pax,pay,paz,pbx,pby,pbz,nx,ny,nz,iterations,status";

/// One results row at the stream's precision; `suffix` (e.g. ",123.4") goes
/// before the newline.
void writeResultRow(std::ostream& out, const ContactResult& result, const std::string& suffix = "");

}  // namespace articula::contact
