#pragma once
// The reports' interactive 3-D view: the bone mesh, the articular points
// coloured by their signed distance to a chosen model (diverging, symmetric
// range, colour bar) and each fitted surface, switchable; drawn by three.js,
// which the section inlines so that the page opens offline. Debian's
// libjs-three: a maintained WebGL library the install script brings with
// apt like every other dependency, small enough (850 KB) to inline, where
// vtk.js and NiiVue would come from npm and weigh more.
#include <string>
#include <vector>

#include <Eigen/Core>

namespace articula::report {

struct ViewSurface {
  std::string name;
  Eigen::MatrixX3d vertices;   // LPS mm
  Eigen::MatrixX3i triangles;  // 0-based
};

struct ViewModelDistances {
  std::string model;
  Eigen::VectorXd signed_distance_mm;  // one per point (positive: outside the model)
};

struct View3d {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // the view turns about it (LPS mm)
  double radius_mm = 25;                             // the head's size, to place the camera
  ViewSurface bone;                                  // no vertices: not shown
  Eigen::MatrixX3d points;                           // articular points, LPS mm
  std::vector<ViewModelDistances> distances;         // the points' colourings, one per model
  std::vector<ViewSurface> fitted;                   // the fitted surfaces, named by model
  std::string selected_model;                        // coloured and shown first
  ViewSurface departures;                            // where the bone departs from the selected model (none: not shown)
  double colour_range_mm = 0;                        // every colouring's range; 0: each its own (symmetricColourRange)
};

/// The signed-distance range a colouring spans, symmetric about 0: the 98th
/// percentile of |d| (outliers saturate instead of washing out the map),
/// at least 0.01 mm.
double symmetricColourRange(const Eigen::VectorXd& signed_distance_mm);

/// A <section id="view3d"> with the view's canvas, controls, colour bar,
/// data and scripts. The canvas reports the pixels its first frame drew in
/// its data-rendered-pixels attribute (a check that the view is not blank).
std::string web3dViewHtml(const View3d& view);

}  // namespace articula::report
