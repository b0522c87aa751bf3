// "Did you mean ...?" for names a user typed: the world loader's unknown
// keys and the script host's misspelt sysCall_* callbacks share one rule.
#pragma once

#include <span>
#include <string>
#include <string_view>

namespace swarmsim {

// Damerau-Levenshtein distance (optimal string alignment: insertions,
// deletions, substitutions and swaps of adjacent characters cost 1).
int EditDistance(std::string_view a, std::string_view b);

// The candidate nearest to `name` if it is close enough to be a typo (up to
// 2 edits, or a third of the longer name, and not a different word
// altogether), else the first candidate that is a whole '_'-separated word of
// `name` or has `name` as one ('noise' for 'noise_std', 'max_range' for
// 'range'), else null. The first of equally near candidates wins.
const std::string* NearestName(std::string_view name, std::span<const std::string> candidates);

// "; did you mean 'radius'?" for the nearest candidate if it is close enough,
// else " (expected one of: a, b, c)" (as many as fit in 400 characters, then
// "... (N more)"), or
// "" when there are no candidates.
std::string Suggest(std::string_view name, std::span<const std::string> candidates);

}  // namespace swarmsim
