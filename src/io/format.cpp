#include "demcal/io/format.hpp"

#include <cmath>
#include <cstdio>

namespace demcal {

std::string num(double v, int significant) {
  if (!std::isfinite(v)) return "n/a";
  char b[64];
  std::snprintf(b, sizeof b, "%.*g", significant, v);
  return b;
}

std::string fixed(double v, int decimals) {
  if (!std::isfinite(v)) return "n/a";
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", decimals, v);
  return b;
}

std::string pct(double fraction, int decimals) {
  if (!std::isfinite(fraction)) return "n/a";
  return fixed(100.0 * fraction, decimals) + " %";
}

std::string signed_pct(double fraction, int decimals) {
  if (!std::isfinite(fraction)) return "n/a";
  // The sign appended, not inserted in front ("+" + string): GCC 12 warns
  // -Wrestrict (a false positive) on the inlined insert.
  std::string out = fraction >= 0 ? "+" : "";
  out += fixed(100.0 * fraction, decimals);
  out += " %";
  return out;
}

std::string sci(double v) {
  if (!std::isfinite(v)) return "n/a";
  if (v == 0.0) return "0";
  const int e = static_cast<int>(std::floor(std::log10(std::abs(v))));
  if (e >= -2 && e <= 4) return num(v, 4);
  char b[64];
  std::snprintf(b, sizeof b, "%.3ge%d", v / std::pow(10.0, e), e);
  return b;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace demcal
