#include "articula/contact/pairs_csv.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <map>
#include <stdexcept>

#include <Eigen/Geometry>

#include "articula/core/csv.hpp"
#include "articula/core/error.hpp"

namespace articula::contact {

namespace {

using Eigen::Vector3d;

// A row that cannot be used; its message becomes PairRow::reason.
struct BadRow : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Row {
  const std::map<std::string, size_t>& columns;
  const std::vector<std::string>& cells;
  const std::string& text(const std::string& name) const {
    const auto it = columns.find(name);
    if (it == columns.end()) throw BadRow("column '" + name + "' is missing from the header");
    return cells[it->second];
  }
  bool empty(const std::string& name) const { return columns.count(name) == 0 || cells[columns.at(name)].empty(); }
  double number(const std::string& name) const {
    const std::string& text = this->text(name);
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || end != text.c_str() + text.size()) throw BadRow(name + ": expected a number, found '" + text + "'");
    if (!std::isfinite(v)) throw BadRow(name + ": expected a finite number, found '" + text + "'");
    return v;
  }
  Vector3d vec(const std::string& x, const std::string& y, const std::string& z) const {
    return {number(x), number(y), number(z)};
  }
};

// Shape "a" or "b" of a row; warns when the quaternion had to be normalised.
// `kind` (shape_b): "sphere" and "ellipsoid" take empty exponent cells as 2
// and reject others; "sphere" also needs three equal radii.
ConvexShape rowShape(const Row& r, const std::string& s, int line, std::vector<std::string>& warnings,
                     const std::string& kind = "") {
  const Eigen::Vector4d q(r.number("qw_" + s), r.number("qx_" + s), r.number("qy_" + s), r.number("qz_" + s));
  const double len = q.norm();
  if (!(len > 1e-12)) throw BadRow("quaternion " + s + " is zero");
  if (std::fabs(len - 1.0) > 1e-9)
    warnings.push_back("line " + std::to_string(line) + ": quaternion " + s + " has length " + std::to_string(len) +
                       "; normalised");
  const Eigen::Matrix3d R = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
  const Vector3d radii = r.vec("ra_" + s, "rb_" + s, "rc_" + s);
  Vector3d exponents(2.0, 2.0, 2.0);
  const bool quadric = kind == "sphere" || kind == "ellipsoid";
  for (int i = 0; i < 3; ++i) {
    const std::string column = "g" + std::to_string(i + 1) + "_" + s;
    if (quadric && r.empty(column)) continue;
    exponents[i] = r.number(column);
    if (quadric && exponents[i] != 2.0)
      throw BadRow(column + ": expected 2 or an empty cell (shape_" + s + " is " + kind + "), found " + r.text(column));
  }
  if (kind == "sphere" && !(radii.maxCoeff() - radii.minCoeff() <= 1e-12 * radii.maxCoeff()))
    throw BadRow("shape_" + s + " is sphere: expected ra_" + s + " = rb_" + s + " = rc_" + s + ", found " +
                 r.text("ra_" + s) + ", " + r.text("rb_" + s) + ", " + r.text("rc_" + s));
  try {
    return makeConvexShape(r.vec("cx_" + s, "cy_" + s, "cz_" + s), R, radii, exponents);
  } catch (const InvalidParameter& e) {
    throw BadRow("shape " + s + ": " + e.what());
  }
}

void parseRow(PairRow& pair, const std::map<std::string, size_t>& columns, const std::vector<std::string>& cells,
              std::size_t header_size) {
  if (cells.size() != header_size)
    throw BadRow("expected " + std::to_string(header_size) + " cells, found " + std::to_string(cells.size()));
  const Row row{columns, cells};
  pair.a = rowShape(row, "a", pair.line, pair.warnings);
  std::string kind = row.empty("shape_b") ? "" : row.text("shape_b");
  std::transform(kind.begin(), kind.end(), kind.begin(), [](unsigned char c) { return std::tolower(c); });
  if (kind != "" && kind != "plane" && kind != "sphere" && kind != "ellipsoid" && kind != "superellipsoid")
    throw BadRow("shape_b: expected plane, sphere, ellipsoid, superellipsoid or empty, found '" + row.text("shape_b") +
                 "'");
  pair.plane = kind == "plane";
  if (pair.plane) {
    pair.plane_point = row.vec("cx_b", "cy_b", "cz_b");
    pair.plane_normal = row.vec("nx_b", "ny_b", "nz_b");
    if (!(pair.plane_normal.norm() > 0.0)) throw BadRow("plane normal nx_b,ny_b,nz_b is zero");
  } else {
    pair.b = rowShape(row, "b", pair.line, pair.warnings, kind);
  }
}

}  // namespace

std::vector<PairRow> readPairsCsv(const std::filesystem::path& path) {
  // Rows as read: a row of the wrong length is that row's problem, not the file's.
  const CsvTable table = readCsv(path, {true});
  std::map<std::string, size_t> columns;
  for (size_t i = 0; i < table.header.size(); ++i) columns[table.header[i]] = i;
  std::vector<std::string> missing;
  for (const char* s : {"a", "b"})
    for (const char* c : {"cx", "cy", "cz"})
      if (!columns.count(std::string(c) + "_" + s)) missing.push_back(std::string(c) + "_" + s);
  for (const char* c : {"qw", "qx", "qy", "qz", "ra", "rb", "rc", "g1", "g2", "g3"})
    if (!columns.count(std::string(c) + "_a")) missing.push_back(std::string(c) + "_a");
  if (!missing.empty()) {
    std::string list;
    for (const auto& m : missing) list += (list.empty() ? "" : ", ") + m;
    throw InputError(path.string() + ":1: header lacks column(s) " + list);
  }

  std::vector<PairRow> rows;
  for (size_t i = 0; i < table.rows.size(); ++i) {
    PairRow& pair = rows.emplace_back();
    pair.line = table.row_lines[i];
    try {
      parseRow(pair, columns, table.rows[i], table.header.size());
      pair.valid = true;
    } catch (const BadRow& e) {
      pair.reason = e.what();
    }
  }
  return rows;
}

void writeResultRow(std::ostream& out, const ContactResult& result, const std::string& suffix) {
  out << result.distance;
  for (const Eigen::Vector3d* v : {&result.point_a, &result.point_b, &result.normal})
    out << ',' << (*v)[0] << ',' << (*v)[1] << ',' << (*v)[2];
  out << ',' << result.summary.iterations << ',' << statusName(result.summary.status) << suffix << '\n';
}

}  // namespace articula::contact
