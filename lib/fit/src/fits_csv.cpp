#include "articula/fit/fits_csv.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace articula::fit {

std::string fitsCsv(const Summary& s) {
  // Standard errors after the values, one per parameter of the superovoid
  // (the widest model), in the values' units; empty where a model lacks the
  // parameter or the points cannot identify it.
  const auto all_names = geometry::parameterNames(geometry::ShapeModel::Superovoid);
  const auto all_kinds = geometry::parameterKinds(geometry::ShapeModel::Superovoid);
  std::ostringstream out;
  out << "model,a_mm,b_mm,c_mm,gamma1,gamma2,gamma3,c0x,c1x,c2x,c3x,c0y,c1y,c2y,c3y,t1_mm,t2_mm,t3_mm,"
         "phi_deg,theta_deg,psi_deg,rms_mm,sse_mm2,algebraic_objective,evaluations,seconds,converged";
  for (size_t k = 0; k < all_names.size(); ++k) {
    const std::string unit = all_kinds[k] == geometry::ParameterKind::Angle ? "deg" : geometry::parameterUnit(all_kinds[k]);
    out << ',' << all_names[k] << "_se" << (unit.empty() ? "" : "_" + unit);
  }
  out << "\n" << std::setprecision(12);
  for (const auto& f : s.fits) {
    const auto& p = f.parameters;
    const Eigen::Vector3d r = p.model == geometry::ShapeModel::Sphere ? Eigen::Vector3d::Constant(p.radii[0]) : p.radii;
    const Eigen::Vector3d deg = p.angles * (180.0 / M_PI);
    out << geometry::modelName(p.model);
    for (double v : {r[0], r[1], r[2], p.exponents[0], p.exponents[1], p.exponents[2], p.cx[0], p.cx[1], p.cx[2],
                     p.cx[3], p.cy[0], p.cy[1], p.cy[2], p.cy[3], p.center[0], p.center[1], p.center[2], deg[0],
                     deg[1], deg[2], f.rms_mm, f.sse_mm2, f.algebraic_objective})
      out << ',' << v;
    out << ',' << f.evaluations << ',' << f.seconds << ',' << (f.converged ? "true" : "false");
    const auto names = geometry::parameterNames(p.model);
    for (size_t k = 0; k < all_names.size(); ++k) {
      out << ',';
      const auto at = std::find(names.begin(), names.end(), all_names[k]);
      if (at == names.end() || f.uncertainty.standard_error.size() != static_cast<Eigen::Index>(names.size())) continue;
      const double se = f.uncertainty.standard_error[at - names.begin()];
      if (std::isfinite(se)) out << (all_kinds[k] == geometry::ParameterKind::Angle ? se * 180.0 / M_PI : se);
    }
    out << "\n";
  }
  return out.str();
}

}  // namespace articula::fit
