// The assembly picture of the report, drawn directly as SVG (no gnuplot
// needed): disks coloured by rotation, contact forces as lines of width
// proportional to the normal force, a legend. Private to the report.
#pragma once

#include <string>

#include "demcal/search/evidence.hpp"

namespace demcal::report {

/// An inline <svg> element; "" for a picture with no extent.
std::string assembly_svg(const AssemblyPicture& p);

}  // namespace demcal::report
