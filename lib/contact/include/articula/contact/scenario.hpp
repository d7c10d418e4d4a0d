#pragma once
// The prescribed motions of thesis tables 5.3 (four ellipsoid pairs) and 5.4
// (three superellipsoid pairs). The thesis gives the shapes and the kind of
// motion but not the placements or speeds; the ones used here are stated in
// scenario.cpp: body i at the origin turning once about its local x axis over
// the 200 steps; body j turning once about its axis and moving on the stated
// path with a gap that goes from +0.25 mm to -0.25 mm (overlap) and back.
#include <string>
#include <vector>

#include "articula/contact/convex_shape.hpp"

namespace articula::contact {

struct ScenarioPair {
  ConvexShape i, j;
};

/// "table5.3-1" ... "table5.3-4", "table5.4-1" ... "table5.4-3".
const std::vector<std::string>& scenarioNames();

/// The pair at step k in [0, steps); throws UsageError for an unknown name
/// (listing the valid names).
ScenarioPair scenarioPair(const std::string& name, int k, int steps = 200);

}  // namespace articula::contact
