// Orders reorder() must refuse (World and SphereWorld,
// detail::inverse_permutation): each with the end of the message it throws.
#pragma once

#include <numeric>
#include <string>
#include <utility>
#include <vector>

namespace demcal::reorder_test {

inline std::vector<std::pair<std::string, std::vector<int>>> bad_orders(int n) {
  std::vector<int> identity(n);
  std::iota(identity.begin(), identity.end(), 0);
  const std::string once = ": order must list every particle once";
  const std::string perm = ": order is not a permutation";
  std::vector<std::pair<std::string, std::vector<int>>> out;
  auto with = [&](int k, int v) {
    std::vector<int> o = identity;
    o[k] = v;
    return o;
  };
  out.emplace_back(perm, with(n - 1, 0));          // 0 twice, n − 1 missing
  out.emplace_back(perm, with(n / 2, n / 2 + 1));  // a repeat inside
  out.emplace_back(perm, with(n - 1, n));          // out of range above
  out.emplace_back(perm, with(0, -1));             // and below
  out.emplace_back(once, std::vector<int>(identity.begin(), identity.end() - 1));  // too short
  std::vector<int> longer = identity;
  longer.push_back(n);
  out.emplace_back(once, longer);  // too long
  out.emplace_back(once, std::vector<int>());
  return out;
}

}  // namespace demcal::reorder_test
