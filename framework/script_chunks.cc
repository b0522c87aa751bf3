// A script's factory, compiled once for every state (script_chunks.h).
#include "framework/script_chunks.h"

#include <algorithm>
#include <string_view>

#include "framework/script_state.h"

namespace swarmsim::lua_host {
namespace {

// Feeds lua_load the wrapped source without copying it.
struct ChunkPieces {
  std::string_view pieces[3];
  int next = 0;
};
const char* ReadPieces(lua_State*, void* data, size_t* size) {
  auto* chunk = static_cast<ChunkPieces*>(data);
  while (chunk->next < 3 && chunk->pieces[chunk->next].empty()) ++chunk->next;
  if (chunk->next == 3) {
    *size = 0;
    return nullptr;
  }
  const std::string_view piece = chunk->pieces[chunk->next++];
  *size = piece.size();
  return piece.data();
}

int AppendBytes(lua_State*, const void* bytes, size_t size, void* out) {
  static_cast<std::string*>(out)->append(static_cast<const char*>(bytes), size);
  return 0;
}

}  // namespace

std::string CompileFactory(lua_State* L, const ScriptSource& source, CompiledChunks* chunks) {
  const std::string chunkname = "@" + (source.path.empty() ? std::string("?") : source.path);
  if (const std::shared_ptr<const std::string> bytecode = chunks ? chunks->Find(source) : nullptr) {
    int status = luaL_loadbufferx(L, bytecode->data(), bytecode->size(), chunkname.c_str(), "b");
    if (status == LUA_OK) status = lua_pcall(L, 0, 1, 0);
    if (status == LUA_OK) return "";
    lua_pop(L, 1);  // out of memory: compile the text below, which reports it
  }
  ChunkPieces chunk{{"return function(_ENV, ...) ", source.code, "\nend"}};
  int status = lua_load(L, ReadPieces, &chunk, chunkname.c_str(), "t");
  std::string bytecode;
  if (status == LUA_OK && chunks != nullptr) lua_dump(L, AppendBytes, &bytecode, 0);
  if (status == LUA_OK) status = lua_pcall(L, 0, 1, 0);
  if (status == LUA_OK && lua_isfunction(L, -1)) {
    // The function must end at our own 'end': a source like "end, function()"
    // would otherwise close it early and compile into something else.
    lua_Debug ar;
    lua_pushvalue(L, -1);
    lua_getinfo(L, ">S", &ar);
    const int last_line =
        2 + static_cast<int>(std::count(source.code.begin(), source.code.end(), '\n'));
    if (ar.linedefined == 1 && ar.lastlinedefined == last_line) {
      if (chunks != nullptr && !bytecode.empty()) chunks->Add(source, std::move(bytecode));
      return "";
    }
  }
  std::string message = status == LUA_OK ? std::string() : ErrorText(L, status);
  lua_pop(L, 1);
  status = luaL_loadbufferx(L, source.code.data(), source.code.size(), chunkname.c_str(), "t");
  if (status != LUA_OK) message = ErrorText(L, status);
  lua_pop(L, 1);
  return message.empty() ? chunkname.substr(1) + ": the script does not compile" : message;
}

}  // namespace swarmsim::lua_host
