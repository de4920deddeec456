// `demcal sweep`: see demcal/sweep.hpp (being written).
#include <stdexcept>

#include "commands.hpp"

namespace demcal::cli {
int cmd_sweep(const SweepOptions&) { throw std::runtime_error("demcal sweep is not built yet"); }
}  // namespace demcal::cli
