// Runs shell commands and the swarmsim program from tests, as a user would.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace swarmsim::testing {

struct CommandResult {
  int exit_code = -1;  // 128 + signal number when the command was killed
  std::string output;  // stdout and stderr together
};

// "ulimit -v KB; " for a shell command: an address-space cap, to show that
// a program refuses input within modest memory. Empty under AddressSanitizer,
// which reserves terabytes of address space for its shadow at start (the
// cap would stop every program before main); the messages are still checked.
inline std::string AddressSpaceLimit(int64_t kb) {
#if defined(__SANITIZE_ADDRESS__)
  (void)kb;
  return "";
#else
  return "ulimit -v " + std::to_string(kb) + "; ";
#endif
}

// Whether glibc itself ended the program (abort, exit 134) for want of
// memory under a tight ulimit -v: "Fatal glibc error: failed to register
// TLS destructor: out of memory", as a thread first touches a thread_local.
// No program can catch that; tests of running out of memory allow it.
inline bool EndedByGlibcOutOfMemory(int exit_code, const std::string& output) {
  return exit_code == 134 && output.find("Fatal glibc error") != std::string::npos;
}

inline CommandResult RunCommand(const std::string& command) {
  CommandResult r;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) r.output.append(buf.data(), n);
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return r;
}

// `build/swarmsim ARGS` (the binary this test tree was built with).
inline CommandResult RunProgram(const std::string& args) {
  return RunCommand(std::string(SWARMSIM_BINARY) + " " + args);
}

// A file's bytes ("" if it cannot be read).
inline std::string ReadFile(const std::filesystem::path& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// tests/data/cli/NAME in the source tree.
inline std::string CliData(const std::string& name) {
  return std::string(SWARMSIM_SOURCE_DIR) + "/tests/data/cli/" + name;
}

// An empty folder path under the temporary folder, unique to this process
// (`prefix`_`name`_pid); whatever was there is removed.
inline std::filesystem::path FreshTempDir(const std::string& prefix, const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    (prefix + "_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  return dir;
}

// A world folder (FreshTempDir(prefix, name)) of one robot, probe#0 (a dummy
// at the origin), running `code` as probe.lua; `settings` go into the
// world's simulation map after the kinematic physics and 0.1 s time step.
inline std::filesystem::path ProbeWorld(const std::string& prefix, const std::string& name,
                                        const std::string& settings, const std::string& code) {
  const std::filesystem::path dir = FreshTempDir(prefix, name);
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "world.yaml") << "simulation: {physics: kinematic, time_step: 0.1"
                                    << (settings.empty() ? "" : ", " + settings)
                                    << "}\nmodels:\n  - {model: probe.yaml, position: [0, 0]}\n";
  std::ofstream(dir / "probe.yaml") << "model: probe\n"
                                       "objects: {name: body, type: dummy, script: probe.lua}\n";
  std::ofstream(dir / "probe.lua") << code;
  return dir;
}

// The rows of a run's metrics.csv (step,time,robot,metric,value); robot is
// empty for the scene's metrics.
struct MetricRow {
  long step = 0;
  std::string robot, metric;
  double value = 0;
};
inline std::vector<MetricRow> ReadMetricsCsv(const std::filesystem::path& file) {
  std::vector<MetricRow> rows;
  std::ifstream csv(file);
  std::string line;
  std::getline(csv, line);  // header
  while (std::getline(csv, line)) {
    std::stringstream s(line);
    std::string step, time, value;
    MetricRow row;
    std::getline(s, step, ',');
    std::getline(s, time, ',');
    std::getline(s, row.robot, ',');
    std::getline(s, row.metric, ',');
    std::getline(s, value, ',');
    row.step = std::stol(step);
    row.value = std::stod(value);
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace swarmsim::testing
