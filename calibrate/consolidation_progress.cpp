#include "consolidation_progress.hpp"

#include <algorithm>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <thread>

#include "demcal/scene/consolidation_cache.hpp"

namespace demcal::cli {

namespace {

std::string seconds(double s) {
  std::ostringstream o;
  o << std::fixed << std::setprecision(s < 10.0 ? 1 : 0) << s << " s";
  return o.str();
}

}  // namespace

int prototype_consolidation_threads(int64_t particles) { return particles >= kThreadsFrom ? 0 : 1; }

std::string consolidation_threads_words(int threads) {
  const int n =
      threads > 0 ? threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return n == 1 ? std::string("single-threaded") : "on " + std::to_string(n) + " threads";
}

ConsolidationCallback consolidation_progress(double every_s) {
  struct Last {
    double line_s = 0.0;  // elapsed_s at the last line
    int64_t steps = 0;    // at the last check
  };
  auto last = std::make_shared<Last>();
  return [last, every_s](const ConsolidationProgress& p) {
    // A later consolidation through the same callback (scaling's sizes)
    // starts again, at step 200 and time 0: its lines count from there.
    if (p.steps <= last->steps) last->line_s = 0.0;
    last->steps = p.steps;
    if (p.elapsed_s - last->line_s < every_s) return;
    last->line_s = p.elapsed_s;
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
  // Three significant digits, whatever the stream's format: a wall time is
  // not known better, and every command prints it alike; whole seconds
  // from 1000 s on (a prototype's consolidation: "4012 s", not "4.01e+03 s").
  std::ostringstream o;
  if (wall_time_s >= 1000.0)
    o << std::fixed << std::setprecision(0);
  else
    o << std::setprecision(3);
  o << wall_time_s << " s";
  out << o.str();
}

void print_consolidated(std::ostream& out, std::string_view prefix, std::string_view what,
                        int64_t steps, double wall_time_s, bool from_cache) {
  out << prefix << "consolidated " << what << (what.empty() ? "" : " ") << "in " << steps
      << " steps, ";
  print_consolidation_time(out, wall_time_s, from_cache);
}

// The cache's entry point with a fresh consolidation ("" for its cache
// folder: none) that announces itself: consolidate()'s state, bit for bit.
ConsolidatedState consolidate_announced(const SceneConfig& config, const Assembly& assembly,
                                        const ConsolidationOptions& options,
                                        const std::function<void()>& announce) {
  return consolidate_cached<ConsolidatedState>(consolidation_cache_dir(), config, assembly, [&] {
    announce();
    return consolidate(config, assembly, std::string(), options);
  });
}

TriaxialState consolidate_announced(const SceneConfig& config, const SphereAssembly& assembly,
                                    const ConsolidationOptions& options,
                                    const std::function<void()>& announce) {
  return consolidate_cached<TriaxialState>(consolidation_cache_dir(), config, assembly, [&] {
    announce();
    return consolidate_triaxial(config, assembly, std::string(), options);
  });
}

}  // namespace demcal::cli
