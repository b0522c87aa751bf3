// The script sandbox: each escape is refused with a message naming the
// robot, script file and line; files only under the world's folder (read)
// and the output folder (write); require from the world's folders;
// trust_scripts lifts it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/world.h"
#include "tests/framework/fakes.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) << (haystack)
#define ASSERT_CONTAINS(haystack, needle) \
  ASSERT_NE(std::string(haystack).find(needle), std::string::npos) << (haystack)

// A temporary world folder with world/, world/scripts/ and out/.
class SandboxTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() /
            ("swarmsim_sandbox_" + std::to_string(::getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_ / "world" / "scripts");
    fs::create_directories(root_ / "out");
    Write(root_ / "world" / "data.txt", "hello\n");
    Write(root_ / "secret.txt", "secret\n");
  }
  void TearDown() override { fs::remove_all(root_); }
  static void Write(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

  // Runs `code` as one robot's script for one step; returns the error ("" if none).
  std::string Run(const std::string& code, bool with_out = true, bool trust = false) {
    WorldSettings settings;
    settings.physics = "null";
    settings.directory = root_ / "world";
    if (with_out) settings.output_directory = root_ / "out";
    settings.trust_scripts = trust;
    registry_ = testing::NullRegistry();
    World world(settings, registry_);
    log_.clear();
    world.set_log_sink([this](std::string_view line) { log_.emplace_back(line); });
    const ObjectId root = world.scene().AddDummy("bot#0", {}, {});
    world.scene().MakeModelInstance(root, "bot", "bot#0");
    world.scene().AttachScript(
        root, std::make_shared<const ScriptSource>(ScriptSource{"scripts/robot.lua", code}));
    try {
      world.Start();
      world.Step();
      world.Stop();
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  }
  std::string Log() const {
    std::string out;
    for (const std::string& line : log_) out += line + "\n";
    return out;
  }

  fs::path root_;
  ModuleRegistry registry_;
  std::vector<std::string> log_;
};

TEST_F(SandboxTest, ForbiddenFunctionsAreRefusedWithScriptAndLine) {
  const std::vector<std::pair<std::string, std::string>> escapes = {
      {"os.execute('true')", "os.execute is not allowed"},
      {"io.popen('ls')", "io.popen is not allowed"},
      {"package.loadlib('libc.so.6', 'system')", "package.loadlib is not allowed"},
      {"debug.getinfo(1)", "debug.getinfo is not allowed"},
      {"dofile('/etc/passwd')", "dofile is not allowed"},
      {"loadfile('/etc/passwd')", "loadfile is not allowed"},
      {"os.getenv('HOME')", "os.getenv is not allowed"},
      {"io.lines()", "io.lines() on standard input is not allowed"},
      {"load('\\27LuaT\\0')", "binary chunks are not allowed"},
      {"string.dump(print)", "string.dump is not allowed"},
      {"('x').dump(print)", "string.dump is not allowed"},
  };
  for (const auto& [call, message] : escapes) {
    const std::string error = Run("\nfunction sysCall_init()\n  " + call + "\nend\n");
    EXPECT_CONTAINS(error, message);
    EXPECT_CONTAINS(error, "bot#0: scripts/robot.lua:3:");
    EXPECT_CONTAINS(error, "--trust-scripts");
  }
  // Harmless os functions stay; other missing string fields are nil as usual.
  EXPECT_EQ(Run("assert(os.clock() >= 0); assert(string.nothere == nil and ('x').nothere == nil)"),
            "");
}

TEST_F(SandboxTest, ReadsOnlyUnderTheWorldFolder) {
  EXPECT_EQ(Run("local f = assert(io.open('data.txt')); assert(f:read('l') == 'hello'); f:close()"
                "\nfor l in io.lines('data.txt') do assert(l == 'hello') end"),
            "");
  EXPECT_CONTAINS(Run("io.open('../secret.txt')"), "'..' is not allowed in a path");
  EXPECT_CONTAINS(Run("io.open('" + (root_ / "secret.txt").string() + "')"),
                  "is outside the world's folder");
  EXPECT_CONTAINS(Run("io.open('/etc/passwd')"), "is outside the world's folder");
  // A symlink inside the folder that leads out.
  fs::create_symlink(root_ / "secret.txt", root_ / "world" / "link.txt");
  EXPECT_CONTAINS(Run("io.open('link.txt')"), "is outside the world's folder");
  // Reading from the output folder is not allowed either; a missing file is nil, message.
  EXPECT_EQ(Run("local f, e = io.open('missing.txt'); assert(f == nil and e:find('missing'))"), "");
}

TEST_F(SandboxTest, WritesOnlyUnderTheOutputFolder) {
  EXPECT_EQ(Run("local f = assert(io.open('log.txt', 'w')); f:write('x=1'); f:close()"), "");
  std::ifstream in(root_ / "out" / "log.txt");
  std::string text;
  std::getline(in, text);
  EXPECT_EQ(text, "x=1");
  EXPECT_CONTAINS(Run("io.open('" + (root_ / "world" / "data.txt").string() + "', 'a')"),
                  "is outside the run's output folder");
  EXPECT_CONTAINS(Run("io.open('../world/data.txt', 'w')"), "'..' is not allowed");
  EXPECT_CONTAINS(Run("io.open('log.txt', 'w')", /*with_out=*/false),
                  "the run has no output folder (swarmsim run --out DIR)");
  fs::create_symlink(root_ / "world", root_ / "out" / "sneaky");
  EXPECT_CONTAINS(Run("io.open('sneaky/data.txt', 'w')"), "is outside the run's output folder");
  // A symlink to a file not there yet, outside: opening it would create it
  // there (QA). Refused, and nothing is created.
  fs::create_symlink("../outside.txt", root_ / "out" / "notes.txt");
  EXPECT_CONTAINS(Run("io.open('notes.txt', 'w')"),
                  "'notes.txt' is a symlink to a file that does not exist (../outside.txt)");
  EXPECT_FALSE(fs::exists(root_ / "outside.txt"));
}

// The room kept aside for the final summary on a full disk is the run's own:
// a script that emptied it would lose summary.json when the disk fills.
TEST_F(SandboxTest, TheDiskReserveIsOneOfTheRunsOwnOutputs) {
  const std::string kept(4096, 'r');
  Write(root_ / "out" / ".swarmsim-reserve", kept);
  for (const char* mode : {"w", "a", "r+", "w+"}) {
    const std::string error =
        Run(std::string("local f = io.open('.swarmsim-reserve', '") + mode + "'); f:close()");
    EXPECT_CONTAINS(error, "'.swarmsim-reserve' is one of the run's own outputs");
    EXPECT_CONTAINS(error, "bot#0: scripts/robot.lua:1:");
  }
  EXPECT_CONTAINS(Run("io.open('./.swarmsim-reserve', 'w')"), "one of the run's own outputs");
  EXPECT_EQ(fs::file_size(root_ / "out" / ".swarmsim-reserve"), kept.size());
}

// A module with a UTF-8 byte-order mark or a `#!` first line loads as the
// `lua` program loads it, its lines numbered as in the file.
TEST_F(SandboxTest, RequireSkipsAByteOrderMarkAndAShebangLine) {
  Write(root_ / "world" / "marked.lua", "\xEF\xBB\xBFreturn {v = 5}\n");
  Write(root_ / "world" / "both.lua",
        "\xEF\xBB\xBF#!/usr/bin/env lua\nlocal x = 1\nerror('third')\n");
  EXPECT_EQ(Run("assert(require('marked').v == 5)"), "");
  EXPECT_CONTAINS(Run("require('both')"), "both.lua:3: third");
}

TEST_F(SandboxTest, RequireLoadsModulesFromTheWorldFoldersOncePerState) {
  Write(root_ / "world" / "scripts" / "util.lua",
        "count = (count or 0) + 1\nprint('loading util')\n"
        "return {twice = function(x) return 2 * x end}\n");
  Write(root_ / "world" / "helpers.lua", "local u = require('util') return {four = u.twice(2)}\n");
  EXPECT_EQ(Run("local u = require('util'); local h = require('helpers')\n"
                "assert(u == require('util')); assert(h.four == 4); assert(count == nil)"),
            "");
  EXPECT_EQ(Log(), "[bot#0] loading util\n");
  EXPECT_CONTAINS(Run("\nrequire('nothere')"),
                  "scripts/robot.lua:2: require: module 'nothere' "
                  "not found; looked for:");
  EXPECT_CONTAINS(Run("require('../secret')"), "is not a module name");
  Write(root_ / "world" / "bad.lua", "os.execute('true')\n");
  EXPECT_CONTAINS(Run("require('bad')"), "bad.lua:1: os.execute is not allowed");
  fs::create_symlink(root_ / "secret.txt", root_ / "world" / "leak.lua");
  EXPECT_CONTAINS(Run("require('leak')"), "module 'leak' not found");
  EXPECT_CONTAINS(Run("require('leak')"), "leak.lua (a symbolic link to " +
                                              fs::weakly_canonical(root_ / "secret.txt").string() +
                                              ", outside the folder: refused)");
}

// Lua errors are longjmps (the C build of Lua): errors raised by Lua code
// that a sim/sandbox function calls, and errors of those functions caught by
// pcall, keep their messages, and the script goes on (the sanitizer build
// checks that nothing a C++ function held is leaked on the way).
TEST_F(SandboxTest, ErrorsThroughCFunctionsKeepTheirMessagesAndCanBeCaught) {
  EXPECT_CONTAINS(Run("print(setmetatable({}, {__tostring = function() error('no text') end}))"),
                  "scripts/robot.lua:1: no text");
  EXPECT_CONTAINS(Run("io.open('data.txt', 'rz')"), "invalid mode");
  EXPECT_CONTAINS(Run("for l in io.lines('missing.txt') do end"), "missing.txt");
  Write(root_ / "world" / "broken.lua", "local x = 1\nerror('module failed')\n");
  EXPECT_CONTAINS(Run("require('broken')"), "broken.lua:2: module failed");
  EXPECT_EQ(Run("for i = 1, 2000 do\n"
                "  local ok, e = pcall(sim.getObject, './nope' .. i)\n"
                "  assert(not ok and e:find('no object at path'), e)\n"
                "  ok, e = pcall(require, 'nothere')\n"
                "  assert(not ok and e:find('not found'), e)\n"
                "  ok, e = pcall(sim.setSignal, 'x', {})\n"
                "  assert(not ok and e:find('a signal is a number'), e)\n"
                "end\n"
                "print('still running')"),
            "");
  EXPECT_EQ(Log(), "[bot#0] still running\n");
}

// coroutine and utf8 are opened on first use (less memory per robot), in
// every script of the state, like the other libraries.
TEST_F(SandboxTest, CoroutineAndUtf8AreThereOnFirstUse) {
  EXPECT_EQ(Run("local gen = coroutine.wrap(function() coroutine.yield(1) coroutine.yield(2) end)\n"
                "assert(gen() == 1 and gen() == 2)\n"
                "assert(utf8.char(72, 228) == 'H\\u{E4}' and utf8.len('H\\u{E4}') == 2)\n"
                "assert(coroutine == _G.coroutine and type(coroutine.isyieldable) == 'function')\n"
                "print(coroutine.running() ~= nil)"),
            "");
  EXPECT_EQ(Log(), "[bot#0] true\n");
}

// math, string and table fetch each entry on first use (a robot's state
// then holds the few its script uses): every function is there, string
// methods work, math.random keeps its generator, and string.dump and the
// deprecated math functions are not.
TEST_F(SandboxTest, LibraryEntriesAreThereOnFirstUse) {
  EXPECT_EQ(
      Run("local used = 0\n"
          "for _ in pairs(math) do used = used + 1 end\n"
          "assert(used == 2, used)  -- random and randomseed, which share a generator\n"
          "assert(math.sqrt(16) == 4 and math.pi > 3.14 and math.maxinteger == (1 << 63) - 1)\n"
          "assert(math.type(1) == 'integer' and math.huge > 1e308)\n"
          "assert(rawget(math, 'sqrt') == math.sqrt and rawget(math, 'floor') == nil)\n"
          "assert(math.pow == nil and math.cosh == nil and math.log10 == nil)\n"
          "assert(('abc'):upper() == 'ABC' and string.format('%03d', 7) == '007')\n"
          "-- numeric strings' arithmetic (the strings' metatable of luaopen_string)\n"
          "assert('10' + 1 == 11 and '3' * '4' == 12 and -'2' == -2 and '7' // 2 == 3)\n"
          "assert('2' ^ 3 == 8 and '7' % 4 == 3 and '1' - 1 == 0 and '9' / '3' == 3)\n"
          "assert(not pcall(function() return 'x' + 1 end))\n"
          "assert(('a,b'):find(',') == 2 and string.rep('x', 3) == 'xxx')\n"
          "local t = {3, 1, 2}; table.sort(t); assert(table.concat(t, ' ') == '1 2 3')\n"
          "assert(table.unpack({1, 2}) == 1 and table.pack(1, 2, 3).n == 3)\n"
          "assert(string.nope == nil and math.nope == nil and table.nope == nil)\n"
          "math.randomseed(3); local a = math.random(1000)\n"
          "math.randomseed(3); assert(math.random(1000) == a)\n"
          "print('ok')"),
      "");
  EXPECT_EQ(Log(), "[bot#0] ok\n");
  EXPECT_CONTAINS(Run("\nlocal f = string.dump"),
                  "scripts/robot.lua:2: string.dump is not allowed in a sandboxed script");
  EXPECT_CONTAINS(Run("local f = ('x').dump"), "string.dump is not allowed");
}

// One rule for every refusal: it ends the callback, pcall or not, naming
// the script and line (or disables the script under disable_script), so a
// script cannot go on without the file, command or seed it asked for.
// Ordinary failures (a missing file, a missing module) stay catchable.
TEST_F(SandboxTest, PcallCannotCatchARefusal) {
  const std::vector<std::pair<std::string, std::string>> refusals = {
      {"pcall(os.execute, 'true')", "os.execute is not allowed"},
      {"pcall(function() return os.execute('true') end)", "os.execute is not allowed"},
      {"pcall(io.popen, 'ls')", "io.popen is not allowed"},
      {"pcall(function() return debug.getinfo(1) end)", "debug.getinfo is not allowed"},
      {"pcall(function() return dofile('x.lua') end)", "dofile is not allowed"},
      {"pcall(io.open, '/etc/passwd')", "is outside the world's folder"},
      {"pcall(io.open, '../secret.txt')", "'..' is not allowed in a path"},
      {"pcall(io.open, 'summary.json', 'w')", "one of the run's own outputs"},
      {"pcall(io.lines, '/etc/passwd')", "is outside the world's folder"},
      {"pcall(setmetatable, {}, {__gc = false})", "__gc finalizers are not allowed"},
      {"pcall(math.randomseed)", "math.randomseed needs a seed"},
      {"pcall(load, string.char(27) .. 'Lua')", "binary chunks are not allowed"},
      {"pcall(function() return string.dump end)", "string.dump is not allowed"},
      {"xpcall(os.exit, function(e) return e end)", "os.exit is not allowed"},
  };
  for (const auto& [call, message] : refusals) {
    const std::string error =
        Run("\nfunction sysCall_init()\n  local ok = " + call + "\n  print('went on', ok)\nend\n");
    EXPECT_CONTAINS(error, message);
    EXPECT_CONTAINS(error, "bot#0: scripts/robot.lua:3:");
    EXPECT_EQ(Log(), "") << call;
  }
  EXPECT_EQ(Run("assert(not pcall(require, 'nothere'))\n"
                "assert(io.open('missing.txt') == nil)\n"
                "print('went on')"),
            "");
  EXPECT_EQ(Log(), "[bot#0] went on\n");
}

// Lua runs __gc finalizers with hooks off: one that loops would hang the
// step for good. setmetatable refuses a metatable with __gc (Lua marks an
// object for finalization only there, so adding __gc later does nothing).
TEST_F(SandboxTest, GcFinalizersAreRefusedBecauseNothingCouldStopOne) {
  ASSERT_CONTAINS(Run("\nsetmetatable({}, {__gc = function() end})"),
                  "bot#0: scripts/robot.lua:2: setmetatable: __gc finalizers are not allowed in a "
                  "sandboxed script (Lua cannot stop one that loops)");
  EXPECT_CONTAINS(Run("setmetatable({}, {__gc = function() while true do end end})\n"
                      "collectgarbage()"),
                  "__gc finalizers are not allowed");
  EXPECT_EQ(Run("local mt = {}\n"
                "local t = setmetatable({}, mt)\n"
                "mt.__gc = function() print('finalized') end\n"
                "t = nil; collectgarbage(); collectgarbage()\n"
                "-- Everything else setmetatable does is unchanged.\n"
                "local c = setmetatable({}, {__index = {x = 1}, __metatable = 'locked'})\n"
                "assert(c.x == 1 and getmetatable(c) == 'locked')\n"
                "assert(not pcall(setmetatable, c, {}))\n"
                "assert(getmetatable(setmetatable(setmetatable({}, {}), nil)) == nil)\n"
                "assert(not pcall(setmetatable, 1, {}) and not pcall(setmetatable, {}, 1))\n"
                "-- A file's metatable, whose __gc Lua runs, cannot be reached.\n"
                "assert(type(getmetatable(io.open('data.txt'))) == 'string')"),
            "");
  EXPECT_EQ(Log(), "");
  EXPECT_EQ(Run("local t = setmetatable({}, {__gc = function() print('finalized') end})\n"
                "t = nil; collectgarbage()",
                true, /*trust=*/true),
            "");
  EXPECT_EQ(Log(), "[bot#0] finalized\n");
}

// math.randomseed() without a seed reads the clock: runs would stop being
// reproducible. With a seed it works as in Lua.
TEST_F(SandboxTest, RandomSeedNeedsASeed) {
  EXPECT_CONTAINS(Run("\nmath.randomseed()"),
                  "bot#0: scripts/robot.lua:2: math.randomseed needs a seed: without one it "
                  "reads the clock and runs stop being reproducible");
  EXPECT_CONTAINS(Run("math.randomseed(nil)"), "math.randomseed needs a seed");
  EXPECT_EQ(Run("math.randomseed(42); local a = math.random(1000000)\n"
                "math.randomseed(42, 7); local b = math.random(1000000)\n"
                "math.randomseed(42); assert(math.random(1000000) == a)\n"
                "math.randomseed(42, 7); assert(math.random(1000000) == b)"),
            "");
  EXPECT_EQ(Run("math.randomseed()", true, /*trust=*/true), "");
}

TEST_F(SandboxTest, TrustScriptsGivesTheFullLibraries) {
  EXPECT_EQ(Run("assert(type(os.execute) == 'function' and type(io.popen) == 'function' and "
                "type(debug.getinfo) == 'function' and type(package.loadlib) == 'function')",
                true, /*trust=*/true),
            "");
  EXPECT_CONTAINS(Run("assert(type(os.execute) == 'function')"), "os.execute is not allowed");
}

// --trust-scripts lifts the restrictions, not the folders: require searches
// the world's folders first, relative reads start in the world's folder and
// relative writes in --out; absolute paths and '..' go anywhere.
TEST_F(SandboxTest, TrustedScriptsFindModulesAndFilesWhereSandboxedOnesDo) {
  fs::create_directories(root_ / "scripts");
  Write(root_ / "world" / "good.lua", "return {name = 'good'}\n");
  Write(root_ / "world" / "scripts" / "sub.lua", "return {name = 'sub'}\n");
  Write(root_ / "scripts" / "beside.lua", "return {name = 'beside'}\n");
  const std::string secret = (root_ / "secret.txt").string();
  EXPECT_EQ(Run("assert(require('good').name == 'good'); assert(require('sub').name == 'sub')\n"
                "assert(require('beside').name == 'beside')",
                true, /*trust=*/true),
            "");
  EXPECT_EQ(Run("local f = assert(io.open('data.txt')); assert(f:read('l') == 'hello'); f:close()\n"
                "for l in io.lines('data.txt') do assert(l == 'hello') end",
                true, /*trust=*/true),
            "");
  EXPECT_EQ(Run("local w = assert(io.open('trusted_copy.txt', 'w')); w:write('x=2'); w:close()",
                true, /*trust=*/true),
            "");
  EXPECT_EQ(Run("assert(io.open('" + secret +
                    "'):read('l') == 'secret')\n"
                    "assert(io.open('../secret.txt'):read('l') == 'secret')\n"
                    "assert(type(os.execute) == 'function' and type(io.popen) == 'function')",
                true, /*trust=*/true),
            "");
  std::ifstream in(root_ / "out" / "trusted_copy.txt");
  std::string text;
  std::getline(in, text);
  EXPECT_EQ(text, "x=2");
  EXPECT_FALSE(fs::exists("trusted_copy.txt"));  // not in the current directory
  fs::remove("trusted_copy.txt");
  // Then Lua's own search path; a missing module names the world's folders too.
  EXPECT_CONTAINS(Run("require('nothere')", true, /*trust=*/true),
                  (root_ / "world" / "scripts" / "nothere.lua").string());
  EXPECT_CONTAINS(Run("require('nothere')", true, /*trust=*/true), "no file '/usr/");
  EXPECT_CONTAINS(Run("io.open('trusted_nowhere.txt', 'w')", /*with_out=*/false, /*trust=*/true),
                  "the run has no output folder (swarmsim run --out DIR)");
  EXPECT_FALSE(fs::exists("trusted_nowhere.txt"));
  fs::remove("trusted_nowhere.txt");
}

}  // namespace
}  // namespace swarmsim
