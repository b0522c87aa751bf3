// `swarmsim kilobot build prog.c`: turns a Kilobot program (written for
// kilolib, compiled unchanged) into a swarmsim plugin that registers one
// native controller running it on every robot of a models entry
// (`native_controller: NAME`). The program and the per-robot part of the
// runtime (runtime/kilolib.c) are compiled with the system C compiler, their
// writable sections renamed so that each robot gets its own copy of every
// global (runtime/host.c swaps it in and out), and linked with the host glue
// into NAME.so. README.md in this folder explains the mechanism.
#pragma once

#include <string>
#include <vector>

namespace swarmsim::kilobot {

struct BuildOptions {
  std::string source;                 // the program, a .c file
  std::string output;                 // the plugin; empty: NAME.so beside the source
  std::string name;                   // the controller; empty: the source's stem
  std::vector<std::string> cc_flags;  // passed to the compiler after ours
  bool quiet = false;                 // no "built ..." line
};

// Builds the plugin. Returns 0, or a nonzero exit code after printing why
// on stderr (a compiler error: the compiler's own messages, then a line
// naming the source). Throws swarmsim::Error for a bad option.
int Build(const BuildOptions& options);

// The folder holding include/ and runtime/ (the source tree's
// swarm/kilobot, or an install's share/swarmsim/kilobot; $SWARMSIM_KILOBOT_DIR
// overrides).
std::string RuntimeFolder();

}  // namespace swarmsim::kilobot
