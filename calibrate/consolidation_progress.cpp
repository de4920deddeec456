#include "consolidation_progress.hpp"

#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

namespace demcal::cli {

namespace {

std::string seconds(double s) {
  std::ostringstream o;
  o << std::fixed << std::setprecision(s < 10.0 ? 1 : 0) << s << " s";
  return o.str();
}

}  // namespace

ConsolidationCallback consolidation_progress(double every_s) {
  auto last = std::make_shared<double>(0.0);  // elapsed_s at the last line
  return [last, every_s](const ConsolidationProgress& p) {
    if (p.elapsed_s - *last < every_s) return;
    *last = p.elapsed_s;
    std::ostringstream o;
    o << "consolidating (" << (p.phase == 0 ? "frictionless" : "friction on") << "): step "
      << p.steps << " of at most " << p.max_steps << ", wall stress error " << std::setprecision(3)
      << 100.0 * p.stress_error << " %, unbalanced-force ratio " << p.unbalanced_ratio << "; "
      << seconds(p.elapsed_s) << " so far, ";
    if (p.steps_to_go >= 0)
      o << "about " << seconds(p.remaining_s) << " (" << p.steps_to_go
        << " steps) more for this phase at its rate of convergence";
    else
      o << "no convergence trend yet";
    o << ", at most " << seconds(p.remaining_max_s) << " (the step budget)";
    std::cerr << o.str() << std::endl;
  };
}

void print_consolidation_time(std::ostream& out, double wall_time_s, bool from_cache) {
  if (from_cache) out << "read from the cache in ";
  out << wall_time_s << " s";
}

}  // namespace demcal::cli
