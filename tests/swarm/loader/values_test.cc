// Values in world and model files (swarm/loader/values.cc): literals,
// "$parameter" references and "= expression"s, each checked against what
// its key expects, with messages naming the key, the place and the value.
#include "swarm/loader/values.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "tests/swarm/loader/yaml_file.h"

namespace swarmsim::loader {
namespace {

namespace fs = std::filesystem;
using testing::ErrorOf;
using testing::Root;
using testing::Yaml;
using testing::YamlDir;

TEST(ValuesTest, LiteralsAreNumbersBooleansOrText) {
  EXPECT_EQ(ParseScalar("1.5", false), ParamValue(1.5));
  EXPECT_EQ(ParseScalar("+2", false), ParamValue(2.0));
  EXPECT_EQ(ParseScalar("-1e3", false), ParamValue(-1000.0));
  for (const char* t : {"true", "True", "TRUE"}) EXPECT_EQ(ParseScalar(t, false), ParamValue(true));
  for (const char* t : {"false", "False", "FALSE"})
    EXPECT_EQ(ParseScalar(t, false), ParamValue(false));
  // Never a quantity: nan and inf; and YAML 1.1's yes/no are text.
  for (const char* t : {"nan", "inf", "-inf", "yes", "no", "1 m", "0x10", ""})
    EXPECT_EQ(ParseScalar(t, false), ParamValue(std::string(t))) << t;
  // Quoted ("!" tag): text, whatever it looks like.
  EXPECT_EQ(ParseScalar("1.5", true), ParamValue(std::string("1.5")));
  EXPECT_EQ(ParseScalar("true", true), ParamValue(std::string("true")));
  EXPECT_STREQ(TypeName(ParamValue(1.0)), "a finite number");
  EXPECT_STREQ(TypeName(ParamValue(true)), "a boolean");
  EXPECT_STREQ(TypeName(ParamValue(std::string("x"))), "a string");
}

TEST(ValuesTest, NumbersAreWrittenShortestAndReadBackTheSame) {
  EXPECT_EQ(FormatNumber(0.1), "0.1");
  EXPECT_EQ(FormatNumber(3), "3");
  EXPECT_EQ(FormatNumber(-2.5), "-2.5");
  EXPECT_EQ(FormatNumber(1e21), "1e+21");
  EXPECT_EQ(FormatNumber(2e6), "2000000") << "a count reads back as written";
  EXPECT_EQ(FormatNumber(-100000), "-100000");
  EXPECT_EQ(FormatNumber(2.5e6), "2500000");
  EXPECT_EQ(FormatNumber(1e-7), "1e-07");
  for (const double v : {0.1 + 0.2, 1.0 / 3, 6.02214076e23, -1e-300})
    EXPECT_EQ(std::stod(FormatNumber(v)), v) << FormatNumber(v);
}

// A world of `yaml` (a mapping) read in a scope of world parameters
// {robots: 4, name: bot, on: true} and model parameters {speed: 0.5, robots: 2}.
struct Read {
  explicit Read(const std::string& yaml) : file(Yaml(yaml)), fields(file, Root(file), "test") {}
  ~Read() { fs::remove_all(YamlDir()); }
  ParameterSet world{{"robots", 4.0}, {"name", std::string("bot")}, {"on", true}};
  ParameterSet model{{"speed", 0.5}, {"robots", 2.0}};
  Expressions expressions;
  YamlFile file;
  Fields fields;
  ValueReader values{file, &expressions, Scope{&world, &model, nullptr}};
  ValueReader world_only{file, &expressions, Scope{&world, nullptr, nullptr}};
  Field operator[](const char* key) const { return fields.Get(key); }
  std::string Where(const char* key) const { return file.Where(fields.Get(key).mark); }
};

TEST(ValuesTest, ParametersAreReferencedAndTheModelsShadowTheWorlds) {
  const Read r("a: $robots\nb: $ name \nc: $speed\nd: $robts\ne: $nothing\n");
  EXPECT_EQ(r.values.Resolve(r["a"]), ParamValue(2.0));
  EXPECT_EQ(r.world_only.Resolve(r["a"]), ParamValue(4.0));
  EXPECT_EQ(r.values.Resolve(r["b"]), ParamValue(std::string("bot")));
  EXPECT_EQ(r.values.Resolve(r["c"]), ParamValue(0.5));
  EXPECT_EQ(ErrorOf([&] { r.values.Resolve(r["d"]); }),
            r.Where("d") + ": unknown parameter '$robts' in 'd'; did you mean 'robots'?");
  const ParameterSet none;
  const ValueReader bare(r.file, nullptr, Scope{&none, nullptr, nullptr});
  EXPECT_EQ(ErrorOf([&] { bare.Resolve(r["e"]); }),
            r.Where("e") + ": unknown parameter '$nothing' in 'e' (there are no parameters)");
}

TEST(ValuesTest, ExpressionsSeeTheParametersAndMathAndNothingElse) {
  const Read r(
      "a: = sqrt(robots * 8)\nb: = math.floor(speed * 3) + pi * 0\nc: = name .. '#1'\n"
      "d: = robots > 3\ne: = require('os')\nf: = math.random()\ng: = 1 / 0\nh: = {}\n"
      "i: = (function() while true do end end)()\nj: =\nk: = rbots + 1\nl: = 1 +\n"
      "m: = sqrt(-robots / speed) + robots\n");
  EXPECT_EQ(r.values.Resolve(r["a"]), ParamValue(4.0));  // robots is the model's 2
  EXPECT_EQ(r.values.Resolve(r["b"]), ParamValue(1.0));
  EXPECT_EQ(r.values.Resolve(r["c"]), ParamValue(std::string("bot#1")));
  EXPECT_EQ(r.values.Resolve(r["d"]), ParamValue(false));
  const auto error = [&](const char* key) { return ErrorOf([&] { r.values.Resolve(r[key]); }); };
  const auto in = [&](const char* key, const std::string& expression) {
    return r.Where(key) + ": in expression '" + expression + "' for '" + key + "': ";
  };
  EXPECT_EQ(error("e").rfind(in("e", "require('os')") + "unknown name 'require' (parameters: ", 0),
            0u)
      << error("e");
  EXPECT_EQ(error("f").rfind(in("f", "math.random()"), 0), 0u) << error("f");
  EXPECT_NE(error("f").find("random"), std::string::npos) << "no random numbers: " << error("f");
  EXPECT_EQ(error("g"), in("g", "1 / 0") + "the expression gave inf");
  // NaN (was "-nan"): what it is, and the parameters it used as they were.
  EXPECT_EQ(error("m"), in("m", "sqrt(-robots / speed) + robots") +
                            "the expression gave nan (not a number: the square root or logarithm "
                            "of a negative number, or 0/0?); with robots = 2, speed = 0.5");
  EXPECT_EQ(error("h"),
            in("h", "{}") + "the expression gave table, not a number, boolean or string");
  EXPECT_EQ(error("i").rfind(in("i", "(function() while true do end end)()"), 0), 0u) << error("i");
  EXPECT_EQ(error("j"), r.Where("j") + ": 'j': empty expression after '='");
  EXPECT_EQ(error("k"), in("k", "rbots + 1") + "unknown name 'rbots'; did you mean 'robots'?");
  EXPECT_EQ(error("l").rfind(in("l", "1 +"), 0), 0u) << error("l");
  EXPECT_EQ(error("l").find("expression:1:"), std::string::npos) << "the place is the file's";
  // Where no expression may be.
  const ValueReader plain(r.file, nullptr, Scope{&r.world, nullptr, nullptr});
  EXPECT_EQ(ErrorOf([&] { plain.Resolve(r["a"]); }),
            r.Where("a") + ": 'a' cannot be an expression");
}

TEST(ValuesTest, ParametersBeingReadCanUseOnlyThoseAboveThem) {
  const ParameterSet above{{"a", 1.0}};
  ParametersBeingRead reading;
  reading.current = "b";
  reading.later = {{"c", "line 12"}};
  const Scope scope{&above, nullptr, &reading};
  EXPECT_EQ(scope.NotYetDefined("c"),
            "parameter 'c' is defined below this one (at line 12); a parameter can use only the "
            "parameters defined above it");
  EXPECT_EQ(scope.NotYetDefined("b"),
            "parameter 'b' cannot use itself (a parameter can use only the parameters defined "
            "above it)");
  EXPECT_EQ(scope.NotYetDefined("zzz"), "");
  EXPECT_EQ(scope.ListHint(), " (parameters defined above this one: a)");
  const ParameterSet none;
  EXPECT_EQ((Scope{&none, nullptr, &reading}).ListHint(),
            " (no parameters are defined above this one)");
  EXPECT_EQ((Scope{&above, nullptr, nullptr}).NotYetDefined("c"), "") << "not while reading";
  Read r("b: = c * 2\n");
  const ValueReader values(r.file, &r.expressions, scope);
  EXPECT_EQ(ErrorOf([&] { values.Resolve(r["b"]); }),
            r.Where("b") +
                ": in expression 'c * 2' for 'b': parameter 'c' is defined below this "
                "one (at line 12); a parameter can use only the parameters defined "
                "above it");
}

TEST(ValuesTest, EachKindOfValueSaysWhatItExpects) {
  const Read r(
      "zero: 0\nbig: 2e3\nname: $name\nhalf: 2.5\nseed: 18446744073709551615\n"
      "seed_over: 18446744073709551616\none: 1\nshape: spher\nlist: [1, 2]\n"
      "bad_element: [1, x, 3]\ncode: 007\nlitbool: TRUE\nmapping: {a: 1}\nempty:\n");
  const NumberRule positive{"a positive number", 0, 1000, true};
  const auto error = [&](const std::function<void()>& f) { return ErrorOf(f); };
  EXPECT_EQ(error([&] { r.values.Number(r["zero"], positive); }),
            r.Where("zero") + ": 'zero' must be a positive number (got \"0\")");
  EXPECT_EQ(error([&] { r.values.Number(r["big"], positive); }),
            r.Where("big") + ": 'big' must be at most 1000 (got \"2e3\")");
  EXPECT_EQ(error([&] { r.values.Number(r["name"], positive); }),
            r.Where("name") + ": 'name' must be a positive number (got \"bot\" from \"$name\")");
  EXPECT_EQ(error([&] { r.values.Number(r["mapping"], positive); }),
            r.Where("mapping") + ": 'mapping' must be a positive number (got a mapping)");
  EXPECT_EQ(error([&] { r.values.Number(r["empty"], positive); }),
            r.Where("empty") + ": 'empty' must be a positive number (got nothing)");
  EXPECT_EQ(r.values.Integer(r["one"], 1, 10), 1);
  EXPECT_EQ(error([&] { r.values.Integer(r["half"], 1, 10); }),
            r.Where("half") + ": 'half' must be a whole number from 1 to 10 (got \"2.5\")");
  // Seeds: every 64-bit value exactly.
  EXPECT_EQ(r.values.Seed(r["seed"]), 18446744073709551615u);
  EXPECT_EQ(error([&] { r.values.Seed(r["seed_over"]); }),
            r.Where("seed_over") +
                ": 'seed_over' must be a whole number from 0 to 18446744073709551615 (got "
                "\"18446744073709551616\")");
  // Not digits alone: the same range, and why an expression's stops at 2^53.
  EXPECT_EQ(error([&] { r.values.Seed(r["half"]); }),
            r.Where("half") +
                ": 'half' must be a whole number from 0 to 18446744073709551615 (written out "
                "in digits; from a parameter or an expression, at most 9007199254740992) (got "
                "\"2.5\")");
  EXPECT_EQ(r.values.Seed(r["big"]), 2000u);
  EXPECT_TRUE(r.values.Bool(r["litbool"]));
  EXPECT_EQ(error([&] { r.values.Bool(r["one"]); }),
            r.Where("one") + ": 'one' must be true or false (got \"1\")");
  // Text as written, even when it reads as a number.
  EXPECT_EQ(r.values.String(r["code"]), "007");
  EXPECT_EQ(r.values.String(r["name"]), "bot");
  EXPECT_EQ(error([&] {
              r.values.Choice(r["shape"], {"sphere", "box"});
            }),
            r.Where("shape") +
                ": 'shape' must be one of sphere, box (got \"spher\"); did you mean 'sphere'?");
  EXPECT_EQ(r.values.Numbers(r["list"], 2, 3, kAnyNumber), (std::vector<double>{1, 2}));
  EXPECT_EQ(error([&] { r.values.Vector3(r["list"], kAnyNumber); }),
            r.Where("list") +
                ": 'list' must be a list of 3 numbers, e.g. [1, 2, 3] (got a list "
                "of 2)");
  const std::string element = error([&] { r.values.Vector3(r["bad_element"], kAnyNumber); });
  EXPECT_EQ(element, r.file.name() + ":10:18: 'bad_element[1]' must be a number (got \"x\")");
}

}  // namespace
}  // namespace swarmsim::loader
