#pragma once
// Fitting the hierarchy sphere -> ellipsoid -> {superellipsoid, ovoid} ->
// superovoid (thesis fig. 3.2) to a point cloud, Ceres-style: an Options
// struct validated before use and a Summary with the termination reason of
// every model.
//
// The local method, chosen by measurement (docs/benchmarks.md, bench-fit):
// Levenberg-Marquardt on the residuals themselves (orthogonal distance
// fitting, Ahn 2004: the Jacobian of the signed distances is dF/dlambda /
// |grad F| at the closest points), about 3x faster than NLopt's best
// (LD_SLSQP on the summed squares) to the same optima. NLopt stays for the
// optional global search (GN_CRS2_LM, Strategy::GlobalLocal) and as the
// alternative local methods.
//
// Every child starts at its parent's optimum (which it contains exactly) and
// keeps the best point it evaluates, so each model's RMS signed Euclidean
// distance is <= its parent's (the nesting guarantee; checked on the exact
// distances after fitting, falling back to the parent's shape otherwise).
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "articula/fit/termination.hpp"
#include "articula/fit/uncertainty.hpp"
#include "articula/geometry/shape.hpp"

namespace articula::fit {

enum class Objective {
  Algebraic,  // thesis eq. 3.1: sum of F(x_i)^2 (F = 0 on the surface)
  Geometric,  // orthogonal distance fitting: sum of squared signed Euclidean distances
};
std::string objectiveName(Objective o);
/// "algebraic" or "geometric"; throws UsageError otherwise.
Objective objectiveFromName(const std::string& name);

enum class Strategy {
  Local,        // local_algorithm from the hierarchical start (default)
  GlobalLocal,  // GN_CRS2_LM within the bounds (seeded, capped), then local_algorithm
};
std::string strategyName(Strategy s);
Strategy strategyFromName(const std::string& name);

struct Options {
  std::vector<geometry::ShapeModel> models = geometry::allModels();  // what to report (ancestors are fitted anyway)
  Objective objective = Objective::Geometric;
  Strategy strategy = Strategy::Local;
  std::string local_algorithm = "LM";  // Levenberg-Marquardt (ours); or NLopt LD_SLSQP, LN_BOBYQA, LD_LBFGS, ...
  unsigned seed = 42;                  // NLopt's random seed (CRS2)
  int threads = 1;                     // worker threads (0: every hardware thread); the same fits for any count
  int max_evaluations = 4000;          // per local run
  int global_evaluations = 3000;       // per global run (GlobalLocal)
  int restarts = 2;                    // local restarts from the result while they gain > 1e-6 relative
  int screening_evaluations = 40;      // models with several starts: evaluations per start before the best is finished
  int screening_points = 400;          // screen the starts on about this many of the points (every k-th; 0 = all)
  int screening_finalists = 3;         // then finish this many of the best (distinct) on all points
  int sample_points = 50000;           // more points: fit on a seeded random sample of this many, then
                                       // finish every model on all of them (0 = always all)
  int refine_evaluations = 20;         // per model, when finishing on all the points
  double relative_tolerance = 1e-12;   // on the objective (ftol_rel)
  double parameter_tolerance = 1e-10;  // on the parameters (xtol_rel)
  // Bounds (thesis section 3.2.5), around the reference ellipsoid start:
  double radius_interval = 0.5;        // radii in [(1 - r) a_min, (1 + r) a_max]
  double center_interval = 0.5;        // centre within this fraction of the largest radius
  double exponent_min = 2.0, exponent_max = 4.0;
  double c01_min = 0.0, c01_max = 1.0;    // c0, c1
  double c23_min = -0.1, c23_max = 0.1;   // c2, c3
  /// Overrides by parameter name of table 3.2 ("a", "gamma1", "c2x", "t1", ...).
  std::map<std::string, std::pair<double, double>> bounds;
  UncertaintyMethod uncertainty = UncertaintyMethod::SpatialModel;  // of every reported model
  /// An ovoid's and superovoid's centre and semi-axes intervals take in
  /// their optima from every labelling of the ellipsoid's axes within the
  /// likelihood-ratio bound (other_optima.hpp).
  bool span_other_optima = true;
  /// The edge's offset field the points' voxel grid implies (none: points of
  /// unknown origin; their intervals hold what the residuals show).
  EdgeOffsetField edge_offset;

  /// Throws UsageError naming the first bad field.
  void validate() const;
};

struct ModelFit {
  geometry::ShapeParameters parameters;
  std::string started_from;        // "algebraic", or the parent model(s) tried
  double rms_mm = 0.0;             // RMS of the exact signed Euclidean distances
  double sse_mm2 = 0.0;            // sum of their squares (geometric objective)
  double algebraic_objective = 0.0;  // eq. 3.1 at the result
  int evaluations = 0;
  double seconds = 0.0;
  std::string termination;         // the optimiser's reason in words, and whether the parent was kept
  Termination termination_type = Termination::InvalidStart;  // the same for programs (of the run kept)
  bool converged = false;
  ParameterUncertainty uncertainty;  // at the result (uncertainty.hpp)
};

struct Summary {
  std::vector<ModelFit> fits;      // in hierarchy order, only the requested models
  std::string best_model;          // lowest RMS (fits.json "least_rms_model"); ties go to the simpler model
  int points = 0;
  double seconds = 0.0;
  std::string briefReport() const;
  std::string fullReport() const;
  const ModelFit& fit(geometry::ShapeModel model) const;  // throws UsageError if absent
};

/// Fits `points` (#P x 3, LPS mm). Throws UsageError for bad options and
/// ProcessingError if no start can be found (degenerate points).
Summary fitHierarchy(const Eigen::MatrixX3d& points, const Options& options = {});

/// One model, fitted locally from `start` alone (its model is start.model),
/// within the bounds fitHierarchy would use: e.g. the reference "started at
/// the true parameters" of the oracle benchmark.
ModelFit fitFrom(const geometry::ShapeParameters& start, const Eigen::MatrixX3d& points, const Options& options = {});

/// What fitHierarchy does to an ovoid's or superovoid's intervals
/// (Options::span_other_optima): `u`, the uncertainty of `egg` (an optimum on
/// `points`), with its centre and semi-axes intervals widened over the egg's
/// optima from each labelling of `ellipsoid`'s axes within the
/// likelihood-ratio bound (other_optima.hpp). For intervals computed apart
/// from the fit (bench-coverage's methods).
void spanEggOptima(const geometry::ShapeParameters& ellipsoid, const geometry::ShapeParameters& egg,
                   const Eigen::MatrixX3d& points, const Options& options, ParameterUncertainty& u);

/// The thesis objective eq. 3.1 and the geometric SSE (mm^2) of a shape.
double algebraicObjective(const geometry::ShapeParameters& shape, const Eigen::MatrixX3d& points);
double geometricObjective(const geometry::ShapeParameters& shape, const Eigen::MatrixX3d& points, int threads = 1);

/// The NLopt and Eigen versions this build fits with.
std::string nloptVersion();
std::string eigenVersion();

}  // namespace articula::fit
