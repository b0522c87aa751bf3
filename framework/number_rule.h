// Bounds for a number read from a world or model file, with the words the
// error message uses ("must be a positive number").
#pragma once

#include "framework/math.h"

namespace swarmsim {

struct NumberRule {
  const char* text;  // what is expected, for messages: "a positive number"
  double min;
  double max;
  bool min_exclusive = false;
};
// Largest length or coordinate accepted, m (framework/math.h).
inline constexpr double kMaxLength = kMaxCoordinate;
inline constexpr NumberRule kAnyNumber{"a number", -1e300, 1e300};
inline constexpr NumberRule kCoordinate{"a number of metres", -kMaxLength, kMaxLength};
inline constexpr NumberRule kPositiveLength{"a positive number", 0, kMaxLength, true};
inline constexpr NumberRule kNonNegativeLength{"a non-negative number", 0, kMaxLength};
inline constexpr NumberRule kPositive{"a positive number", 0, 1e300, true};
inline constexpr NumberRule kNonNegative{"a non-negative number", 0, 1e300};
inline constexpr NumberRule kFraction{"a number from 0 to 1", 0, 1};
inline constexpr NumberRule kAngleDeg{"an angle in degrees", -1e6, 1e6};
// A body's mass, kg: past 1e9 (a large ship) the solvers' arithmetic breaks
// (1e308 was an ODE assertion at the first step, naming no link).
inline constexpr double kMaxMass = 1e9;
inline constexpr NumberRule kMass{"a positive number of kg", 0, kMaxMass, true};

}  // namespace swarmsim
