#include "swarm/sweep/stats.h"

#include <cmath>
#include <iterator>
#include <limits>

#include "framework/error.h"

namespace swarmsim {
namespace {

struct TableRow {
  int64_t df;
  double t;
};

// t(0.975, df), computed with mpmath (betainc + findroot, 30 digits).
constexpr TableRow kT975[] = {
    {1, 12.7062047362},    {2, 4.30265272975},   {3, 3.18244630528},   {4, 2.7764451052},
    {5, 2.57058183564},    {6, 2.44691185114},   {7, 2.36462425159},   {8, 2.3060041352},
    {9, 2.2621571628},     {10, 2.22813885199},  {11, 2.20098516009},  {12, 2.17881282967},
    {13, 2.16036865646},   {14, 2.14478668792},  {15, 2.13144954556},  {16, 2.11990529922},
    {17, 2.10981557783},   {18, 2.10092204024},  {19, 2.09302405441},  {20, 2.08596344727},
    {21, 2.07961384473},   {22, 2.0738730679},   {23, 2.06865761042},  {24, 2.06389856163},
    {25, 2.05953855275},   {26, 2.05552943864},  {27, 2.05183051648},  {28, 2.0484071418},
    {29, 2.04522964213},   {30, 2.0422724563},   {35, 2.03010792825},  {40, 2.02107539031},
    {45, 2.01410338888},   {50, 2.0085591121},   {60, 2.00029782201},  {70, 1.99443711177},
    {80, 1.99006342125},   {90, 1.9866745407},   {100, 1.98397151852}, {120, 1.97993040508},
    {150, 1.9759053309},   {200, 1.97189622363}, {300, 1.96790301126}, {500, 1.96471983747},
    {1000, 1.96233908083},
};
constexpr double kNormal975 = 1.95996398454;

}  // namespace

double StudentT975(int64_t df) {
  SWARMSIM_CHECK(df >= 1, "StudentT975 needs df >= 1");
  const TableRow* prev = nullptr;
  for (const TableRow& row : kT975) {
    if (row.df == df) return row.t;
    if (row.df > df) {
      // Between prev and row: linear in 1/df (t is nearly linear in 1/df).
      const double u = 1.0 / static_cast<double>(df), u0 = 1.0 / static_cast<double>(prev->df),
                   u1 = 1.0 / static_cast<double>(row.df);
      return prev->t + (row.t - prev->t) * (u - u0) / (u1 - u0);
    }
    prev = &row;
  }
  const TableRow& last = kT975[std::size(kT975) - 1];
  const double u = 1.0 / static_cast<double>(df), u0 = 1.0 / static_cast<double>(last.df);
  return kNormal975 + (last.t - kNormal975) * u / u0;
}

Summary Summarize(const std::vector<double>& values) {
  Summary s;
  s.n = static_cast<int64_t>(values.size());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (s.n == 0) {
    s.mean = s.sd = s.ci_low = s.ci_high = nan;
    return s;
  }
  double sum = 0;
  for (double v : values) sum += v;
  s.mean = sum / static_cast<double>(s.n);
  if (s.n < 2) {
    s.sd = s.ci_low = s.ci_high = nan;
    return s;
  }
  double ss = 0;
  for (double v : values) ss += (v - s.mean) * (v - s.mean);
  s.sd = std::sqrt(ss / static_cast<double>(s.n - 1));
  const double half = StudentT975(s.n - 1) * s.sd / std::sqrt(static_cast<double>(s.n));
  s.ci_low = s.mean - half;
  s.ci_high = s.mean + half;
  return s;
}

}  // namespace swarmsim
