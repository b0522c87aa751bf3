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

// Whether `word` is one of the '_'-separated words of `name` (not all of it).
bool IsWordOf(std::string_view word, std::string_view name) {
  if (word.empty() || word.size() >= name.size()) return false;
  for (size_t start = 0; start <= name.size();) {
    const size_t end = std::min(name.find('_', start), name.size());
    if (name.substr(start, end - start) == word) return true;
    start = end + 1;
  }
  return false;
}

const std::string* NearestName(std::string_view name, std::span<const std::string> candidates) {
  // A name cut short (with_cam): the shortest that begins with it, before
  // any that is fewer edits away (with_rab).
  const std::string* longer = nullptr;
  if (name.size() >= 3)
    for (const std::string& c : candidates)
      if (c.size() > name.size() && c.starts_with(name) && (!longer || c.size() < longer->size()))
        longer = &c;
  if (longer != nullptr) return longer;
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
  // Or one is a whole word of the other ('noise_std' for 'noise').
  for (const std::string& c : candidates)
    if (IsWordOf(c, name) || IsWordOf(name, c)) return &c;
  return nullptr;
}

std::string Suggest(std::string_view name, std::span<const std::string> candidates) {
  if (candidates.empty()) return "";
  if (const std::string* nearest = NearestName(name, candidates))
    return "; did you mean '" + *nearest + "'?";
  // Every key of a section fits; a model's every path can be hundreds: as
  // many as fit in about five lines, and a count.
  constexpr size_t kListedCharacters = 400;
  std::string list;
  size_t listed = 0;
  for (; listed < candidates.size(); ++listed) {
    if (listed > 0 && list.size() + candidates[listed].size() > kListedCharacters) break;
    list += (list.empty() ? "" : ", ") + candidates[listed];
  }
  if (listed < candidates.size())
    list += ", ... (" + std::to_string(candidates.size() - listed) + " more)";
  return " (expected one of: " + list + ")";
}

}  // namespace swarmsim
