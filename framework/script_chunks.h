// Internal to the Lua host (script_host.cc): a script source compiled as
// `function(_ENV, ...) <code> end`, once for every state (its bytecode
// shared by the states of the robots).
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <utility>

#include "framework/lua_api.h"
#include "framework/scene.h"

namespace swarmsim::lua_host {

// Each distinct script source compiled once for every state: the bytecode
// of its factory chunk (lua_dump, debug information kept, so messages name
// the same file and lines), loaded by the other states without parsing.
// Filled by whichever state compiles a source first; shared by the threads
// that start robots. Two threads may compile a source at the same time
// before either has added it: the first one added is kept, and a reader
// holds its bytecode (shared) while it loads, so no Add changes the bytes
// under it.
class CompiledChunks {
 public:
  // The bytecode of `source`'s factory, or null when none is kept yet.
  std::shared_ptr<const std::string> Find(const ScriptSource& source) {
    const std::lock_guard lock(mutex_);
    const auto it = chunks_.find(&source);
    // A source at an address a freed one had is another source: compare.
    if (it == chunks_.end() || it->second.path != source.path || it->second.code != source.code)
      return nullptr;
    return it->second.bytecode;
  }
  void Add(const ScriptSource& source, std::string bytecode) {
    const std::lock_guard lock(mutex_);
    Entry& entry = chunks_[&source];
    if (entry.bytecode && entry.path == source.path && entry.code == source.code) return;
    entry.path = source.path;
    entry.code = source.code;
    entry.bytecode = std::make_shared<const std::string>(std::move(bytecode));
  }

 private:
  struct Entry {
    std::string path, code;
    std::shared_ptr<const std::string> bytecode;
  };
  std::mutex mutex_;
  std::unordered_map<const ScriptSource*, Entry> chunks_;
};

// Compiles `source` into a function(_ENV, ...) running its code, left on
// the stack. The prefix shares the first line, so line numbers in messages
// are the file's own. Returns "" or the compiler's message (for a broken
// source, the message of compiling it as it is, so that it reads naturally).
// With `chunks`, a source compiled before (by any state) is loaded from its
// bytecode, and one compiled here is added.
std::string CompileFactory(lua_State* L, const ScriptSource& source,
                           CompiledChunks* chunks = nullptr);

}  // namespace swarmsim::lua_host
