// Numbers as people read them in reports, tables and messages. One set of
// formatters for every module, so the same quantity reads the same way in
// report.md, the sweep atlas, the scaling study and the decks.
#pragma once

#include <chrono>
#include <string>

namespace demcal {

/// printf "%.{significant}g"; "n/a" when not finite.
std::string num(double v, int significant = 4);
/// printf "%.{decimals}f"; "n/a" when not finite.
std::string fixed(double v, int decimals);
/// A fraction as a percentage: pct(0.0123) = "1.23 %".
std::string pct(double fraction, int decimals = 2);
/// As pct, with the sign always written: "+1.23 %", "-0.40 %".
std::string signed_pct(double fraction, int decimals = 2);
/// Engineering-style: plain for 1e-2 <= |v| < 1e5, else "1.23e6".
std::string sci(double v);

/// Wall-clock seconds since t0 (a steady clock: immune to clock changes).
double seconds_since(std::chrono::steady_clock::time_point t0);

}  // namespace demcal
