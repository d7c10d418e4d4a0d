#pragma once
// The report's CT slices: three orthogonal planes (axial, coronal, sagittal,
// in radiological view), each through the fitted head's centre and half a
// radius to either side, the CT in a bone window, the segmentation's edge
// and the fitted model's outline drawn on it, so that a wrong segmentation
// or a fit beside the bone shows at a glance; orientation letters, a 10 mm
// scale bar and each slice's position.
#include <string>

#include <Eigen/Core>

#include "articula/geometry/shape.hpp"
#include "articula/imaging/image.hpp"

namespace articula::subject {

/// Inline SVG figures (the CT as an embedded PNG, the label's edge in
/// yellow when `label` is given, the model's outline in magenta), each a
/// square of `half_width_mm` either side of its centre sampled every
/// `step_mm`; a row of three per plane.
std::string headSlicesHtml(const imaging::Volume& ct, const imaging::Label* label, const geometry::ShapeParameters& model,
                           double half_width_mm, double step_mm);

}  // namespace articula::subject
