// Values in world and model files: literal numbers, booleans and strings,
// parameter references ("$robots") and Lua expressions ("= sqrt(robots)"),
// checked against what each key expects.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "framework/math.h"
#include "framework/number_rule.h"
#include "framework/parameters.h"
#include "swarm/loader/yaml.h"

namespace swarmsim::loader {

// While the world's parameters are read, in file order: the one being read
// and those further down the file, which exist but cannot be used yet.
struct ParametersBeingRead {
  std::string_view current;
  std::map<std::string, std::string, std::less<>> later;  // name -> "line 12"
};

// The names a value may refer to: a model's parameters (if any) shadow the
// world's, as World::FindParameter does for scripts.
struct Scope {
  const ParameterSet* world = nullptr;
  const ParameterSet* model = nullptr;
  const ParametersBeingRead* reading = nullptr;  // only while reading them

  const ParamValue* Find(std::string_view name) const;
  std::vector<std::string> Names() const;
  // Why `name` (not found) cannot be used when it is being read or below
  // ("parameter 'b' is defined below this one (at line 12); ..."), else "".
  std::string NotYetDefined(std::string_view name) const;
  // The hint after "unknown ..." when there is no near miss: the parameters
  // there are, or " (there are no parameters)"; while the world's
  // parameters are read, the ones above.
  std::string ListHint() const;
};

// A small sandboxed Lua state for "= expression" values. Its globals are the
// scope's parameters and the math library (sqrt, floor, pi, ...; not random,
// which would break determinism). No other library: no I/O, no os, no load.
// It is a LimitedLua (framework/lua_evaluator.h): the script host's
// allocator and instruction-budget hook turn a runaway expression (over a
// million instructions or 64 MiB) into an error.
class Expressions {
 public:
  Expressions();
  ~Expressions();
  Expressions(const Expressions&) = delete;
  Expressions& operator=(const Expressions&) = delete;

  // The value of `expression`; throws swarmsim::Error with a message without
  // position (the caller adds file:line:column) on any failure.
  ParamValue Evaluate(std::string_view expression, const Scope& scope);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// NumberRule and the usual rules (kPositiveLength, ...): framework/number_rule.h.
using swarmsim::NumberRule;

// Reads typed values from fields of one file, in one scope.
class ValueReader {
 public:
  ValueReader(const YamlFile& file, Expressions* expressions, Scope scope)
      : file_(file), expressions_(expressions), scope_(scope) {}

  const YamlFile& file() const { return file_; }
  const Scope& scope() const { return scope_; }

  // The value of a scalar field: a literal (number if it reads as one,
  // true/false, else a string), "$name" or "= expression".
  ParamValue Resolve(const Field& field) const;

  double Number(const Field& field, const NumberRule& rule) const;
  // `range`, if given, says the range in messages instead of "from min to
  // max" (a bound checked after, with its own message).
  int64_t Integer(const Field& field, int64_t min, int64_t max, std::string_view range = {}) const;
  uint64_t Seed(const Field& field) const;
  bool Bool(const Field& field) const;
  std::string String(const Field& field) const;
  // One of `choices`, with a suggestion for a near miss.
  std::string Choice(const Field& field, const std::vector<std::string>& choices) const;
  // A list of `min_count`..`max_count` numbers.
  std::vector<double> Numbers(const Field& field, size_t min_count, size_t max_count,
                              const NumberRule& rule) const;
  Vec3 Vector3(const Field& field, const NumberRule& rule) const;

  [[noreturn]] void Fail(const Field& field, const std::string& message) const {
    file_.Fail(field.mark, message);
  }

 private:
  // "(got ...)" for a resolved value: the literal, or the value and where it came from.
  std::string Got(const Field& field, const ParamValue& value) const;

  const YamlFile& file_;
  Expressions* expressions_;
  Scope scope_;
};

// A literal scalar as a value: a number if the text reads as a finite
// number, true/false, else the text (used for --set values too).
ParamValue ParseScalar(std::string_view text, bool quoted);
// Shortest text that reads back as the same double ("0.1", not "0.10000000000000001").
std::string FormatNumber(double value);
// "a number", "a boolean", "a string".
const char* TypeName(const ParamValue& value);
// `text` (a --set or --param value) as a value of the parameter `declared`'s
// type: the text itself for a string parameter, else what it reads as if
// that is a number or boolean like `declared`; nothing when it is not.
std::optional<ParamValue> AsDeclaredType(const std::string& text, const ParamValue& declared);

// Object names are path elements (./leftMotor, /box): refuses at `field`
// an empty name or one with a space, '/', '[' or ']'.
void CheckObjectName(const ValueReader& values, const Field& field, const std::string& name);

}  // namespace swarmsim::loader
