// The script sandbox as a user meets it: each escape, tried from a world
// file through the program, ends the run with a message naming the robot,
// script and line; --out makes a writable folder; --trust-scripts lifts it.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/swarm/run_program.h"

namespace {

namespace fs = std::filesystem;

using Result = swarmsim::testing::CommandResult;
using swarmsim::testing::RunProgram;

// A world folder whose one robot runs `code` in sysCall_init (line 2).
fs::path MakeWorld(const std::string& code) {
  const fs::path dir = swarmsim::testing::ProbeWorld(
      "swarmsim_sandbox_cli", "probe", "", "function sysCall_init()\n  " + code + "\nend\n");
  std::ofstream(dir / "data.txt") << "42\n";
  return dir;
}

TEST(SandboxCliTest, EachEscapeFromAWorldFileIsRefusedWithScriptAndLine) {
  const std::vector<std::pair<std::string, std::string>> escapes = {
      {"os.execute('touch /tmp/swarmsim_pwned')", "os.execute is not allowed"},
      {"io.popen('ls')", "io.popen is not allowed"},
      {"package.loadlib('libc.so.6', 'system')", "package.loadlib is not allowed"},
      {"debug.sethook()", "debug.sethook is not allowed"},
      {"load(string.char(27) .. 'LuaT')", "binary chunks are not allowed"},
      {"io.open('/etc/passwd')", "is outside the world's folder"},
      {"io.open('../x.txt')", "'..' is not allowed in a path"},
      {"io.open('x.txt', 'w')", "the run has no output folder"},
      {"require('os_tools')", "module 'os_tools' not found"},
  };
  for (const auto& [code, message] : escapes) {
    const fs::path dir = MakeWorld(code);
    const Result r = RunProgram("run " + (dir / "world.yaml").string() + " --steps 2 --quiet");
    EXPECT_EQ(r.exit_code, 1) << code << "\n" << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("probe#0: "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("probe.lua:2:"), std::string::npos) << r.output;
    fs::remove_all(dir);
  }
  EXPECT_FALSE(fs::exists("/tmp/swarmsim_pwned"));
}

// What a script's state does as it closes still happens at the run's end:
// a file it never closed is complete, and (with --trust-scripts) its
// finalizers run. The program leaves states to the system at its end only
// when closing them runs no code (no io, sandboxed).
TEST(SandboxCliTest, WhatClosingAScriptsStateDoesHappensAtTheRunsEnd) {
  fs::path dir = MakeWorld("log = assert(io.open('log.txt', 'w')); log:write('started')");
  Result r = RunProgram("run " + (dir / "world.yaml").string() + " --steps 3 --quiet --out " +
                        (dir / "out").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  std::string text;
  std::getline(std::ifstream(dir / "out" / "log.txt"), text);
  EXPECT_EQ(text, "started");
  fs::remove_all(dir);

  dir = MakeWorld("keep = setmetatable({}, {__gc = function() local f = io.open('" +
                  (fs::temp_directory_path() / "swarmsim_gc_probe.txt").string() +
                  "', 'w'); f:write('finalized'); f:close() end})");
  fs::remove(fs::temp_directory_path() / "swarmsim_gc_probe.txt");
  r = RunProgram("run " + (dir / "world.yaml").string() + " --steps 3 --quiet --trust-scripts");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  text.clear();
  std::getline(std::ifstream(fs::temp_directory_path() / "swarmsim_gc_probe.txt"), text);
  EXPECT_EQ(text, "finalized");
  fs::remove(fs::temp_directory_path() / "swarmsim_gc_probe.txt");
  fs::remove_all(dir);
}

TEST(SandboxCliTest, OutFolderIsWritableAndTrustScriptsLiftsTheSandbox) {
  fs::path dir = MakeWorld(
      "local v = io.open('data.txt'):read('n'); local f = assert(io.open('copy.txt', 'w')); "
      "f:write(v * 2); f:close()");
  Result r = RunProgram("run " + (dir / "world.yaml").string() + " --steps 1 --quiet --out " +
                        (dir / "out").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  std::ifstream copy(dir / "out" / "copy.txt");
  std::string text;
  std::getline(copy, text);
  EXPECT_EQ(text, "84");
  fs::remove_all(dir);

  dir = MakeWorld("assert(type(os.execute) == 'function' and type(debug.getinfo) == 'function')");
  r = RunProgram("run " + (dir / "world.yaml").string() + " --steps 1 --quiet --trust-scripts");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  r = RunProgram("run " + (dir / "world.yaml").string() + " --steps 1 --quiet");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  fs::remove_all(dir);
}

// A script cannot clobber the files the run itself writes into --out: any
// mode but plain reading is refused for them; other names, and the same
// names in a subfolder, stay writable.
TEST(SandboxCliTest, ScriptsCannotOverwriteTheRunsOwnOutputs) {
  for (const std::string name : {"metrics.csv", "summary.json", "paint.png", "stderr.txt"}) {
    for (const std::string mode : {"w", "a", "r+", "wb"}) {
      const fs::path dir =
          MakeWorld("local f = io.open('" + name + "', '" + mode + "'); f:write('clobbered')");
      const Result r = RunProgram("run " + (dir / "world.yaml").string() +
                                  " --steps 2 --quiet --out " + (dir / "out").string());
      EXPECT_EQ(r.exit_code, 1) << name << " " << mode << "\n" << r.output;
      EXPECT_NE(
          r.output.find("probe.lua:2: io.open: '" + name + "' is one of the run's own outputs"),
          std::string::npos)
          << r.output;
      std::ifstream summary(dir / "out" / "summary.json");
      std::string text((std::istreambuf_iterator<char>(summary)), std::istreambuf_iterator<char>());
      EXPECT_NE(text.find("\"status\""), std::string::npos) << name << " " << mode << ": " << text;
      fs::remove_all(dir);
    }
  }
  const fs::path dir = MakeWorld(
      "assert(io.open('out.csv', 'w')):close()\n"
      "  assert(io.open('sub/metrics.csv', 'w')):close()");
  fs::create_directories(dir / "out" / "sub");
  const Result r = RunProgram("run " + (dir / "world.yaml").string() + " --steps 2 --quiet --out " +
                              (dir / "out").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir / "out" / "sub" / "metrics.csv"));
  EXPECT_TRUE(fs::exists(dir / "out" / "out.csv"));
  fs::remove_all(dir);
}

// What works sandboxed works trusted: modules from the world's folders,
// relative reads from the world's folder and writes to --out.
TEST(SandboxCliTest, TrustedScriptsUseTheWorldsFoldersLikeSandboxedOnes) {
  const fs::path dir = MakeWorld(
      "local v = require('good').scale * io.open('data.txt'):read('n'); "
      "local f = assert(io.open('copy.txt', 'w')); f:write(v); f:close()");
  std::ofstream(dir / "good.lua") << "return {scale = 3}\n";
  for (const char* flags : {"", " --trust-scripts"}) {
    fs::remove_all(dir / "out");
    const Result r = RunProgram("run " + (dir / "world.yaml").string() +
                                " --steps 1 --quiet --out " + (dir / "out").string() + flags);
    EXPECT_EQ(r.exit_code, 0) << flags << "\n" << r.output;
    std::ifstream copy(dir / "out" / "copy.txt");
    std::string text;
    std::getline(copy, text);
    EXPECT_EQ(text, "126") << flags;
  }
  EXPECT_FALSE(fs::exists("copy.txt"));
  fs::remove_all(dir);
}

// A plugin is native code: a world loads one from its own folder or the
// program's plugins/ folder; one elsewhere (absolute, '../', or a symbolic
// link out of the folder) takes --trust-scripts or --plugin.
TEST(SandboxCliTest, WorldLoadsPluginsOnlyFromItsFolderOrTheProgramsUnlessTrusted) {
  const fs::path built = fs::path(SWARMSIM_BINARY).parent_path() / "plugins" / "example_plugin.so";
  ASSERT_TRUE(fs::exists(built));
  const fs::path dir = MakeWorld("assert(sim.exampleSum(1, 2) == 3)");
  const fs::path elsewhere = dir.string() + "_lib";
  fs::remove_all(elsewhere);
  fs::create_directories(elsewhere);
  fs::copy_file(built, elsewhere / "example_plugin.so");
  fs::create_directories(dir / "lib");
  fs::copy_file(built, dir / "lib" / "mine.so");
  fs::create_symlink(elsewhere / "example_plugin.so", dir / "link.so");
  const auto world_with = [&](const std::string& plugin) {
    std::ofstream(dir / "world.yaml") << "plugins: [" << plugin
                                      << "]\nsimulation: {physics: kinematic, time_step: 0.1}\n"
                                         "models:\n  - {model: probe.yaml, position: [0, 0]}\n";
    return "run " + (dir / "world.yaml").string() + " --steps 1 --quiet";
  };
  for (const std::string& outside :
       {(elsewhere / "example_plugin.so").string(),
        "../" + elsewhere.filename().string() + "/example_plugin.so", std::string("link.so")}) {
    Result r = RunProgram(world_with(outside));
    EXPECT_EQ(r.exit_code, 2) << outside << "\n" << r.output;
    EXPECT_NE(r.output.find("world.yaml:1:"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("outside the world's folder"), std::string::npos) << r.output;
    r = RunProgram(world_with(outside) + " --trust-scripts");
    EXPECT_EQ(r.exit_code, 0) << outside << "\n" << r.output;
  }
  // From the world's folder, and by name from the program's plugins/.
  for (const std::string& inside : {std::string("lib/mine.so"), std::string("example_plugin")}) {
    const Result r = RunProgram(world_with(inside));
    EXPECT_EQ(r.exit_code, 0) << inside << "\n" << r.output;
  }
  // --plugin is the user's own choice, from anywhere.
  std::ofstream(dir / "world.yaml") << "simulation: {physics: kinematic, time_step: 0.1}\n"
                                       "models:\n  - {model: probe.yaml, position: [0, 0]}\n";
  const Result r =
      RunProgram("run " + (dir / "world.yaml").string() + " --steps 1 --quiet --plugin " +
                 (elsewhere / "example_plugin.so").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  fs::remove_all(dir);
  fs::remove_all(elsewhere);
}

}  // namespace

namespace {

// Modules are named in messages as scripts are, relative to the current
// folder: a require loop reads "a.lua:1: ...", not an absolute path.
TEST(SandboxCliTest, ModulesAreNamedRelativeToTheCurrentFolder) {
  const fs::path dir = MakeWorld("require('a')");
  std::ofstream(dir / "a.lua") << "require('b')\nreturn {}\n";
  std::ofstream(dir / "b.lua") << "\nrequire('a')\nreturn {}\n";
  const Result r = swarmsim::testing::RunCommand("cd " + dir.string() + " && " + SWARMSIM_BINARY +
                                                 " run world.yaml --steps 1 --quiet");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("b.lua:2: require: module 'a' requires itself (a loop)"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find(dir.string() + "/b.lua"), std::string::npos) << r.output;
  fs::remove_all(dir);
}

}  // namespace
