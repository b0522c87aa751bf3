// Summary statistics for sweep reports: mean, sample standard deviation and
// a 95% confidence interval of the mean (Student's t).
#pragma once

#include <cstdint>
#include <vector>

namespace swarmsim {

// The two-sided 95% critical value t(0.975, df) of Student's t distribution:
// exact to 9 digits for df 1..30 and the tabulated df up to 1000 (values
// computed with mpmath), interpolated linearly in 1/df between them, 1.959964
// (the normal) as df -> infinity. df must be >= 1.
double StudentT975(int64_t df);

struct Summary {
  int64_t n = 0;
  double mean = 0;
  double sd = 0;      // sample standard deviation (n - 1); NaN for n < 2
  double ci_low = 0;  // mean -/+ t(0.975, n-1) sd / sqrt(n); NaN for n < 2
  double ci_high = 0;
};

Summary Summarize(const std::vector<double>& values);

}  // namespace swarmsim
