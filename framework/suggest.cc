#include "framework/suggest.h"

#include <algorithm>
#include <string>
#include <vector>

namespace swarmsim {

int EditDistance(std::string_view a, std::string_view b) {
  // Optimal string alignment over three rows (two back for swaps).
  const size_t n = a.size(), m = b.size();
  std::vector<int> prev2(m + 1), prev(m + 1), cur(m + 1);
  for (size_t j = 0; j <= m; ++j) prev[j] = static_cast<int>(j);
  for (size_t i = 1; i <= n; ++i) {
    cur[0] = static_cast<int>(i);
    for (size_t j = 1; j <= m; ++j) {
      const int cost = a[i - 1] == b[j - 1] ? 0 : 1;
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        cur[j] = std::min(cur[j], prev2[j - 2] + 1);
    }
    prev2.swap(prev);
    prev.swap(cur);
  }
  return prev[m];
}

const std::string* NearestName(std::string_view name, std::span<const std::string> candidates) {
  const std::string* best = nullptr;
  int best_distance = 0;
  for (const std::string& c : candidates) {
    const int d = EditDistance(name, c);
    if (!best || d < best_distance) best = &c, best_distance = d;
  }
  if (best == nullptr) return nullptr;
  // Close enough to be a typo: up to 2 edits, or a third of the longer name.
  const int longest = static_cast<int>(std::max(name.size(), best->size()));
  if ((best_distance <= 2 || best_distance * 3 <= longest) && best_distance < longest) return best;
  return nullptr;
}

std::string Suggest(std::string_view name, std::span<const std::string> candidates) {
  if (candidates.empty()) return "";
  if (const std::string* nearest = NearestName(name, candidates))
    return "; did you mean '" + *nearest + "'?";
  // A model's every path can be hundreds: the first dozen and a count.
  constexpr size_t kListed = 12;
  std::string list;
  for (size_t i = 0; i < candidates.size() && i < kListed; ++i)
    list += (list.empty() ? "" : ", ") + candidates[i];
  if (candidates.size() > kListed)
    list += ", ... (" + std::to_string(candidates.size() - kListed) + " more)";
  return " (expected one of: " + list + ")";
}

}  // namespace swarmsim
