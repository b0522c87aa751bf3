// A test's view of printed text: its lines, without their line breaks (the
// progress lines of a run or a sweep, the rows of an output file).
#pragma once

#include <sstream>
#include <string>
#include <vector>

namespace swarmsim::testing {

inline std::vector<std::string> TextLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

}  // namespace swarmsim::testing
