#include "swarm/sweep/grid.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <set>

#include "framework/error.h"

namespace swarmsim {
namespace {

std::vector<std::string> Split(const std::string& text, char sep) {
  std::vector<std::string> parts;
  size_t start = 0;
  while (true) {
    const size_t at = text.find(sep, start);
    parts.push_back(text.substr(start, at - start));
    if (at == std::string::npos) break;
    start = at + 1;
  }
  return parts;
}

double ToDouble(const std::string& text, const std::string& context) {
  size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !std::isfinite(v))
    throw Error(context + ": '" + text + "' is not a number");
  return v;
}

int64_t ToCount(const std::string& text, const std::string& context) {
  const double v = ToDouble(text, context);
  if (v < 1 || v != std::floor(v) || v > 1e6)
    throw Error(context + ": the number of values '" + text +
                "' must be a whole number from 1 to 10^6");
  return static_cast<int64_t>(v);
}

// What a seed is, as `run --seed` takes it.
constexpr char kSeedRange[] = "(a whole number from 0 to 18446744073709551615)";

// One seed: decimal, 0..2^64-1.
uint64_t ToSeed(const std::string& text, const std::string& context) {
  uint64_t value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || !std::isdigit(static_cast<unsigned char>(text[0])) || ec != std::errc() ||
      end != text.data() + text.size())
    throw Error(context + ": '" + text + "' is not a seed " + kSeedRange);
  return value;
}

}  // namespace

std::string FormatNumber(double value) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.12g", value);
  return buf;
}

ParamSpec ParseParamSpec(const std::string& name_equals_spec) {
  const size_t eq = name_equals_spec.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == name_equals_spec.size())
    throw Error("--param expects NAME=SPEC (a list 1,2,4, a range A:B:N or log:A:B:N), got '" +
                name_equals_spec + "'");
  ParamSpec p;
  p.name = name_equals_spec.substr(0, eq);
  p.spec = name_equals_spec.substr(eq + 1);
  const std::string context = "--param " + name_equals_spec;
  const bool is_log = p.spec.rfind("log:", 0) == 0;
  if (is_log || p.spec.find(':') != std::string::npos) {
    const std::vector<std::string> f = Split(is_log ? p.spec.substr(4) : p.spec, ':');
    if (f.size() != 3)
      throw Error(context + ": a range is A:B:N or log:A:B:N (N values from A to B)");
    const double a = ToDouble(f[0], context), b = ToDouble(f[1], context);
    const int64_t n = ToCount(f[2], context);
    if (n == 1 && a != b) throw Error(context + ": one value from A to B needs A = B");
    p.kind = is_log ? "log" : "linear";
    if (is_log && (a <= 0 || b <= 0)) throw Error(context + ": a log range needs A > 0 and B > 0");
    for (int64_t i = 0; i < n; ++i) {
      const double t = n == 1 ? 0.0 : static_cast<double>(i) / static_cast<double>(n - 1);
      double v = is_log ? std::pow(10.0, std::log10(a) + t * (std::log10(b) - std::log10(a)))
                        : a + t * (b - a);
      if (i == n - 1) v = b;  // the end point exactly, whatever the rounding
      p.values.push_back(FormatNumber(v));
    }
  } else {
    p.kind = "list";
    for (const std::string& v : Split(p.spec, ',')) {
      if (v.empty()) throw Error(context + ": empty value in the list");
      p.values.push_back(v);
    }
  }
  // Twice the same value, also spelled two ways (1.0 and 1e0 are one number
  // to the world file: the same runs twice).
  std::map<std::string, std::string> seen;  // the value as a world reads it -> as given
  for (const std::string& v : p.values) {
    std::string key = v;
    char* end = nullptr;
    const double number = std::strtod(v.c_str(), &end);
    if (end != v.c_str() && *end == '\0' && std::isfinite(number)) key = FormatNumber(number);
    const auto [it, added] = seen.emplace(key, v);
    if (!added)
      throw Error(context + ": value '" + v + "' appears twice" +
                  (it->second == v ? "" : " (as '" + it->second + "')"));
  }
  return p;
}

std::vector<uint64_t> ParseSeeds(const std::string& spec) {
  const std::string context = "--seeds " + spec;
  if (spec.empty())
    throw Error("--seeds: expected K (seeds 1..K), a range A-B or a list A,B,C, got ''");
  std::vector<uint64_t> seeds;
  if (spec.find(',') != std::string::npos) {
    for (const std::string& s : Split(spec, ',')) {
      if (s.empty()) throw Error(context + ": empty seed in the list");
      seeds.push_back(ToSeed(s, context));
    }
  } else if (const size_t dash = spec.find('-'); dash != std::string::npos && dash > 0) {
    // (A leading '-' is a negative seed, not a range.)
    const std::string first = spec.substr(0, dash), last = spec.substr(dash + 1);
    if (last.empty()) throw Error(context + ": a seed range A-B needs both A and B");
    const uint64_t a = ToSeed(first, context);
    const uint64_t b = ToSeed(last, context);
    if (b < a)
      throw Error(context + ": a seed range A-B needs A <= B (got " + first + " > " + last + ")");
    if (b - a >= 1000000) throw Error(context + ": more than a million seeds");
    for (uint64_t s = a;; ++s) {  // (not s <= b: b may be 2^64 - 1)
      seeds.push_back(s);
      if (s == b) break;
    }
  } else if (spec.find_first_not_of("0123456789") == std::string::npos) {
    // A count K (out of range for any number of digits).
    uint64_t k = 0;
    const auto [end, ec] = std::from_chars(spec.data(), spec.data() + spec.size(), k);
    if (ec != std::errc() || k == 0 || k > 1000000)
      throw Error(context + ": the number of seeds K must be 1 to 10^6, got '" + spec +
                  "' (a range A-B or a list A,B,C takes any seeds)");
    for (uint64_t s = 1; s <= k; ++s) seeds.push_back(s);
  } else if (spec.front() == '-') {
    throw Error(context + ": '" + spec + "' is not a seed " + kSeedRange);
  } else {
    throw Error(context + ": expected K (seeds 1..K), a range A-B or a list A,B,C, got '" + spec +
                "'");
  }
  std::set<uint64_t> seen;
  for (uint64_t s : seeds)
    if (!seen.insert(s).second) throw Error(context + ": seed " + std::to_string(s) + " twice");
  return seeds;
}

std::vector<GridRun> ExpandGrid(const std::vector<ParamSpec>& params,
                                const std::vector<uint64_t>& seeds) {
  std::set<std::string> names;
  for (const ParamSpec& p : params)
    if (!names.insert(p.name).second) throw Error("--param " + p.name + " is given twice");
  // At most a million runs: a sweep's runs are listed whole (the database,
  // the grid's hash) before the first one starts.
  constexpr int64_t kMaxRuns = 1000000;
  int64_t points = 1;
  bool too_many = false;
  std::string shape;
  for (const ParamSpec& p : params) {
    const int64_t n = static_cast<int64_t>(p.values.size());
    shape += std::to_string(n) + " values of " + p.name + " x ";
    too_many = too_many || points > kMaxRuns / n;
    if (!too_many) points *= n;
  }
  if (too_many || points > kMaxRuns / static_cast<int64_t>(seeds.size()))
    throw Error("the sweep would have more than 10^6 runs (" + shape +
                std::to_string(seeds.size()) +
                " seeds): sweep fewer values, or split it into several sweeps");
  std::vector<GridRun> runs;
  runs.reserve(static_cast<size_t>(points) * seeds.size());
  for (int64_t point = 0; point < points; ++point) {
    // Mixed-radix digits of `point`, the last parameter fastest.
    std::vector<std::pair<std::string, std::string>> values(params.size());
    int64_t rest = point;
    for (size_t i = params.size(); i-- > 0;) {
      const int64_t n = static_cast<int64_t>(params[i].values.size());
      values[i] = {params[i].name, params[i].values[static_cast<size_t>(rest % n)]};
      rest /= n;
    }
    for (uint64_t seed : seeds) {
      GridRun r;
      r.id = static_cast<int64_t>(runs.size()) + 1;  // runs are numbered from 1, as SQLite's rows
      r.point = point;
      r.seed = seed;
      r.params = values;
      runs.push_back(std::move(r));
    }
  }
  return runs;
}

}  // namespace swarmsim
