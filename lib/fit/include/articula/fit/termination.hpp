#pragma once
// Why a local fit stopped, for programs and study tables (the words of
// ModelFit::termination are for people): Levenberg-Marquardt's and NLopt's
// reasons in one set.

namespace articula::fit {

enum class Termination {
  ObjectiveTolerance,  // an accepted step gained less than the relative tolerance
  ParameterTolerance,  // the scaled step became negligible
  ExactFit,            // residuals at rounding level (exact data)
  NoFurtherDescent,    // the damping reached its limit without a better point
  RoundoffLimited,     // the optimiser stopped at rounding level (NLopt)
  EvaluationLimit,     // stopped by the evaluation limit: not converged
  TimeLimit,           // stopped by a time limit: not converged
  InvalidStart,        // the start lies outside the model's valid set
  OptimizerFailure,    // the optimiser gave up (NLopt's failure codes)
};

/// snake_case, as written in fits.json's "termination_type".
constexpr const char* terminationName(Termination t) {
  switch (t) {
    case Termination::ObjectiveTolerance: return "objective_tolerance";
    case Termination::ParameterTolerance: return "parameter_tolerance";
    case Termination::ExactFit: return "exact_fit";
    case Termination::NoFurtherDescent: return "no_further_descent";
    case Termination::RoundoffLimited: return "roundoff_limited";
    case Termination::EvaluationLimit: return "evaluation_limit";
    case Termination::TimeLimit: return "time_limit";
    case Termination::InvalidStart: return "invalid_start";
    case Termination::OptimizerFailure: return "optimizer_failure";
  }
  return "optimizer_failure";
}

/// Whether a run that stopped for this reason reached a minimum.
constexpr bool isConverged(Termination t) {
  return t == Termination::ObjectiveTolerance || t == Termination::ParameterTolerance || t == Termination::ExactFit ||
         t == Termination::NoFurtherDescent || t == Termination::RoundoffLimited;
}

}  // namespace articula::fit
