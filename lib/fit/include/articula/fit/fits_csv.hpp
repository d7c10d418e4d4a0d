#pragma once
// fits.csv (docs/formats.md): a row per fitted model, its parameters with
// their units in the column names, its RMS, objective and the optimiser's
// report, then a standard error per parameter of the superovoid (the widest
// model), empty where a model lacks the parameter or the points leave it open.
#include <string>

#include "articula/fit/fit_hierarchy.hpp"

namespace articula::fit {

/// The whole file's text, header first.
std::string fitsCsv(const Summary& summary);

}  // namespace articula::fit
