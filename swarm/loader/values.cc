#include "swarm/loader/values.h"

#include <lauxlib.h>
#include <lua.h>
#include <lualib.h>

#include <cctype>
#include <charconv>
#include <cmath>
#include <set>

#include "framework/error.h"
#include "framework/lua_evaluator.h"

namespace swarmsim::loader {

namespace {

std::string FormatValue(const ParamValue& value) {
  if (const double* d = std::get_if<double>(&value)) return FormatNumber(*d);
  if (const bool* b = std::get_if<bool>(&value)) return *b ? "true" : "false";
  return "\"" + std::get<std::string>(value) + "\"";
}

std::optional<double> ParseNumber(std::string_view text) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  if (text.empty()) return std::nullopt;
  double value = 0;
  const auto result = std::from_chars(text.data(), text.data() + text.size(), value);
  if (result.ec != std::errc() || result.ptr != text.data() + text.size()) return std::nullopt;
  if (!std::isfinite(value)) return std::nullopt;  // "nan", "inf": never a usable quantity
  return value;
}

// Lua's "expression:1: " in front of a message: the caller gives the position.
std::string StripChunkPosition(std::string message) {
  const std::string_view prefix = "expression:";
  if (!message.starts_with(prefix)) return message;
  size_t i = prefix.size();
  while (i < message.size() && std::isdigit(static_cast<unsigned char>(message[i]))) ++i;
  if (i > prefix.size() && message.compare(i, 2, ": ") == 0) return message.substr(i + 2);
  return message;
}

std::string_view Trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

}  // namespace

std::string FormatNumber(double value) {
  char buf[32];
  // Whole numbers as digits (2000000, not the shorter 2e+06: a count a
  // user wrote reads back as written); the rest in the shortest form.
  const bool whole = value == std::floor(value) && std::abs(value) < 1e15;
  const auto result = whole ? std::to_chars(buf, buf + sizeof buf, value, std::chars_format::fixed)
                            : std::to_chars(buf, buf + sizeof buf, value);
  return std::string(buf, result.ptr);
}

// --- Scope ----------------------------------------------------------------------------

const ParamValue* Scope::Find(std::string_view name) const {
  if (model)
    if (auto it = model->find(name); it != model->end()) return &it->second;
  if (world)
    if (auto it = world->find(name); it != world->end()) return &it->second;
  return nullptr;
}

std::vector<std::string> Scope::Names() const {
  std::vector<std::string> out;
  if (model)
    for (const auto& [name, value] : *model) out.push_back(name);
  if (world)
    for (const auto& [name, value] : *world)
      if (!model || !model->contains(name)) out.push_back(name);
  return out;
}

std::string Scope::NotYetDefined(std::string_view name) const {
  constexpr std::string_view kRule = "a parameter can use only the parameters defined above it";
  if (!reading) return "";
  if (name == reading->current)
    return "parameter '" + std::string(name) + "' cannot use itself (" + std::string(kRule) + ")";
  const auto it = reading->later.find(name);
  if (it == reading->later.end()) return "";
  return "parameter '" + std::string(name) + "' is defined below this one (at " + it->second +
         "); " + std::string(kRule);
}

std::string Scope::ListHint() const {
  std::string params;
  for (const std::string& n : Names()) params += (params.empty() ? "" : ", ") + n;
  if (reading)
    return params.empty() ? " (no parameters are defined above this one)"
                          : " (parameters defined above this one: " + params + ")";
  return params.empty() ? " (there are no parameters)" : " (parameters: " + params + ")";
}

// --- Expressions ------------------------------------------------------------------------

struct Expressions::Impl {
  static constexpr size_t kMemoryLimit = 64 << 20;        // bytes
  static constexpr int64_t kInstructionBudget = 1000000;  // per expression

  LimitedLua lua{"the expression", kMemoryLimit, kInstructionBudget};
  int math_ref = LUA_NOREF;
  const Scope* scope = nullptr;  // during Evaluate

  static Impl* From(lua_State* L) {
    return static_cast<Impl*>(lua_touserdata(L, lua_upvalueindex(1)));
  }

  // __index of the expression's globals: a name that is neither a parameter
  // nor a math function is an error, with a suggestion.
  static int UnknownName(lua_State* L) {
    {
      std::string message;
      if (lua_type(L, 2) != LUA_TSTRING) {
        message = "unknown name";
      } else {
        const std::string key = lua_tostring(L, 2);
        const Scope& scope = *From(L)->scope;
        message = scope.NotYetDefined(key);
        if (message.empty()) {
          std::vector<std::string> names;
          lua_pushnil(L);
          while (lua_next(L, 1) != 0) {
            if (lua_type(L, -2) == LUA_TSTRING) names.push_back(lua_tostring(L, -2));
            lua_pop(L, 1);
          }
          std::string hint = Suggest(key, names);
          // No near miss: list the parameters only (not all of math).
          if (!hint.starts_with(";")) hint = scope.ListHint();
          message = "unknown name '" + key + "'" + hint;
        }
      }
      lua_pushstring(L, message.c_str());
    }
    return lua_error(L);
  }

  void PushValue(const ParamValue& value) {
    lua_State* L = lua.L();
    if (const double* d = std::get_if<double>(&value))
      lua_pushnumber(L, *d);
    else if (const bool* b = std::get_if<bool>(&value))
      lua_pushboolean(L, *b);
    else
      lua_pushstring(L, std::get<std::string>(value).c_str());
  }
};

Expressions::Expressions() : impl_(std::make_unique<Impl>()) {
  lua_State* L = impl_->lua.L();
  // The math library without its random generator (seeded from the clock).
  luaL_requiref(L, "math", luaopen_math, 0);
  lua_pushnil(L);
  lua_setfield(L, -2, "random");
  lua_pushnil(L);
  lua_setfield(L, -2, "randomseed");
  impl_->math_ref = luaL_ref(L, LUA_REGISTRYINDEX);
  lua_settop(L, 0);
}

Expressions::~Expressions() = default;

namespace {

// "; with robots = -5, density = 1": the parameters `expression` names, as
// they were (what a user checks first when it gives nan or inf).
std::string ValuesUsed(std::string_view expression, const Scope& scope) {
  std::string out;
  std::set<std::string> said;
  const auto is_name = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  };
  for (size_t i = 0; i < expression.size();) {
    if (!is_name(expression[i]) || std::isdigit(static_cast<unsigned char>(expression[i]))) {
      // Skip a number whole (1e5, 0x10) and any other character.
      const bool number = std::isdigit(static_cast<unsigned char>(expression[i])) != 0;
      ++i;
      while (number && i < expression.size() && is_name(expression[i])) ++i;
      continue;
    }
    size_t end = i;
    while (end < expression.size() && is_name(expression[end])) ++end;
    const std::string name(expression.substr(i, end - i));
    i = end;
    if (said.contains(name)) continue;
    if (const ParamValue* value = scope.Find(name)) {
      said.insert(name);
      out += (out.empty() ? "; with " : ", ") + name + " = " + FormatValue(*value);
    }
  }
  return out;
}

}  // namespace

ParamValue Expressions::Evaluate(std::string_view expression, const Scope& scope) {
  lua_State* L = impl_->lua.L();
  lua_settop(L, 0);
  impl_->scope = &scope;
  const std::string code = "return " + std::string(expression);
  // Text only: a binary chunk could crash the VM.
  if (luaL_loadbufferx(L, code.data(), code.size(), "=expression", "t") != LUA_OK) {
    std::string message = lua_tostring(L, -1) ? lua_tostring(L, -1) : "syntax error";
    lua_settop(L, 0);
    throw Error(StripChunkPosition(message));
  }
  // Globals: math functions, `math` itself, then the parameters (model over world).
  lua_newtable(L);
  lua_rawgeti(L, LUA_REGISTRYINDEX, impl_->math_ref);
  lua_pushnil(L);
  while (lua_next(L, -2) != 0) {
    lua_pushvalue(L, -2);
    lua_insert(L, -2);
    lua_rawset(L, -5);
  }
  lua_setfield(L, -2, "math");
  if (scope.world)
    for (const auto& [name, value] : *scope.world) {
      impl_->PushValue(value);
      lua_setfield(L, -2, name.c_str());
    }
  if (scope.model)
    for (const auto& [name, value] : *scope.model) {
      impl_->PushValue(value);
      lua_setfield(L, -2, name.c_str());
    }
  lua_newtable(L);
  lua_pushlightuserdata(L, impl_.get());
  lua_pushcclosure(L, &Impl::UnknownName, 1);
  lua_setfield(L, -2, "__index");
  lua_setmetatable(L, -2);
  lua_setupvalue(L, -2, 1);  // _ENV of the chunk
  ParamValue result;
  std::string error;
  if (!impl_->lua.Call(0, 1, &error)) {
    // ("attempt to perform arithmetic on a string value (global 'robots')":
    // what the parameters held says why.)
    error = StripChunkPosition(error) + ValuesUsed(expression, scope);
  } else {
    switch (lua_type(L, -1)) {
      case LUA_TNUMBER: {
        const double value = lua_tonumber(L, -1);
        if (!std::isfinite(value))
          error = "the expression gave " +
                  (std::isnan(value) ? std::string("nan (not a number: the square root or "
                                                   "logarithm of a negative number, or 0/0?)")
                                     : FormatNumber(value)) +
                  ValuesUsed(expression, scope);
        result = value;
        break;
      }
      case LUA_TBOOLEAN: result = lua_toboolean(L, -1) != 0; break;
      case LUA_TSTRING: result = std::string(lua_tostring(L, -1)); break;
      default:
        error = std::string("the expression gave ") + luaL_typename(L, -1) +
                ", not a number, boolean or string";
    }
  }
  lua_settop(L, 0);
  impl_->scope = nullptr;
  lua_gc(L, LUA_GCCOLLECT);
  if (!error.empty()) throw Error(error);
  return result;
}

// --- Literals -----------------------------------------------------------------------------

ParamValue ParseScalar(std::string_view text, bool quoted) {
  if (!quoted) {
    if (auto number = ParseNumber(text)) return *number;
    if (text == "true" || text == "True" || text == "TRUE") return true;
    if (text == "false" || text == "False" || text == "FALSE") return false;
  }
  return std::string(text);
}

const char* TypeName(const ParamValue& value) {
  // "finite": "nan" and "inf" never read as a parameter's number.
  if (std::holds_alternative<double>(value)) return "a finite number";
  if (std::holds_alternative<bool>(value)) return "a boolean";
  return "a string";
}

std::optional<ParamValue> AsDeclaredType(const std::string& text, const ParamValue& declared) {
  if (std::holds_alternative<std::string>(declared)) return ParamValue(text);
  ParamValue parsed = ParseScalar(text, false);
  if (parsed.index() == declared.index()) return parsed;
  return std::nullopt;
}

// --- ValueReader ----------------------------------------------------------------------

ParamValue ValueReader::Resolve(const Field& field) const {
  if (!field.present()) Fail(field, "'" + field.name + "' needs a value");
  if (!field.node.IsScalar())
    Fail(field, "'" + field.name + "' must be a single value (got " + Describe(field.node) + ")");
  const std::string& text = field.node.Scalar();
  const std::string_view trimmed = Trim(text);
  if (trimmed.starts_with("$")) {
    const std::string name(Trim(trimmed.substr(1)));
    if (const ParamValue* value = scope_.Find(name)) return *value;
    if (std::string later = scope_.NotYetDefined(name); !later.empty())
      Fail(field, "'" + field.name + "': " + later);
    const std::vector<std::string> names = scope_.Names();
    Fail(field, "unknown parameter '$" + name + "' in '" + field.name + "'" +
                    (names.empty() ? scope_.ListHint() : Suggest(name, names)));
  }
  if (trimmed.starts_with("=")) {
    const std::string expression(Trim(trimmed.substr(1)));
    if (expression.empty()) Fail(field, "'" + field.name + "': empty expression after '='");
    if (!expressions_) Fail(field, "'" + field.name + "' cannot be an expression");
    try {
      return expressions_->Evaluate(expression, scope_);
    } catch (const Error& e) {
      Fail(field, "in expression '" + expression + "' for '" + field.name + "': " + e.what());
    }
  }
  return ParseScalar(text, field.node.Tag() == "!");
}

std::string ValueReader::Got(const Field& field, const ParamValue& value) const {
  const std::string_view text = Trim(field.node.Scalar());
  if (field.node.IsScalar() && (text.starts_with("$") || text.starts_with("=")))
    return FormatValue(value) + " from " + Describe(field.node);
  return Describe(field.node);
}

double ValueReader::Number(const Field& field, const NumberRule& rule) const {
  if (!field.node.IsScalar() || !field.present())
    Fail(field,
         "'" + field.name + "' must be " + rule.text + " (got " + Describe(field.node) + ")");
  const ParamValue value = Resolve(field);
  std::optional<double> number;
  if (const double* d = std::get_if<double>(&value))
    number = *d;
  else if (const std::string* s = std::get_if<std::string>(&value))
    number = ParseNumber(Trim(*s));
  if (!number) {
    // A parameter's name written without its '$' (count: robots).
    const std::string_view text = Trim(field.node.Scalar());
    const bool bare_name = std::holds_alternative<std::string>(value) && !text.empty() &&
                           text[0] != '$' && text[0] != '=' && scope_.Find(text) != nullptr;
    Fail(field,
         "'" + field.name + "' must be " + rule.text + " (got " + Got(field, value) + ")" +
             (bare_name ? "; did you mean '$" + std::string(text) + "', the parameter?" : ""));
  }
  const bool below = rule.min_exclusive ? !(*number > rule.min) : !(*number >= rule.min);
  if (below)
    Fail(field, "'" + field.name + "' must be " + rule.text + " (got " + Got(field, *number) + ")");
  if (*number > rule.max)
    Fail(field, "'" + field.name + "' must be at most " + FormatNumber(rule.max) + " (got " +
                    Got(field, *number) + ")");
  return *number;
}

int64_t ValueReader::Integer(const Field& field, int64_t min, int64_t max,
                             std::string_view range) const {
  const std::string text =
      range.empty() ? "a whole number from " + std::to_string(min) + " to " + std::to_string(max)
                    : std::string(range);
  // No bound of its own: the range below is the message ("at most 1e+300" was).
  const NumberRule rule{text.c_str(), -INFINITY, INFINITY};
  const double value = Number(field, rule);
  if (value != std::floor(value) || value < static_cast<double>(min) ||
      value > static_cast<double>(max))
    Fail(field, "'" + field.name + "' must be " + text + " (got " + Got(field, value) + ")");
  return static_cast<int64_t>(value);
}

uint64_t ValueReader::Seed(const Field& field) const {
  // Literal digits are read exactly (all of uint64); other forms through doubles.
  if (field.node.IsScalar()) {
    const std::string_view text = Trim(field.node.Scalar());
    if (!text.empty() && text.find_first_not_of("0123456789") == std::string_view::npos) {
      uint64_t seed = 0;
      const auto result = std::from_chars(text.data(), text.data() + text.size(), seed);
      if (result.ec != std::errc() || result.ptr != text.data() + text.size())
        Fail(field, "'" + field.name +
                        "' must be a whole number from 0 to 18446744073709551615 (got " +
                        Describe(field.node) + ")");
      return seed;
    }
  }
  // Not digits alone ($seed, an expression, -1, 1.5): a double, exact up to 2^53.
  const char* const text =
      "a whole number from 0 to 18446744073709551615 (written out in digits; "
      "from a parameter or an expression, at most 9007199254740992)";
  const double value = Number(field, NumberRule{text, -1e300, 1e300});
  if (value != std::floor(value) || value < 0 || value > 9007199254740992.0)
    Fail(field, "'" + field.name + "' must be " + text + " (got " + Got(field, value) + ")");
  return static_cast<uint64_t>(value);
}

bool ValueReader::Bool(const Field& field) const {
  if (!field.node.IsScalar() || !field.present())
    Fail(field, "'" + field.name + "' must be true or false (got " + Describe(field.node) + ")");
  const ParamValue value = Resolve(field);
  if (const bool* b = std::get_if<bool>(&value)) return *b;
  Fail(field, "'" + field.name + "' must be true or false (got " + Got(field, value) + ")");
}

std::string ValueReader::String(const Field& field) const {
  if (!field.node.IsScalar() || !field.present())
    Fail(field, "'" + field.name + "' must be a name or text (got " + Describe(field.node) + ")");
  const ParamValue value = Resolve(field);
  if (const std::string* s = std::get_if<std::string>(&value)) return *s;
  const std::string_view text = Trim(field.node.Scalar());
  if (text.starts_with("$") || text.starts_with("=")) return ParamToString(value);
  return field.node.Scalar();  // a literal that looked like a number or boolean, as written
}

std::string ValueReader::Choice(const Field& field, const std::vector<std::string>& choices) const {
  std::string list;
  for (const std::string& c : choices) list += (list.empty() ? "" : ", ") + c;
  if (!field.node.IsScalar() || !field.present())
    Fail(field,
         "'" + field.name + "' must be one of " + list + " (got " + Describe(field.node) + ")");
  const std::string value = String(field);
  for (const std::string& c : choices)
    if (c == value) return value;
  const std::string hint = Suggest(value, choices);
  Fail(field, "'" + field.name + "' must be one of " + list + " (got " + Got(field, value) + ")" +
                  (hint.starts_with(";") ? hint : ""));
}

std::vector<double> ValueReader::Numbers(const Field& field, size_t min_count, size_t max_count,
                                         const NumberRule& rule) const {
  const std::string count = min_count == max_count
                                ? std::to_string(min_count)
                                : std::to_string(min_count) + " to " + std::to_string(max_count);
  if (!field.node.IsSequence() || field.node.size() < min_count || field.node.size() > max_count) {
    const std::string got = field.node.IsSequence()
                                ? "a list of " + std::to_string(field.node.size())
                                : Describe(field.node);
    Fail(field, "'" + field.name + "' must be a list of " + count + " numbers, e.g. [" +
                    (min_count == 2 ? "1, 2" : "1, 2, 3") + "] (got " + got + ")");
  }
  std::vector<double> out;
  size_t i = 0;
  for (const YAML::Node& element : field.node) {
    const YAML::Mark mark = element.Mark().is_null() ? field.mark : element.Mark();
    out.push_back(Number({field.name + "[" + std::to_string(i) + "]", element, mark, mark}, rule));
    ++i;
  }
  return out;
}

Vec3 ValueReader::Vector3(const Field& field, const NumberRule& rule) const {
  const std::vector<double> v = Numbers(field, 3, 3, rule);
  return {v[0], v[1], v[2]};
}

// Object names are path elements: no '/', no brackets.
void CheckObjectName(const ValueReader& values, const Field& field, const std::string& name) {
  if (name.empty() || name.find_first_of("/[]") != std::string::npos ||
      name.find_first_of(" \t\n") != std::string::npos)
    values.Fail(field, "object name '" + name +
                           "' must be non-empty, without spaces, '/', '[' or ']' (it is used in "
                           "paths such as ./leftMotor)");
}

}  // namespace swarmsim::loader
