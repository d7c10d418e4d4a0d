#include "articula/fit/fit_hierarchy.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <random>
#include <sstream>

#include <Eigen/Geometry>
#include <nlopt.hpp>

#include "articula/core/error.hpp"
#include "articula/core/log.hpp"
#include "articula/core/parallel.hpp"
#include "articula/distance/signed_distance.hpp"
#include "articula/geometry/algebraic_fit.hpp"
#include "articula/fit/levenberg_marquardt.hpp"
#include "articula/fit/other_optima.hpp"
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
// Our Levenberg-Marquardt (levenberg_marquardt.hpp) in place of an NLopt method.
const std::string kLevenbergMarquardt = "LM";

nlopt::algorithm localAlgorithm(const std::string& name) {
  for (auto a : {nlopt::LN_BOBYQA, nlopt::LD_SLSQP, nlopt::LD_LBFGS, nlopt::LD_MMA, nlopt::LD_TNEWTON_PRECOND_RESTART})
    if (name == nlopt::algorithm_name(a) || name == nlopt_algorithm_to_string(static_cast<nlopt_algorithm>(a)))
      return a;
  throw UsageError("local_algorithm: expected LM, LN_BOBYQA, LD_SLSQP, LD_LBFGS, LD_MMA or LD_TNEWTON_PRECOND_RESTART, found '" +
                   name + "'");
}

}  // namespace

void Options::validate() const {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw UsageError("fit options: " + what);
  };
  require(!models.empty(), "models: expected at least one model");
  if (local_algorithm != kLevenbergMarquardt) localAlgorithm(local_algorithm);
  require(max_evaluations > 0, "max_evaluations: expected > 0");
  require(global_evaluations > 0, "global_evaluations: expected > 0");
  require(screening_evaluations >= 0 && screening_points >= 0 && restarts >= 0,
          "screening_evaluations, screening_points, restarts: expected >= 0");
  require(screening_finalists >= 1, "screening_finalists: expected >= 1");
  require(sample_points == 0 || sample_points >= 1000, "sample_points: expected 0 (all) or >= 1000");
  require(refine_evaluations >= 1, "refine_evaluations: expected >= 1");
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

double geometricObjective(const ShapeParameters& shape, const Eigen::MatrixX3d& points, int threads) {
  return distance::signedDistances(shape, points, threads).squaredNorm();
}

namespace {

using Clock = std::chrono::steady_clock;

struct Bounds {
  VectorXd lower, upper;
  std::vector<char> given;  // set by the user (Options::bounds): never widened, the start clamped into it
};

using geometry::ParameterKind;

// Parameter bounds of thesis section 3.2.5 around the reference start.
Bounds makeBounds(ShapeModel model, const ShapeParameters& reference, const ShapeParameters& sphere,
                  const Options& o) {
  const double r_min = std::min(reference.radii.minCoeff(), sphere.radii[0]);
  const double r_max = std::max(reference.radii.maxCoeff(), sphere.radii[0]);
  const auto names = geometry::parameterNames(model);
  const auto kinds = geometry::parameterKinds(model);
  Bounds b{VectorXd(names.size()), VectorXd(names.size()), std::vector<char>(names.size(), 0)};
  int translation_axis = 0;
  for (size_t k = 0; k < names.size(); ++k) {
    const Eigen::Index i = static_cast<Eigen::Index>(k);
    double lo = 0.0, hi = 0.0;
    switch (kinds[k]) {
      case ParameterKind::Radius:
        lo = (1.0 - o.radius_interval) * r_min;
        hi = (1.0 + o.radius_interval) * r_max;
        break;
      case ParameterKind::Exponent:
        lo = o.exponent_min;
        hi = o.exponent_max;
        break;
      case ParameterKind::OvoidScale:
        lo = o.c01_min;
        hi = o.c01_max;
        break;
      case ParameterKind::OvoidCurvature:
        lo = o.c23_min;
        hi = o.c23_max;
        break;
      case ParameterKind::Translation: {
        const int axis = translation_axis++;
        lo = std::min(reference.center[axis], sphere.center[axis]) - o.center_interval * r_max;
        hi = std::max(reference.center[axis], sphere.center[axis]) + o.center_interval * r_max;
        break;
      }
      case ParameterKind::Angle:
        // Set per run to start +- pi (a full turn, so wrapping never blocks).
        lo = -std::numeric_limits<double>::infinity();
        hi = std::numeric_limits<double>::infinity();
        break;
    }
    if (auto it = o.bounds.find(names[k]); it != o.bounds.end()) {
      lo = it->second.first;
      hi = it->second.second;
      b.given[k] = 1;
    }
    b.lower[i] = lo;
    b.upper[i] = hi;
  }
  return b;
}

// Initial trust-region steps, in each parameter's own units.
VectorXd initialSteps(ShapeModel model, const ShapeParameters& start) {
  const auto kinds = geometry::parameterKinds(model);
  VectorXd step(static_cast<Eigen::Index>(kinds.size()));
  const double r = start.radii.maxCoeff();
  for (size_t k = 0; k < kinds.size(); ++k) {
    double s = 0.05;  // angles (rad)
    switch (kinds[k]) {
      case ParameterKind::Radius:
      case ParameterKind::Translation: s = 0.02 * r; break;
      case ParameterKind::Exponent: s = 0.05; break;
      case ParameterKind::OvoidScale:
      case ParameterKind::OvoidCurvature: s = 0.01; break;
      case ParameterKind::Angle: s = 0.05; break;
    }
    step[static_cast<Eigen::Index>(k)] = s;
  }
  return step;
}

// The residuals of the objective: F(x_i) (algebraic) or the signed distance
// d_i (geometric; `feet` are warm starts on entry, closest points on exit).
// Throws InvalidParameter outside the valid set.
void residuals(const ShapeParameters& p, Objective kind, const Eigen::MatrixX3d& points, VectorXd& r,
               Eigen::MatrixX3d& feet, int threads) {
  if (kind == Objective::Algebraic) {
    const auto surface = geometry::makeSurface(p);
    r.resize(points.rows());
    for (Eigen::Index i = 0; i < points.rows(); ++i) r[i] = surface->value(points.row(i).transpose());
  } else {
    distance::SignedDistance(p, threads).evaluate(points, r, feet, feet.rows() == points.rows());
  }
}

// Their Jacobian (#P x M): dF/dlambda at the points, or, for the signed
// distances, dF/dlambda / |grad F| at the closest points `feet` (the envelope
// theorem; orthogonal distance fitting, Ahn 2004).
Eigen::MatrixXd residualJacobian(const ShapeParameters& p, Objective kind, const Eigen::MatrixX3d& points,
                                 const Eigen::MatrixX3d& feet, int threads) {
  Eigen::MatrixXd J;
  VectorXd norms;
  if (kind == Objective::Algebraic) {
    parameterGradient(p, points, J, norms, threads);
  } else {
    parameterGradient(p, feet, J, norms, threads);
    J.array().colwise() /= norms.array();
  }
  return J;
}

// The residuals as a least-squares problem for levenbergMarquardt, with the
// closest points of the current parameters as warm starts for the next
// (`feet`: those of the start, if known; else empty).
class ResidualProblem : public LeastSquaresProblem {
 public:
  ResidualProblem(ShapeModel model, const Eigen::MatrixX3d& points, Objective kind, Eigen::MatrixX3d feet, int threads)
      : model_(model), points_(points), kind_(kind), threads_(threads), feet_(std::move(feet)) {}

  const Eigen::MatrixX3d& feet() const { return feet_; }

  bool evaluate(const VectorXd& x, VectorXd& r) override {
    try {
      trial_ = geometry::fromVector(model_, x);
      trial_feet_ = feet_;
      residuals(trial_, kind_, points_, r, trial_feet_, threads_);
      return true;
    } catch (const InvalidParameter&) {
      return false;  // e.g. an ovoid denominator reaching 0 on [-1, 1]
    }
  }

  void accept(Eigen::MatrixXd& J) override {
    feet_.swap(trial_feet_);
    J = residualJacobian(trial_, kind_, points_, feet_, threads_);
  }

 private:
  ShapeModel model_;
  const Eigen::MatrixX3d& points_;
  Objective kind_;
  int threads_;
  Eigen::MatrixX3d feet_, trial_feet_;
  ShapeParameters trial_;
};

// The objective seen by NLopt, in scaled variables x = (lambda - lambda0) / s
// so that every parameter moves on a unit scale; it remembers the best point
// it was shown, so a run never returns anything worse than its start.
class ObjectiveFunction {
 public:
  ObjectiveFunction(ShapeModel model, const Eigen::MatrixX3d& points, Objective kind, VectorXd origin, VectorXd scale,
                    Eigen::MatrixX3d feet, int threads)
      : model_(model), points_(points), kind_(kind), threads_(threads), origin_(std::move(origin)), scale_(std::move(scale)),
        best_feet_(std::move(feet)) {}

  const Eigen::MatrixX3d& bestFeet() const { return best_feet_; }

  VectorXd toLambda(const double* x) const {
    return origin_ + scale_.cwiseProduct(Eigen::Map<const VectorXd>(x, origin_.size()));
  }

  double operator()(const std::vector<double>& x, std::vector<double>& grad) {
    ++evaluations;
    const VectorXd lambda = toLambda(x.data());
    double f = 0.0;
    try {
      const ShapeParameters p = geometry::fromVector(model_, lambda);
      feet_ = best_feet_;
      residuals(p, kind_, points_, d_, feet_, threads_);
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
    const VectorXd g = 2.0 * (residualJacobian(p, kind_, points_, feet_, threads_).transpose() * d_).cwiseProduct(scale_);
    std::copy(g.data(), g.data() + g.size(), grad.begin());
  }

  ShapeModel model_;
  const Eigen::MatrixX3d& points_;
  Objective kind_;
  int threads_;
  VectorXd origin_, scale_;
  VectorXd d_;
  Eigen::MatrixX3d feet_, best_feet_;
};

Termination resultType(nlopt::result r) {
  switch (r) {
    case nlopt::SUCCESS:
    case nlopt::FTOL_REACHED: return Termination::ObjectiveTolerance;
    case nlopt::STOPVAL_REACHED: return Termination::ExactFit;
    case nlopt::XTOL_REACHED: return Termination::ParameterTolerance;
    case nlopt::MAXEVAL_REACHED: return Termination::EvaluationLimit;
    case nlopt::MAXTIME_REACHED: return Termination::TimeLimit;
    default: return Termination::OptimizerFailure;
  }
}

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
  Eigen::MatrixX3d feet;  // closest points at x (geometric objective)
  double value = 0.0;
  int evaluations = 0;
  std::string termination;
  Termination type = Termination::InvalidStart;
  bool converged = false;
};

// One NLopt run of `algorithm` from `start` within `bounds`, in variables
// scaled by `steps`; `feet`: the closest points of the start if known (else
// empty), warm starts for the first evaluation.
RunResult runNlopt(nlopt::algorithm algorithm, ShapeModel model, const VectorXd& start, const Bounds& bounds,
                   const VectorXd& steps, int max_evaluations, const Eigen::MatrixX3d& points,
                   const Eigen::MatrixX3d& feet, const Options& o) {
  const unsigned n = static_cast<unsigned>(start.size());
  ObjectiveFunction objective(model, points, o.objective, start, steps, feet, o.threads);
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
    result.type = resultType(r);
    result.converged = isConverged(result.type);
  } catch (const nlopt::roundoff_limited&) {
    // Reached the minimum to rounding: keep the best point.
    result.termination = "roundoff limited";
    result.type = Termination::RoundoffLimited;
    result.converged = true;
  } catch (const std::exception& e) {
    result.termination = std::string("NLopt stopped: ") + e.what();
    result.type = Termination::OptimizerFailure;
  }
  result.x = objective.best_lambda;
  result.feet = objective.bestFeet();
  result.value = objective.best_value;
  result.evaluations = objective.evaluations;
  return result;
}

// Levenberg-Marquardt on the residuals from `start` within `bounds`.
RunResult runLevenbergMarquardt(ShapeModel model, const VectorXd& start, const Bounds& bounds, int max_evaluations,
                                const Eigen::MatrixX3d& points, const Eigen::MatrixX3d& feet, const Options& o) {
  ResidualProblem problem(model, points, o.objective, feet, o.threads);
  LeastSquaresOptions lm;
  lm.max_evaluations = max_evaluations;
  lm.relative_tolerance = o.relative_tolerance;
  lm.parameter_tolerance = o.parameter_tolerance;
  lm.absolute_cost = 1e-20 * static_cast<double>(points.rows());
  const LeastSquaresResult r = levenbergMarquardt(problem, start, bounds.lower, bounds.upper, lm);
  return {r.x, problem.feet(), r.cost, r.evaluations, r.termination, r.type, r.converged};
}

// The local method of `o` from `start`: ours (LM) or NLopt's.
RunResult runLocal(ShapeModel model, const VectorXd& start, const Bounds& bounds, const VectorXd& steps,
                   int max_evaluations, const Eigen::MatrixX3d& points, const Eigen::MatrixX3d& feet,
                   const Options& o) {
  if (o.local_algorithm == kLevenbergMarquardt)
    return runLevenbergMarquardt(model, start, bounds, max_evaluations, points, feet, o);
  return runNlopt(localAlgorithm(o.local_algorithm), model, start, bounds, steps, max_evaluations, points, feet, o);
}

Bounds boundsForStart(Bounds b, ShapeModel model, const VectorXd& start) {
  const auto kinds = geometry::parameterKinds(model);
  for (Eigen::Index i = 0; i < start.size(); ++i) {
    if (b.given[static_cast<size_t>(i)]) continue;  // the user's box, as given (the start is clamped into it)
    if (kinds[static_cast<size_t>(i)] == ParameterKind::Angle) {
      b.lower[i] = start[i] - M_PI;
      b.upper[i] = start[i] + M_PI;
    }
    // A parent's optimum always lies inside the child's box.
    b.lower[i] = std::min(b.lower[i], start[i]);
    b.upper[i] = std::max(b.upper[i], start[i]);
  }
  return b;
}

// The ovoid's radius a and its coefficients c_jx enter the surface only
// through the products a c_jx (the same for b and c_jy): (a, c) and
// (k a, c / k) are one surface, an exact degeneracy along which local methods
// crept for a hundred steps (measured on bench-fit). Holding a at its upper
// bound loses no surface when each c_j range contains 0: the feasible
// products a c_j, over all a <= a_max, are exactly a_max [lo_j, hi_j]. The
// index of a (or b) and of c0..c3 of each axis, if it can be held.
struct OvoidAxis {
  Eigen::Index radius, c0;
};
std::vector<OvoidAxis> holdableOvoidAxes(ShapeModel model, const Bounds& b) {
  std::vector<OvoidAxis> axes;
  if (model != ShapeModel::Ovoid && model != ShapeModel::Superovoid) return axes;
  const auto names = geometry::parameterNames(model);
  auto index = [&](const std::string& n) {
    return static_cast<Eigen::Index>(std::find(names.begin(), names.end(), n) - names.begin());
  };
  for (const char* axis : {"x", "y"}) {
    const OvoidAxis a{index(axis[0] == 'x' ? "a" : "b"), index(std::string("c0") + axis)};
    bool holdable = std::isfinite(b.upper[a.radius]) && b.upper[a.radius] > 0.0;
    for (Eigen::Index j = a.c0; j < a.c0 + 4; ++j) holdable = holdable && b.lower[j] <= 0.0 && b.upper[j] >= 0.0;
    if (holdable) axes.push_back(a);
  }
  return axes;
}

// A start of `model` as a vector with its bounds, the ovoid radii held (above).
std::pair<VectorXd, Bounds> prepareStart(ShapeModel model, const ShapeParameters& start, const Bounds& model_bounds) {
  VectorXd x0 = geometry::toVector(geometry::promote(start, model));
  for (Eigen::Index i = 0; i < x0.size(); ++i)
    if (model_bounds.given[static_cast<size_t>(i)]) x0[i] = std::clamp(x0[i], model_bounds.lower[i], model_bounds.upper[i]);
  Bounds b = boundsForStart(model_bounds, model, x0);
  for (const OvoidAxis& a : holdableOvoidAxes(model, b)) {
    const double factor = x0[a.radius] / b.upper[a.radius];
    x0.segment(a.c0, 4) *= factor;
    x0[a.radius] = b.lower[a.radius] = b.upper[a.radius];
  }
  return {x0, b};
}

// The reverse for reporting: the smallest radius within the bounds that
// keeps every c_j within its own (so c0 = 1 when c0 limits), same surface.
ShapeParameters releaseOvoidScales(ShapeParameters p, const Bounds& model_bounds) {
  const VectorXd x = geometry::toVector(p);
  VectorXd out = x;
  for (const OvoidAxis& a : holdableOvoidAxes(p.model, model_bounds)) {
    double factor = model_bounds.lower[a.radius] / x[a.radius];
    for (Eigen::Index j = a.c0; j < a.c0 + 4; ++j) {
      if (x[j] > 0.0) factor = std::max(factor, x[j] / model_bounds.upper[j]);
      if (x[j] < 0.0) factor = std::max(factor, x[j] / model_bounds.lower[j]);
    }
    if (!(factor > 0.0 && factor < 1.0)) continue;
    out[a.radius] = x[a.radius] * factor;
    out.segment(a.c0, 4) = (x.segment(a.c0, 4) / factor)  // the limiting c_j lands on its bound up to rounding
                               .cwiseMax(model_bounds.lower.segment(a.c0, 4))
                               .cwiseMin(model_bounds.upper.segment(a.c0, 4));
  }
  try {
    return geometry::fromVector(p.model, out);
  } catch (const InvalidParameter&) {
    return p;  // e.g. bounds overridden beyond the valid set: keep the held form
  }
}

ShapeParameters wrapAngles(ShapeParameters p) {
  // Normalise through the rotation matrix: same rotation, canonical angles.
  p.angles = geometry::anglesFromRotation(geometry::rotationFromAngles(p.angles));
  return p;
}

// The RMS of the exact signed distances (the global closest points, into
// `feet`), whatever the objective: what is reported and nested. `feet` on
// entry: closest points on a nearby surface, if known, that spare most global
// searches without making the result any less exact.
double exactRms(const ShapeParameters& p, const Eigen::MatrixX3d& points, double& sse, Eigen::MatrixX3d& feet,
                int threads) {
  VectorXd d;
  distance::SignedDistance(p, threads).evaluate(points, d, feet, distance::SignedDistance::Start::WarmExact);
  sse = d.squaredNorm();
  return std::sqrt(sse / static_cast<double>(points.rows()));
}

// A start of a model's fit; `feet`: its exact closest points if known (a
// parent's optimum, the same surface), else empty.
struct Start {
  std::string label;
  ShapeParameters shape;
  Eigen::MatrixX3d feet;
};

// A model's fit and the exact closest points of its result (warm starts for its children).
struct Fitted {
  ModelFit fit;
  Eigen::MatrixX3d feet;
};

// Every k-th point, about `target` of them (all if target is 0 or above
// half the points): enough to rank starts at a fraction of the cost.
Eigen::MatrixX3d subsample(const Eigen::MatrixX3d& points, int target) {
  const Eigen::Index k = target > 0 ? points.rows() / target : 0;
  if (k < 2) return points;
  Eigen::MatrixX3d out((points.rows() + k - 1) / k, 3);
  for (Eigen::Index i = 0; i < out.rows(); ++i) out.row(i) = points.row(i * k);
  return out;
}

// Fits `model` from each start and keeps the best.
// With `screen` > 0 and several starts, every start first gets `screen`
// evaluations on a subsample of the points (Options::screening_points) and
// only the best few (Options::screening_finalists; equal values count once)
// are run to convergence on all of them.
Fitted fitModel(ShapeModel model, std::vector<Start> starts, const Bounds& model_bounds,
                const Eigen::MatrixX3d& points, const Options& o, int screen = 0) {
  const auto t0 = Clock::now();
  Fitted fitted;
  ModelFit& best = fitted.fit;
  double best_value = std::numeric_limits<double>::infinity();
  int screening_evaluations = 0;
  std::string screened_labels;
  if (screen > 0 && starts.size() > 1) {
    Options short_run = o;
    short_run.max_evaluations = screen;
    short_run.strategy = Strategy::Local;
    std::vector<std::pair<double, Start>> screened;
    const Eigen::MatrixX3d screen_points = subsample(points, o.screening_points);
    // The starts are independent: screened side by side over --threads, then
    // taken in their order (the same answer for any thread count).
    std::vector<RunResult> runs(starts.size());
    parallelFor(static_cast<std::ptrdiff_t>(starts.size()), 1, o.threads, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
      for (std::ptrdiff_t i = begin; i < end; ++i) {
        const Start& start = starts[static_cast<size_t>(i)];
        const auto [x0, b] = prepareStart(model, start.shape, model_bounds);
        const Eigen::MatrixX3d feet = start.feet.rows() == points.rows() ? subsample(start.feet, o.screening_points)
                                                                           : Eigen::MatrixX3d();
        runs[static_cast<size_t>(i)] =
            runLocal(model, x0, b, initialSteps(model, start.shape), screen, screen_points, feet, short_run);
      }
    });
    for (size_t i = 0; i < starts.size(); ++i) {
      screening_evaluations += runs[i].evaluations;
      if (std::isfinite(runs[i].value))
        screened.push_back({runs[i].value, {starts[i].label, geometry::fromVector(model, runs[i].x), {}}});
    }
    // On a subsample, nearby optima can swap ranks (measured on bench-fit):
    // finish the best few distinct ones.
    std::stable_sort(screened.begin(), screened.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    if (!screened.empty()) {  // else (no valid start) every start is run as it is
      for (const auto& s : starts) screened_labels += (screened_labels.empty() ? "" : ",") + s.label;
      starts.clear();
      for (size_t i = 0; i < screened.size() && static_cast<int>(starts.size()) < o.screening_finalists; ++i)
        if (i == 0 || screened[i].first > screened[i - 1].first * (1.0 + 1e-9)) starts.push_back(screened[i].second);
    }
  }
  best.evaluations = screening_evaluations;
  for (const Start& start : starts) {
    const auto [x0, b] = prepareStart(model, start.shape, model_bounds);
    const VectorXd steps = initialSteps(model, start.shape);
    RunResult run;
    int evaluations = 0;
    std::string how;
    // The global search explores the whole box: once per model is enough
    // (from the best screened start).
    const bool search_globally = o.strategy == Strategy::GlobalLocal && model != ShapeModel::Sphere &&
                                 (screened_labels.empty() || &start == &starts.front());
    if (search_globally) {
      const RunResult global =
          runNlopt(nlopt::GN_CRS2_LM, model, x0, b, steps, o.global_evaluations, points, start.feet, o);
      evaluations += global.evaluations;
      how = "GN_CRS2_LM (" + global.termination + ") then ";
      run = runLocal(model, global.x, b, steps, o.max_evaluations, points, global.feet, o);
    } else {
      run = runLocal(model, x0, b, steps, o.max_evaluations, points, start.feet, o);
    }
    evaluations += run.evaluations;
    // A run can stop on a short step while still descending (SLSQP's
    // objective test; LM after heavy damping): restart (a fresh quasi-Newton
    // model or damping) while that still gains. With LM this costs 2-3
    // evaluations per model.
    for (int restart = 0; restart < o.restarts; ++restart) {
      const RunResult again = runLocal(model, run.x, b, steps, o.max_evaluations, points, run.feet, o);
      evaluations += again.evaluations;
      const bool gained = again.value < run.value * (1.0 - 1e-6) && again.value > 1e-20 * static_cast<double>(points.rows());
      if (again.value < run.value) run = again;
      if (!gained) break;
    }
    best.evaluations += evaluations;
    if (run.value < best_value) {
      best_value = run.value;
      fitted.feet = run.feet;  // guesses for the exact distances below
      best.parameters = wrapAngles(releaseOvoidScales(geometry::fromVector(model, run.x), model_bounds));
      best.termination = how + o.local_algorithm + ": " + run.termination;
      best.termination_type = run.type;
      best.converged = run.converged;
      best.started_from = start.label;
    }
  }
  if (!screened_labels.empty()) {
    best.started_from += " (screened: " + screened_labels + ")";
  } else if (starts.size() > 1) {
    std::string all;
    for (const Start& s : starts) all += (all.empty() ? "" : ",") + s.label;
    best.started_from += " (best of " + all + ")";
  }
  best.rms_mm = exactRms(best.parameters, points, best.sse_mm2, fitted.feet, o.threads);
  best.algebraic_objective = algebraicObjective(best.parameters, points);
  best.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return fitted;
}

// The six labellings of an ellipsoid's or a superellipsoid's axes with a
// right-handed frame (local z along each axis, either way): the same surface,
// but distinct starts for the ovoid and superovoid, whose asymmetry runs
// along local z (c1 >= 0: wider towards +z).
std::vector<Start> axisLabellings(const Fitted& parent) {
  const ShapeParameters& e = parent.fit.parameters;
  const Eigen::Matrix3d R = geometry::rotationFromAngles(e.angles);
  std::vector<Start> out;
  for (int k = 2; k < 5; ++k)
    for (double sign : {1.0, -1.0}) {
      const int iz = k % 3, ix = (k + 1) % 3, iy = (k + 2) % 3;
      Eigen::Matrix3d L;
      L.col(2) = sign * R.col(iz);
      L.col(0) = R.col(ix);
      L.col(1) = L.col(2).cross(L.col(0));
      ShapeParameters p = e;
      p.radii = Eigen::Vector3d(e.radii[ix], e.radii[iy], e.radii[iz]);
      p.exponents = Eigen::Vector3d(e.exponents[ix], e.exponents[iy], e.exponents[iz]);
      p.angles = geometry::anglesFromRotation(L);
      out.push_back({geometry::modelName(e.model) + " (z = " + (sign > 0 ? "+" : "-") + "xyz"[iz] + ")", p, parent.feet});
    }
  return out;
}

// Superellipsoid starts beyond the ellipsoid's: a femoral head's radii lie
// within a few per cent of each other, so the ellipsoid's axes are nearly
// arbitrary there, and a local search cannot turn the exponents a quarter
// turn onto the head's own axes. So: the ellipsoid; each of its axes with a
// larger exponent; and its frame turned by 45 degrees either way about each
// axis, boxy (exponents 2.4). Screened on a subsample, the best finished.
std::vector<Start> superellipsoidStarts(const Fitted& ellipsoid) {
  const ShapeParameters e = geometry::promote(ellipsoid.fit.parameters, ShapeModel::Superellipsoid);
  std::vector<Start> out{{"ellipsoid", e, ellipsoid.feet}};
  for (int i = 0; i < 3; ++i) {
    ShapeParameters p = e;
    p.exponents[i] = 2.4;
    out.push_back({std::string("ellipsoid, exponent 2.4 on ") + "xyz"[i], p, {}});
  }
  const Eigen::Matrix3d R = geometry::rotationFromAngles(e.angles);
  for (int i = 0; i < 3; ++i)
    for (double turn : {M_PI / 4, -M_PI / 4}) {
      ShapeParameters p = e;
      p.angles = geometry::anglesFromRotation(R * Eigen::AngleAxisd(turn, Eigen::Vector3d::Unit(i)).toRotationMatrix());
      p.exponents.setConstant(2.4);
      p.radii.setConstant(e.radii.mean());
      out.push_back({std::string("ellipsoid turned ") + (turn > 0 ? "+" : "-") + "45 deg about " + "xyz"[i], p, {}});
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
// Not where the user's bounds exclude the parent (then the child answers
// within them, even if the parent fits better).
void enforceNesting(Fitted& fitted, const Fitted& parent_fitted, const Eigen::MatrixX3d& points, const Bounds& bounds,
                    int threads) {
  ModelFit& child = fitted.fit;
  const ModelFit& parent = parent_fitted.fit;
  if (child.rms_mm <= parent.rms_mm) return;
  const ShapeModel model = child.parameters.model;
  const VectorXd promoted = geometry::toVector(geometry::promote(parent.parameters, model));
  for (Eigen::Index i = 0; i < promoted.size(); ++i)
    if (bounds.given[static_cast<size_t>(i)] && !(promoted[i] >= bounds.lower[i] && promoted[i] <= bounds.upper[i])) return;
  child.parameters = geometry::promote(parent.parameters, model);
  fitted.feet = parent_fitted.feet;
  child.rms_mm = exactRms(child.parameters, points, child.sse_mm2, fitted.feet, threads);
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
  s << "fitted " << fits.size() << " models to " << points << " points in " << seconds << " s; least RMS: " << best_model;
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

namespace {

// The algebraic starts (thesis section 3.2.4) that seed the sphere and the
// ellipsoid and centre the bounds of every model.
struct AlgebraicStarts {
  ShapeParameters sphere, ellipsoid;
  bool have_ellipsoid = false;
};

AlgebraicStarts algebraicStarts(const Eigen::MatrixX3d& points) {
  AlgebraicStarts a;
  a.sphere = geometry::algebraicSphere(points);
  a.ellipsoid = geometry::promote(a.sphere, ShapeModel::Ellipsoid);
  try {
    const ShapeParameters e = geometry::algebraicEllipsoid(points);
    // Reject an algebraic ellipsoid that is far from the data's scale (a flat cap).
    const double r = a.sphere.radii[0];
    if (e.radii.maxCoeff() < 3.0 * r && e.radii.minCoeff() > r / 3.0) {
      a.ellipsoid = e;
      a.have_ellipsoid = true;
    }
  } catch (const ProcessingError& e) {
    log::debug(std::string("ellipsoid-specific start unavailable: ") + e.what());
  }
  return a;
}

// Every model of the hierarchy; a model not fitted has 0 evaluations.
struct HierarchyFits {
  Fitted sphere, ellipsoid, superellipsoid, ovoid, superovoid;
};

bool wanted(const Options& o, ShapeModel m) { return std::find(o.models.begin(), o.models.end(), m) != o.models.end(); }

// Progress of long fits on stderr, one line per model.
void reportModel(const Fitted& f, bool long_run) {
  const std::string line = "fit: " + geometry::modelName(f.fit.parameters.model) + " rms " +
                           std::to_string(f.fit.rms_mm) + " mm (" + std::to_string(f.fit.seconds) + " s)";
  long_run ? log::info(line) : log::debug(line);
}

HierarchyFits fitAll(const Eigen::MatrixX3d& points, const AlgebraicStarts& a, const Options& o, bool long_run) {
  auto bounds = [&](ShapeModel m) { return makeBounds(m, a.ellipsoid, a.sphere, o); };
  HierarchyFits h;
  h.sphere = fitModel(ShapeModel::Sphere, {{"algebraic", a.sphere, {}}}, bounds(ShapeModel::Sphere), points, o);
  reportModel(h.sphere, long_run);
  std::vector<Start> e_starts{{"sphere", h.sphere.fit.parameters, h.sphere.feet}};
  if (a.have_ellipsoid) e_starts.push_back({"algebraic", a.ellipsoid, {}});
  h.ellipsoid =
      fitModel(ShapeModel::Ellipsoid, e_starts, bounds(ShapeModel::Ellipsoid), points, o, o.screening_evaluations);
  enforceNesting(h.ellipsoid, h.sphere, points, bounds(ShapeModel::Ellipsoid), o.threads);
  reportModel(h.ellipsoid, long_run);

  const bool need_se = wanted(o, ShapeModel::Superellipsoid) || wanted(o, ShapeModel::Superovoid);
  const bool need_o = wanted(o, ShapeModel::Ovoid) || wanted(o, ShapeModel::Superovoid);
  if (need_se) {
    h.superellipsoid = fitModel(ShapeModel::Superellipsoid, superellipsoidStarts(h.ellipsoid),
                                bounds(ShapeModel::Superellipsoid), points, o, o.screening_evaluations);
    enforceNesting(h.superellipsoid, h.ellipsoid, points, bounds(ShapeModel::Superellipsoid), o.threads);
    reportModel(h.superellipsoid, long_run);
  }
  if (need_o) {
    h.ovoid = fitModel(ShapeModel::Ovoid, axisLabellings(h.ellipsoid), bounds(ShapeModel::Ovoid), points, o,
                       o.screening_evaluations);
    enforceNesting(h.ovoid, h.ellipsoid, points, bounds(ShapeModel::Ovoid), o.threads);
    reportModel(h.ovoid, long_run);
  }
  if (wanted(o, ShapeModel::Superovoid)) {
    // Every labelling of the superellipsoid: which axis the asymmetry takes
    // decided the optimum reached on the real femoral head (measured).
    std::vector<Start> so_starts = axisLabellings(h.superellipsoid);
    so_starts.push_back({"ovoid", h.ovoid.fit.parameters, h.ovoid.feet});
    so_starts.push_back({"ovoid with the superellipsoid's exponents",
                         combineParents(h.superellipsoid.fit.parameters, h.ovoid.fit.parameters), {}});
    h.superovoid = fitModel(ShapeModel::Superovoid, so_starts, bounds(ShapeModel::Superovoid), points, o,
                            o.screening_evaluations);
    enforceNesting(h.superovoid, h.superellipsoid.fit.rms_mm <= h.ovoid.fit.rms_mm ? h.superellipsoid : h.ovoid,
                   points, bounds(ShapeModel::Superovoid), o.threads);
    reportModel(h.superovoid, long_run);
  }
  return h;
}

// Nested seeded random samples: the first `count` of one seeded shuffle of
// the points, in their original order (a larger sample holds every smaller one).
class NestedSamples {
 public:
  NestedSamples(Eigen::Index n, unsigned seed) : order_(static_cast<size_t>(n)) {
    std::iota(order_.begin(), order_.end(), Eigen::Index{0});
    std::shuffle(order_.begin(), order_.end(), std::mt19937_64(seed));
  }
  Eigen::MatrixX3d take(const Eigen::MatrixX3d& points, Eigen::Index count) const {
    std::vector<Eigen::Index> index(order_.begin(), order_.begin() + count);
    std::sort(index.begin(), index.end());
    Eigen::MatrixX3d out(count, 3);
    for (Eigen::Index i = 0; i < count; ++i) out.row(i) = points.row(index[static_cast<size_t>(i)]);
    return out;
  }

 private:
  std::vector<Eigen::Index> order_;
};

// Every model fitted on a sample, finished on a larger set of points from
// its optimum there (a few Levenberg-Marquardt steps: the sample's optimum is
// within its standard errors of the larger one's), nesting checked again.
HierarchyFits refineAll(const HierarchyFits& on_sample, const Eigen::MatrixX3d& points, const AlgebraicStarts& a,
                        const Options& o) {
  auto bounds = [&](ShapeModel m) { return makeBounds(m, a.ellipsoid, a.sphere, o); };
  // From so near the optimum, steps that gain less than 1e-7 of the squared
  // sum (an RMS change of 5e-8 relative) are not worth ~0.5 s each at 10^6 points.
  Options finish = o;
  finish.max_evaluations = o.refine_evaluations;
  finish.restarts = 0;
  finish.relative_tolerance = std::max(o.relative_tolerance, 1e-7);
  // `parent`: a refined parent, whose closest points on all the points are
  // warm starts for its child (as in fitAll), sparing a global search.
  auto refine = [&](const Fitted& coarse, const Fitted* parent) {
    if (coarse.fit.evaluations == 0) return coarse;
    const ShapeModel model = coarse.fit.parameters.model;
    Eigen::MatrixX3d feet;
    if (parent && parent->feet.rows() == points.rows()) feet = parent->feet;
    Fitted f = fitModel(model, {{coarse.fit.started_from, coarse.fit.parameters, feet}}, bounds(model), points, finish);
    log::debug("fit: " + geometry::modelName(model) + " finished on " + std::to_string(points.rows()) + " points in " +
               std::to_string(f.fit.evaluations) + " evaluations, " + std::to_string(f.fit.seconds) + " s (" +
               f.fit.termination + ")");
    f.fit.started_from = coarse.fit.started_from;
    f.fit.evaluations += coarse.fit.evaluations;
    f.fit.seconds += coarse.fit.seconds;
    return f;
  };
  HierarchyFits h;
  h.sphere = refine(on_sample.sphere, nullptr);
  h.ellipsoid = refine(on_sample.ellipsoid, &h.sphere);
  enforceNesting(h.ellipsoid, h.sphere, points, bounds(ShapeModel::Ellipsoid), o.threads);
  h.superellipsoid = refine(on_sample.superellipsoid, &h.ellipsoid);
  if (h.superellipsoid.fit.evaluations > 0)
    enforceNesting(h.superellipsoid, h.ellipsoid, points, bounds(ShapeModel::Superellipsoid), o.threads);
  h.ovoid = refine(on_sample.ovoid, &h.ellipsoid);
  if (h.ovoid.fit.evaluations > 0) enforceNesting(h.ovoid, h.ellipsoid, points, bounds(ShapeModel::Ovoid), o.threads);
  const Fitted& so_parent = h.superellipsoid.fit.rms_mm <= h.ovoid.fit.rms_mm ? h.superellipsoid : h.ovoid;
  h.superovoid = refine(on_sample.superovoid, &so_parent);
  if (h.superovoid.fit.evaluations > 0) enforceNesting(h.superovoid, so_parent, points, bounds(ShapeModel::Superovoid), o.threads);
  return h;
}

// Other labellings' optima are fitted on about this many of the points
// (every k-th, where there are twice as many or more), with at most this
// many evaluations each (most take 30-60): their part is the intervals'
// reach, not the fit.
constexpr int kOtherOptimaPoints = 1000, kOtherOptimumEvaluations = 150;

// The egg `reported`'s intervals widened over its optima from each labelling
// of the ellipsoid's axes (other_optima.hpp), compared on the same points.
void spanOptimaOfLabellings(const Fitted& ellipsoid, const Bounds& bounds, const Eigen::MatrixX3d& all_points, const Options& o,
                   ModelFit& reported) {
  const Eigen::MatrixX3d points = subsample(all_points, kOtherOptimaPoints);
  const ShapeModel model = reported.parameters.model;
  // The bound on all the points' sum of squares, scaled to the subsample's as its rises are.
  const double bound = likelihoodRatioBoundMm2(reported.parameters, reported.uncertainty, reported.sse_mm2,
                                               all_points.rows()) *
                       static_cast<double>(points.rows()) / static_cast<double>(all_points.rows());
  if (!(bound > 0)) return;
  // The reported optimum's residuals on the points compared, and their sum of squares.
  const VectorXd own = distance::signedDistances(reported.parameters, points, o.threads);
  const double sse = points.rows() == all_points.rows() ? reported.sse_mm2 : own.squaredNorm();
  Options local = o;
  local.strategy = Strategy::Local;
  local.restarts = 0;
  local.max_evaluations = std::min(o.max_evaluations, kOtherOptimumEvaluations);
  local.threads = 1;  // the labellings side by side instead
  std::vector<Start> starts;
  for (Start start : axisLabellings(ellipsoid)) {
    if (reported.started_from.rfind(start.label, 0) == 0) continue;  // the reported optimum's own start
    if (start.feet.rows() == all_points.rows()) start.feet = subsample(start.feet, kOtherOptimaPoints);
    starts.push_back(start);
  }
  // Independent fits, each into its own slot: the same optima for any thread count.
  std::vector<std::optional<OtherOptimum>> found(starts.size());
  parallelFor(static_cast<std::ptrdiff_t>(starts.size()), 1, o.threads, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
    for (auto i = static_cast<size_t>(begin); i < static_cast<size_t>(end); ++i) {
      const Fitted f = fitModel(model, {starts[i]}, bounds, points, local);
      const bool same = (f.fit.parameters.center - reported.parameters.center).norm() < 1e-6;
      // Taken in unless the data rule it out: beyond the bound and by its lean along the difference.
      if (same || !(f.fit.sse_mm2 <= sse + bound ||
                    couldBeTheTruth(own, distance::signedDistances(f.fit.parameters, points, 1), points,
                                    reported.uncertainty.correlation, static_cast<int>(starts.size()))))
        continue;
      found[i] = OtherOptimum{f.fit.parameters, f.fit.sse_mm2,
                              parameterUncertainty(f.fit.parameters, points, f.feet, o.uncertainty, o.edge_offset, 1)};
    }
  });
  std::vector<OtherOptimum> others;
  for (auto& f : found)
    if (f) others.push_back(std::move(*f));
  spanOtherOptima(reported.parameters, bound, others, reported.uncertainty);
}

}  // namespace

void spanEggOptima(const ShapeParameters& ellipsoid, const ShapeParameters& egg, const Eigen::MatrixX3d& points,
                   const Options& o, ParameterUncertainty& u) {
  o.validate();
  const AlgebraicStarts a = algebraicStarts(points);
  Fitted parent;
  parent.fit.parameters = ellipsoid;
  ModelFit reported;
  reported.parameters = egg;
  Eigen::MatrixX3d feet;
  exactRms(egg, points, reported.sse_mm2, feet, o.threads);
  reported.uncertainty = std::move(u);
  spanOptimaOfLabellings(parent, makeBounds(egg.model, a.ellipsoid, a.sphere, o), points, o, reported);
  u = std::move(reported.uncertainty);
}

ModelFit fitFrom(const ShapeParameters& start, const Eigen::MatrixX3d& points, const Options& o) {
  o.validate();
  const AlgebraicStarts a = algebraicStarts(points);
  const Bounds b = makeBounds(start.model, a.ellipsoid, a.sphere, o);
  Fitted f = fitModel(start.model, {{"given start", start, {}}}, b, points, o);
  f.fit.uncertainty = parameterUncertainty(f.fit.parameters, points, f.feet, o.uncertainty, o.edge_offset, o.threads);
  return f.fit;
}

Summary fitHierarchy(const Eigen::MatrixX3d& points, const Options& o) {
  o.validate();
  const auto t0 = Clock::now();
  const Eigen::Index min_points = geometry::parameterCount(ShapeModel::Superovoid);
  if (points.rows() < min_points)
    throw InputError("fit: expected at least " + std::to_string(min_points) + " points, found " +
                     std::to_string(points.rows()));
  if (!points.allFinite()) throw InputError("fit: points contain NaN or Inf");

  HierarchyFits h;
  AlgebraicStarts a;
  if (o.sample_points > 0 && points.rows() > o.sample_points) {
    // Fitted on a sample, then finished on samples four times larger up to
    // all the points: each stage starts within a few steps of its optimum,
    // and most steps are taken where they are cheap.
    log::info("fit: " + std::to_string(points.rows()) + " points: fitting on a random sample of " +
              std::to_string(o.sample_points) + ", then on larger ones up to all");
    const NestedSamples samples(points.rows(), o.seed);
    Eigen::Index size = o.sample_points;
    const Eigen::MatrixX3d first = samples.take(points, size);
    a = algebraicStarts(first);
    h = fitAll(first, a, o, true);
    while (size < points.rows()) {
      size = 8 * size >= points.rows() ? points.rows() : 4 * size;  // no stage of more than half the points
      h = refineAll(h, size == points.rows() ? points : samples.take(points, size), a, o);
      for (const Fitted* f : {&h.sphere, &h.ellipsoid, &h.superellipsoid, &h.ovoid, &h.superovoid})
        if (f->fit.evaluations > 0) reportModel(*f, true);
    }
    const std::string note = " (fitted on a random sample of " + std::to_string(o.sample_points) + " of the " +
                             std::to_string(points.rows()) + " points, then on all)";
    for (Fitted* f : {&h.sphere, &h.ellipsoid, &h.superellipsoid, &h.ovoid, &h.superovoid}) f->fit.started_from += note;
  } else {
    a = algebraicStarts(points);
    h = fitAll(points, a, o, false);
  }

  Summary summary;
  summary.points = static_cast<int>(points.rows());
  for (const Fitted* f : {&h.sphere, &h.ellipsoid, &h.superellipsoid, &h.ovoid, &h.superovoid})
    if (wanted(o, f->fit.parameters.model) && f->fit.evaluations > 0) {
      summary.fits.push_back(f->fit);
      summary.fits.back().uncertainty = parameterUncertainty(f->fit.parameters, points, f->feet, o.uncertainty, o.edge_offset, o.threads);
      const ShapeModel model = f->fit.parameters.model;
      if (geometry::contains(model, ShapeModel::Ovoid) && o.span_other_optima)
        spanOptimaOfLabellings(h.ellipsoid, makeBounds(model, a.ellipsoid, a.sphere, o), points, o, summary.fits.back());
    }
  double best_rms = std::numeric_limits<double>::infinity();
  for (const auto& f : summary.fits)
    if (f.rms_mm < best_rms - 1e-9) {
      best_rms = f.rms_mm;
      summary.best_model = geometry::modelName(f.parameters.model);
    }
  summary.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return summary;
}

std::string nloptVersion() {
  int major = 0, minor = 0, bugfix = 0;
  nlopt::version(major, minor, bugfix);
  return std::to_string(major) + "." + std::to_string(minor) + "." + std::to_string(bugfix);
}

std::string eigenVersion() {
  return std::to_string(EIGEN_WORLD_VERSION) + "." + std::to_string(EIGEN_MAJOR_VERSION) + "." + std::to_string(EIGEN_MINOR_VERSION);
}

}  // namespace articula::fit
