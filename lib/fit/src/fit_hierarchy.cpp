#include "articula/fit/fit_hierarchy.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include <Eigen/Geometry>
#include <nlopt.hpp>

#include "articula/core/error.hpp"
#include "articula/core/log.hpp"
#include "articula/distance/signed_distance.hpp"
#include "articula/fit/algebraic_start.hpp"
#include "articula/fit/parameter_gradient.hpp"
#include "articula/geometry/pose.hpp"
#include "articula/geometry/surface.hpp"

namespace articula::fit {

using Eigen::VectorXd;
using geometry::ShapeModel;
using geometry::ShapeParameters;

std::string objectiveName(Objective o) { return o == Objective::Algebraic ? "algebraic" : "geometric"; }
Objective objectiveFromName(const std::string& name) {
  if (name == "algebraic") return Objective::Algebraic;
  if (name == "geometric") return Objective::Geometric;
  throw UsageError("--objective: expected 'algebraic' or 'geometric', found '" + name + "'");
}
std::string strategyName(Strategy s) { return s == Strategy::Local ? "local" : "global-local"; }
Strategy strategyFromName(const std::string& name) {
  if (name == "local") return Strategy::Local;
  if (name == "global-local") return Strategy::GlobalLocal;
  throw UsageError("--strategy: expected 'local' or 'global-local', found '" + name + "'");
}

namespace {
nlopt::algorithm localAlgorithm(const std::string& name) {
  for (auto a : {nlopt::LN_BOBYQA, nlopt::LD_SLSQP, nlopt::LD_LBFGS, nlopt::LD_MMA, nlopt::LD_TNEWTON_PRECOND_RESTART})
    if (name == nlopt::algorithm_name(a) || name == nlopt_algorithm_to_string(static_cast<nlopt_algorithm>(a)))
      return a;
  throw UsageError("local_algorithm: expected LN_BOBYQA, LD_SLSQP, LD_LBFGS, LD_MMA or LD_TNEWTON_PRECOND_RESTART, found '" +
                   name + "'");
}

}  // namespace

void Options::validate() const {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw UsageError("fit options: " + what);
  };
  require(!models.empty(), "models: expected at least one model");
  localAlgorithm(local_algorithm);
  require(max_evaluations > 0, "max_evaluations: expected > 0");
  require(global_evaluations > 0, "global_evaluations: expected > 0");
  require(screening_evaluations >= 0 && screening_points >= 0 && restarts >= 0,
          "screening_evaluations, screening_points, restarts: expected >= 0");
  require(relative_tolerance >= 0.0 && parameter_tolerance >= 0.0, "tolerances: expected >= 0");
  require(radius_interval > 0.0 && radius_interval < 1.0, "radius_interval: expected in (0, 1)");
  require(center_interval > 0.0, "center_interval: expected > 0");
  require(exponent_min >= 2.0 && exponent_max >= exponent_min, "exponent bounds: expected 2 <= min <= max");
  require(c01_min <= 1.0 && c01_max >= 1.0 && c01_min <= 0.0, "c0/c1 bounds: expected to contain 0 and 1");
  require(c23_min <= 0.0 && c23_max >= 0.0, "c2/c3 bounds: expected to contain 0");
  const auto names = geometry::parameterNames(ShapeModel::Superovoid);
  for (const auto& [name, range] : bounds) {
    require(std::find(names.begin(), names.end(), name) != names.end(),
            "bounds: unknown parameter '" + name + "' (expected a name of thesis table 3.2)");
    require(range.first <= range.second, "bounds: lower > upper for '" + name + "'");
  }
}

double algebraicObjective(const ShapeParameters& shape, const Eigen::MatrixX3d& points) {
  const auto surface = geometry::makeSurface(shape);
  double sum = 0.0;
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const double f = surface->value(points.row(i).transpose());
    sum += f * f;
  }
  return sum;
}

double geometricObjective(const ShapeParameters& shape, const Eigen::MatrixX3d& points) {
  return distance::signedDistances(shape, points).squaredNorm();
}

namespace {

using Clock = std::chrono::steady_clock;

struct Bounds {
  VectorXd lower, upper;
};

// Parameter bounds of thesis section 3.2.5 around the reference start.
Bounds makeBounds(ShapeModel model, const ShapeParameters& reference, const ShapeParameters& sphere,
                  const Options& o) {
  const double r_min = std::min(reference.radii.minCoeff(), sphere.radii[0]);
  const double r_max = std::max(reference.radii.maxCoeff(), sphere.radii[0]);
  const auto names = geometry::parameterNames(model);
  Bounds b{VectorXd(names.size()), VectorXd(names.size())};
  for (size_t k = 0; k < names.size(); ++k) {
    const std::string& n = names[k];
    const Eigen::Index i = static_cast<Eigen::Index>(k);
    double lo = 0.0, hi = 0.0;
    if (n == "a" || n == "b" || n == "c") {
      lo = (1.0 - o.radius_interval) * r_min;
      hi = (1.0 + o.radius_interval) * r_max;
    } else if (n.rfind("gamma", 0) == 0) {
      lo = o.exponent_min;
      hi = o.exponent_max;
    } else if (n[0] == 'c' && (n[1] == '0' || n[1] == '1')) {
      lo = o.c01_min;
      hi = o.c01_max;
    } else if (n[0] == 'c') {
      lo = o.c23_min;
      hi = o.c23_max;
    } else if (n[0] == 't') {
      const int axis = n[1] - '1';
      lo = std::min(reference.center[axis], sphere.center[axis]) - o.center_interval * r_max;
      hi = std::max(reference.center[axis], sphere.center[axis]) + o.center_interval * r_max;
    } else {
      // Angles: set per run to start +- pi (a full turn, so wrapping never blocks).
      lo = -std::numeric_limits<double>::infinity();
      hi = std::numeric_limits<double>::infinity();
    }
    if (auto it = o.bounds.find(n); it != o.bounds.end()) {
      lo = it->second.first;
      hi = it->second.second;
    }
    b.lower[i] = lo;
    b.upper[i] = hi;
  }
  return b;
}

// Initial trust-region steps, in each parameter's own units.
VectorXd initialSteps(ShapeModel model, const ShapeParameters& start) {
  const auto names = geometry::parameterNames(model);
  VectorXd step(names.size());
  const double r = start.radii.maxCoeff();
  for (size_t k = 0; k < names.size(); ++k) {
    const std::string& n = names[k];
    const Eigen::Index i = static_cast<Eigen::Index>(k);
    if (n == "a" || n == "b" || n == "c") step[i] = 0.02 * r;
    else if (n[0] == 't') step[i] = 0.02 * r;
    else if (n.rfind("gamma", 0) == 0) step[i] = 0.05;
    else if (n[0] == 'c') step[i] = 0.01;
    else step[i] = 0.05;  // angles (rad)
  }
  return step;
}

// The objective seen by NLopt, in scaled variables x = (lambda - lambda0) / s
// so that every parameter moves on a unit scale; it remembers the best point
// it was shown, so a run never returns anything worse than its start.
class ObjectiveFunction {
 public:
  ObjectiveFunction(ShapeModel model, const Eigen::MatrixX3d& points, Objective kind, VectorXd origin, VectorXd scale)
      : model_(model), points_(points), kind_(kind), origin_(std::move(origin)), scale_(std::move(scale)) {}

  VectorXd toLambda(const double* x) const {
    return origin_ + scale_.cwiseProduct(Eigen::Map<const VectorXd>(x, origin_.size()));
  }

  double operator()(const std::vector<double>& x, std::vector<double>& grad) {
    ++evaluations;
    const VectorXd lambda = toLambda(x.data());
    double f = 0.0;
    try {
      const ShapeParameters p = geometry::fromVector(model_, lambda);
      if (kind_ == Objective::Algebraic) {
        const auto surface = geometry::makeSurface(p);
        d_.resize(points_.rows());
        for (Eigen::Index i = 0; i < points_.rows(); ++i) d_[i] = surface->value(points_.row(i).transpose());
      } else {
        const distance::SignedDistance field(p);
        feet_ = best_feet_;
        field.evaluate(points_, d_, feet_, best_feet_.rows() == points_.rows());
      }
      f = d_.squaredNorm();
      if (!grad.empty()) gradient(p, grad);
    } catch (const InvalidParameter&) {
      // Outside the valid set (e.g. an ovoid denominator reaching 0 on [-1, 1]).
      if (!grad.empty()) std::fill(grad.begin(), grad.end(), 0.0);
      return std::isfinite(best_value) ? 10.0 * best_value + 1.0 : 1e30;
    }
    if (!std::isfinite(f)) return 1e30;
    if (f < best_value) {
      best_value = f;
      best_lambda = lambda;
      if (kind_ == Objective::Geometric) best_feet_ = feet_;
    }
    return f;
  }

  static double call(const std::vector<double>& x, std::vector<double>& grad, void* self) {
    return (*static_cast<ObjectiveFunction*>(self))(x, grad);
  }

  int evaluations = 0;
  double best_value = std::numeric_limits<double>::infinity();
  VectorXd best_lambda;

 private:
  void gradient(const ShapeParameters& p, std::vector<double>& grad) const {
    Eigen::MatrixXd J;
    VectorXd norms;
    if (kind_ == Objective::Algebraic) {
      parameterGradient(p, points_, J, norms);
    } else {
      parameterGradient(p, feet_, J, norms);
      J.array().colwise() /= norms.array();
    }
    const VectorXd g = 2.0 * (J.transpose() * d_).cwiseProduct(scale_);
    std::copy(g.data(), g.data() + g.size(), grad.begin());
  }

  ShapeModel model_;
  const Eigen::MatrixX3d& points_;
  Objective kind_;
  VectorXd origin_, scale_;
  VectorXd d_;
  Eigen::MatrixX3d feet_, best_feet_;
};

std::string resultName(nlopt::result r) {
  switch (r) {
    case nlopt::SUCCESS: return "success";
    case nlopt::STOPVAL_REACHED: return "stopval reached";
    case nlopt::FTOL_REACHED: return "objective tolerance reached";
    case nlopt::XTOL_REACHED: return "parameter tolerance reached";
    case nlopt::MAXEVAL_REACHED: return "evaluation limit reached";
    case nlopt::MAXTIME_REACHED: return "time limit reached";
    default: return "failure (" + std::to_string(static_cast<int>(r)) + ")";
  }
}

struct RunResult {
  VectorXd x;
  double value = 0.0;
  int evaluations = 0;
  std::string termination;
  bool converged = false;
};

// One NLopt run of `algorithm` from `start` within `bounds`, in variables
// scaled by `steps`.
RunResult runNlopt(nlopt::algorithm algorithm, ShapeModel model, const VectorXd& start, const Bounds& bounds,
                   const VectorXd& steps, int max_evaluations, const Eigen::MatrixX3d& points, const Options& o) {
  const unsigned n = static_cast<unsigned>(start.size());
  ObjectiveFunction objective(model, points, o.objective, start, steps);
  std::vector<double> x(n, 0.0), no_gradient;
  objective(x, no_gradient);  // the start is always a candidate
  const VectorXd lower = (bounds.lower - start).cwiseQuotient(steps);
  const VectorXd upper = (bounds.upper - start).cwiseQuotient(steps);
  nlopt::srand(o.seed);
  nlopt::opt opt(algorithm, n);
  opt.set_lower_bounds(std::vector<double>(lower.data(), lower.data() + n));
  opt.set_upper_bounds(std::vector<double>(upper.data(), upper.data() + n));
  opt.set_min_objective(&ObjectiveFunction::call, &objective);
  opt.set_ftol_rel(o.relative_tolerance);
  opt.set_xtol_rel(o.parameter_tolerance);
  opt.set_maxeval(max_evaluations);
  if (algorithm == nlopt::LN_BOBYQA) opt.set_initial_step(1.0);
  double value = 0.0;
  RunResult result;
  try {
    const nlopt::result r = opt.optimize(x, value);
    result.termination = resultName(r);
    result.converged = r == nlopt::SUCCESS || r == nlopt::FTOL_REACHED || r == nlopt::XTOL_REACHED ||
                       r == nlopt::STOPVAL_REACHED;
  } catch (const nlopt::roundoff_limited&) {
    // Reached the minimum to rounding: keep the best point.
    result.termination = "roundoff limited";
    result.converged = true;
  } catch (const std::exception& e) {
    result.termination = std::string("NLopt stopped: ") + e.what();
  }
  result.x = objective.best_lambda;
  result.value = objective.best_value;
  result.evaluations = objective.evaluations;
  return result;
}

Bounds boundsForStart(Bounds b, ShapeModel model, const VectorXd& start) {
  const auto names = geometry::parameterNames(model);
  for (Eigen::Index i = 0; i < start.size(); ++i) {
    const std::string& n = names[static_cast<size_t>(i)];
    if (n == "phi" || n == "theta" || n == "psi") {
      b.lower[i] = start[i] - M_PI;
      b.upper[i] = start[i] + M_PI;
    }
    // A parent's optimum always lies inside the child's box.
    b.lower[i] = std::min(b.lower[i], start[i]);
    b.upper[i] = std::max(b.upper[i], start[i]);
  }
  return b;
}

ShapeParameters wrapAngles(ShapeParameters p) {
  // Normalise through the rotation matrix: same rotation, canonical angles.
  p.angles = geometry::anglesFromRotation(geometry::rotationFromAngles(p.angles));
  return p;
}

double rmsOf(const ShapeParameters& p, const Eigen::MatrixX3d& points, double& sse) {
  sse = geometricObjective(p, points);
  return std::sqrt(sse / static_cast<double>(points.rows()));
}

// Every k-th point, about `target` of them (all if target is 0 or above
// half the points): enough to rank starts at a fraction of the cost.
Eigen::MatrixX3d subsample(const Eigen::MatrixX3d& points, int target) {
  const Eigen::Index k = target > 0 ? points.rows() / target : 0;
  if (k < 2) return points;
  Eigen::MatrixX3d out((points.rows() + k - 1) / k, 3);
  for (Eigen::Index i = 0; i < out.rows(); ++i) out.row(i) = points.row(i * k);
  return out;
}

// Fits `model` from each start (label, parameters) and keeps the best.
// With `screen` > 0 and several starts, every start first gets `screen`
// evaluations on a subsample of the points (Options::screening_points) and
// only the best one is run to convergence on all of them.
ModelFit fitModel(ShapeModel model, std::vector<std::pair<std::string, ShapeParameters>> starts,
                  const Bounds& model_bounds, const Eigen::MatrixX3d& points, const Options& o, int screen = 0) {
  const auto t0 = Clock::now();
  const nlopt::algorithm local = localAlgorithm(o.local_algorithm);
  ModelFit best;
  double best_value = std::numeric_limits<double>::infinity();
  int screening_evaluations = 0;
  if (screen > 0 && starts.size() > 1) {
    Options short_run = o;
    short_run.max_evaluations = screen;
    short_run.strategy = Strategy::Local;
    std::pair<std::string, ShapeParameters> winner;
    const Eigen::MatrixX3d screen_points = subsample(points, o.screening_points);
    for (const auto& [label, start_shape] : starts) {
      const ShapeParameters start = geometry::promote(start_shape, model);
      const VectorXd x0 = geometry::toVector(start);
      const RunResult r = runNlopt(local, model, x0, boundsForStart(model_bounds, model, x0),
                                   initialSteps(model, start), screen, screen_points, short_run);
      screening_evaluations += r.evaluations;
      if (r.value < best_value) {
        best_value = r.value;
        winner = {label, geometry::fromVector(model, r.x)};
      }
    }
    starts = {winner};
    best_value = std::numeric_limits<double>::infinity();
  }
  best.evaluations = screening_evaluations;
  for (const auto& [label, start_shape] : starts) {
    const ShapeParameters start = geometry::promote(start_shape, model);
    const VectorXd x0 = geometry::toVector(start);
    const Bounds b = boundsForStart(model_bounds, model, x0);
    const VectorXd steps = initialSteps(model, start);
    RunResult run;
    int evaluations = 0;
    std::string how;
    if (o.strategy == Strategy::GlobalLocal && model != ShapeModel::Sphere) {
      const RunResult global =
          runNlopt(nlopt::GN_CRS2_LM, model, x0, b, steps, o.global_evaluations, points, o);
      evaluations += global.evaluations;
      how = "GN_CRS2_LM (" + global.termination + ") then ";
      run = runNlopt(local, model, global.x, b, steps, o.max_evaluations, points, o);
    } else {
      run = runNlopt(local, model, x0, b, steps, o.max_evaluations, points, o);
    }
    evaluations += run.evaluations;
    // SLSQP's objective test can stop on a short step while still descending:
    // restart (a fresh quasi-Newton model) while that still gains.
    for (int restart = 0; restart < o.restarts; ++restart) {
      const RunResult again = runNlopt(local, model, run.x, b, steps, o.max_evaluations, points, o);
      evaluations += again.evaluations;
      const bool gained = again.value < run.value * (1.0 - 1e-6) && again.value > 1e-20 * static_cast<double>(points.rows());
      if (again.value < run.value) run = again;
      if (!gained) break;
    }
    best.evaluations += evaluations;
    if (run.value < best_value) {
      best_value = run.value;
      best.parameters = wrapAngles(geometry::fromVector(model, run.x));
      best.termination = how + o.local_algorithm + ": " + run.termination;
      best.converged = run.converged;
      best.started_from = label;
    }
  }
  if (starts.size() > 1) {
    std::string all;
    for (const auto& s : starts) all += (all.empty() ? "" : ",") + s.first;
    best.started_from += " (best of " + all + ")";
  }
  best.rms_mm = rmsOf(best.parameters, points, best.sse_mm2);
  best.algebraic_objective = algebraicObjective(best.parameters, points);
  best.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return best;
}

// The six labellings of an ellipsoid's axes with a right-handed frame (local
// z along each axis, either way): the same surface, but distinct starts for
// the ovoid, whose asymmetry runs along local z (c1 >= 0: wider towards +z).
std::vector<std::pair<std::string, ShapeParameters>> axisLabellings(const ShapeParameters& e) {
  const Eigen::Matrix3d R = geometry::rotationFromAngles(e.angles);
  std::vector<std::pair<std::string, ShapeParameters>> out;
  for (int k = 2; k < 5; ++k)
    for (double sign : {1.0, -1.0}) {
      const int iz = k % 3, ix = (k + 1) % 3, iy = (k + 2) % 3;
      Eigen::Matrix3d L;
      L.col(2) = sign * R.col(iz);
      L.col(0) = R.col(ix);
      L.col(1) = L.col(2).cross(L.col(0));
      ShapeParameters p = e;
      p.radii = Eigen::Vector3d(e.radii[ix], e.radii[iy], e.radii[iz]);
      p.angles = geometry::anglesFromRotation(L);
      out.emplace_back(std::string("ellipsoid (z = ") + (sign > 0 ? "+" : "-") + "xyz"[iz] + ")", p);
    }
  return out;
}

// A third superovoid start that joins what both parents learnt: the ovoid
// with the exponents of the superellipsoid, each taken from the
// superellipsoid axis most parallel to the ovoid's.
ShapeParameters combineParents(const ShapeParameters& superellipsoid, const ShapeParameters& ovoid) {
  ShapeParameters p = geometry::promote(ovoid, ShapeModel::Superovoid);
  const Eigen::Matrix3d Ro = geometry::rotationFromAngles(ovoid.angles);
  const Eigen::Matrix3d Rs = geometry::rotationFromAngles(superellipsoid.angles);
  for (int i = 0; i < 3; ++i) {
    int best = 0;
    for (int j = 1; j < 3; ++j)
      if (std::fabs(Ro.col(i).dot(Rs.col(j))) > std::fabs(Ro.col(i).dot(Rs.col(best)))) best = j;
    p.exponents[i] = superellipsoid.exponents[best];
  }
  return p;
}

// The nesting guarantee: a child never reports a worse RMS than its parent.
void enforceNesting(ModelFit& child, const ModelFit& parent, const Eigen::MatrixX3d& points) {
  if (child.rms_mm <= parent.rms_mm) return;
  const ShapeModel model = child.parameters.model;
  child.parameters = geometry::promote(parent.parameters, model);
  child.rms_mm = rmsOf(child.parameters, points, child.sse_mm2);
  child.algebraic_objective = algebraicObjective(child.parameters, points);
  child.termination += "; kept the " + geometry::modelName(parent.parameters.model) + " (fit was not better)";
}

}  // namespace

const ModelFit& Summary::fit(ShapeModel model) const {
  for (const auto& f : fits)
    if (f.parameters.model == model) return f;
  throw UsageError("no fit for model " + geometry::modelName(model));
}

std::string Summary::briefReport() const {
  std::ostringstream s;
  s << "fitted " << fits.size() << " models to " << points << " points in " << seconds << " s; best: " << best_model;
  return s.str();
}

std::string Summary::fullReport() const {
  std::ostringstream s;
  s << briefReport() << "\n";
  for (const auto& f : fits)
    s << "  " << geometry::modelName(f.parameters.model) << ": rms " << f.rms_mm << " mm, " << f.evaluations
      << " evaluations, " << f.seconds << " s, from " << f.started_from << ", " << f.termination << "\n";
  return s.str();
}

Summary fitHierarchy(const Eigen::MatrixX3d& points, const Options& o) {
  o.validate();
  const auto t0 = Clock::now();
  const Eigen::Index min_points = geometry::parameterCount(ShapeModel::Superovoid);
  if (points.rows() < min_points)
    throw InputError("fit: expected at least " + std::to_string(min_points) + " points, found " +
                     std::to_string(points.rows()));
  if (!points.allFinite()) throw InputError("fit: points contain NaN or Inf");

  const ShapeParameters sphere_start = algebraicSphere(points);
  ShapeParameters ellipsoid_start = geometry::promote(sphere_start, ShapeModel::Ellipsoid);
  bool have_algebraic_ellipsoid = false;
  try {
    const ShapeParameters e = algebraicEllipsoid(points);
    // Reject an algebraic ellipsoid that is far from the data's scale (a flat cap).
    const double r = sphere_start.radii[0];
    if (e.radii.maxCoeff() < 3.0 * r && e.radii.minCoeff() > r / 3.0) {
      ellipsoid_start = e;
      have_algebraic_ellipsoid = true;
    }
  } catch (const ProcessingError& e) {
    log::debug(std::string("ellipsoid-specific start unavailable: ") + e.what());
  }

  auto bounds = [&](ShapeModel m) { return makeBounds(m, ellipsoid_start, sphere_start, o); };
  const ModelFit sphere = fitModel(ShapeModel::Sphere, {{"algebraic", sphere_start}}, bounds(ShapeModel::Sphere),
                                   points, o);
  std::vector<std::pair<std::string, ShapeParameters>> e_starts{{"sphere", sphere.parameters}};
  if (have_algebraic_ellipsoid) e_starts.emplace_back("algebraic", ellipsoid_start);
  ModelFit ellipsoid =
      fitModel(ShapeModel::Ellipsoid, e_starts, bounds(ShapeModel::Ellipsoid), points, o, o.screening_evaluations);
  enforceNesting(ellipsoid, sphere, points);

  auto wanted = [&](ShapeModel m) { return std::find(o.models.begin(), o.models.end(), m) != o.models.end(); };
  const bool need_se = wanted(ShapeModel::Superellipsoid) || wanted(ShapeModel::Superovoid);
  const bool need_o = wanted(ShapeModel::Ovoid) || wanted(ShapeModel::Superovoid);
  ModelFit superellipsoid, ovoid, superovoid;
  if (need_se) {
    superellipsoid = fitModel(ShapeModel::Superellipsoid, {{"ellipsoid", ellipsoid.parameters}},
                              bounds(ShapeModel::Superellipsoid), points, o);
    enforceNesting(superellipsoid, ellipsoid, points);
  }
  if (need_o) {
    ovoid = fitModel(ShapeModel::Ovoid, axisLabellings(ellipsoid.parameters), bounds(ShapeModel::Ovoid), points, o,
                     o.screening_evaluations);
    enforceNesting(ovoid, ellipsoid, points);
  }
  if (wanted(ShapeModel::Superovoid)) {
    superovoid = fitModel(ShapeModel::Superovoid,
                          {{"superellipsoid", superellipsoid.parameters},
                           {"ovoid", ovoid.parameters},
                           {"ovoid with the superellipsoid's exponents",
                            combineParents(superellipsoid.parameters, ovoid.parameters)}},
                          bounds(ShapeModel::Superovoid), points, o, o.screening_evaluations);
    enforceNesting(superovoid, superellipsoid.rms_mm <= ovoid.rms_mm ? superellipsoid : ovoid, points);
  }

  Summary summary;
  summary.points = static_cast<int>(points.rows());
  for (const ModelFit* f : std::initializer_list<const ModelFit*>{&sphere, &ellipsoid, &superellipsoid, &ovoid, &superovoid})
    if (wanted(f->parameters.model) && f->evaluations > 0) summary.fits.push_back(*f);
  double best_rms = std::numeric_limits<double>::infinity();
  for (const auto& f : summary.fits)
    if (f.rms_mm < best_rms - 1e-9) {
      best_rms = f.rms_mm;
      summary.best_model = geometry::modelName(f.parameters.model);
    }
  summary.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return summary;
}

}  // namespace articula::fit
