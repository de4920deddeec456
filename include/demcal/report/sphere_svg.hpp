// The 3D assembly picture of the report: the spheres in a shaded
// axonometric view, drawn directly as SVG (no gnuplot needed). Orthographic projection
// along the view direction, painter's order (farthest first, so a sphere in
// front covers the ones behind it), each sphere a circle filled with a
// radial gradient (highlight up-left, darker rim) of its colour: the sum of
// the normal contact forces on it, on a sequential scale binned into
// kSphereColourBins colours, with a legend from the smallest to the largest
// value. The box of walls is drawn around them: its hidden edges behind the
// spheres, the three edges at the corner nearest the viewer in front.
#pragma once

#include <string>
#include <vector>

#include "demcal/search/evidence.hpp"

namespace demcal {

/// A view direction: from the scene toward the viewer, z up. The default
/// looks down on the box from the front right (the viewer at +x, −y and
/// above), off the cube's diagonal so that the three visible faces have
/// different sizes and the nearest corner does not sit in the middle.
struct SphereView {
  double azimuth_deg = -35.0;  ///< of the viewer, from +x toward +y
  double elevation_deg = 24.0;
};

/// One sphere as drawn: screen position (u right, v up, metres), radius,
/// depth along the view direction (larger = nearer the viewer) and its index
/// in the picture.
struct ProjectedSphere {
  double u = 0, v = 0, r = 0, depth = 0;
  int index = 0;
};
/// Every sphere of `p` projected, in drawing order: increasing depth (the
/// farthest first); ties keep the picture's order.
std::vector<ProjectedSphere> project_spheres(const SpherePicture& p, const SphereView& view = {});

inline constexpr int kSphereColourBins = 24;

/// The colour scale of a picture: [lo, hi] the smallest and largest force.
struct SphereColourScale {
  double lo = 0, hi = 0;
  /// The bin (0 … kSphereColourBins − 1) of value v.
  int bin(double v) const;
};
SphereColourScale colour_scale(const SpherePicture& p);

/// An inline <svg class="assembly"> element: one <circle> per sphere in
/// project_spheres() order, the legend (a <g class="legend"> with
/// data-lo/data-hi, the scale's range to 9 digits); "" for a picture with
/// no spheres or no extent.
std::string sphere_svg(const SpherePicture& p, const SphereView& view = {});

}  // namespace demcal
