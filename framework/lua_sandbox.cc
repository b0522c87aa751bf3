// The libraries a script sees (the sandbox): Lua's base library without
// binary chunks, and string, table, math, coroutine, utf8. Filled in on
// first use (a global miss), so a robot that does not use them pays nothing:
//   io       open/lines/type/close only: read under the world's folder,
//            write under the run's output folder (--out); '..' and symlinks
//            leading out are refused;
//   require  Lua modules from the world's folder and the scripts/ folders
//            inside and beside it, cached per state (per robot);
//   os       clock, time, date, difftime only.
// The lazy library tables are lua_libraries.cc's.
// Everything else (os.execute, io.popen, package.loadlib, debug, dofile,
// loadfile, string.dump, binary chunks) raises "file:line: os.execute is not
// allowed ...". A refusal ends the running callback whatever catches it
// (pcall, xpcall, coroutines nested in coroutines: CheckedCall). Three more
// rules keep runs stoppable, reproducible and their outputs intact:
// setmetatable refuses a metatable with __gc (Lua runs finalizers with hooks
// off: nothing could stop one that loops); math.randomseed needs a seed
// (without one it reads the clock); io.open refuses to write the run's own
// outputs (kRunOutputs and what the modules list) in the output folder.
// --trust-scripts (WorldSettings::trust_scripts) opens
// the full standard libraries instead, with the same folders: require
// searches the world's folders before Lua's path, and relative paths in
// io.open/io.lines start in the world's folder (reading) or the output
// folder (writing).
#include <algorithm>
#include <array>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "framework/display_path.h"
#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/lua_file_text.h"
#include "framework/lua_libraries.h"
#include "framework/world.h"

namespace swarmsim {
namespace {

using sandbox::BaseFunction;
using sandbox::BaseLibrary;
using sandbox::Extras;
using sandbox::FindEntry;
using sandbox::KeepEntry;
using sandbox::LazyLibrary;
using sandbox::LibraryEntry;
using sandbox::LibraryExtras;
using sandbox::OpenLazy;
using sandbox::ReadLibrary;
using sandbox::Refuse;
using sandbox::WrapField;

// load(chunk [, chunkname [, mode [, env]]]): text chunks only, and by
// default in the calling script's environment rather than the shared
// globals, so a loaded chunk cannot leak globals into other scripts.
int SafeLoad(lua_State* L) {
  const int n = lua_gettop(L);
  if (lua_type(L, 1) == LUA_TSTRING && lua_tostring(L, 1)[0] == LUA_SIGNATURE[0])
    RaiseRefusal(L,
                 "load: binary chunks are not allowed in a sandboxed script (run with "
                 "--trust-scripts to lift the sandbox)");
  lua_settop(L, 4);
  lua_pushliteral(L, "t");
  lua_replace(L, 3);
  if (n < 4) {
    lua_rawgeti(L, LUA_REGISTRYINDEX, Context(L).script_env_ref);
    lua_replace(L, 4);
  }
  lua_pushvalue(L, lua_upvalueindex(1));  // the original load
  lua_insert(L, 1);
  lua_call(L, 4, LUA_MULTRET);
  return lua_gettop(L);
}

// setmetatable(t, mt): Lua's, but a metatable with a __gc field is refused.
// A finalizer runs with hooks off, so neither the instruction budget nor the
// memory limit could stop one that loops. Lua marks an object for
// finalization only here (when its new metatable has __gc, looked up raw),
// so a __gc added to the metatable afterwards is never run.
int SafeSetMetatable(lua_State* L) {
  ArgType(L, 1, LUA_TTABLE);
  const int type = lua_type(L, 2);
  if (type != LUA_TNIL && type != LUA_TTABLE)
    throw Error(std::string("bad argument #2 (nil or table expected, got ") + luaL_typename(L, 2) +
                ")");
  lua_settop(L, 2);
  if (type == LUA_TTABLE) {
    lua_pushliteral(L, "__gc");
    const bool finalizer = lua_rawget(L, 2) != LUA_TNIL;
    lua_pop(L, 1);
    if (finalizer)
      RaiseRefusal(
          L,
          "setmetatable: __gc finalizers are not allowed in a sandboxed script (Lua cannot "
          "stop one that loops); run with --trust-scripts to lift the sandbox");
  }
  if (luaL_getmetafield(L, 1, "__metatable") != LUA_TNIL)
    throw Error("cannot change a protected metatable");
  lua_setmetatable(L, 1);
  return 1;
}

// math.randomseed(x [, y]): Lua's, but a seed is required; without one Lua
// seeds from the clock and the address of a local, and runs stop being
// reproducible.
int SafeRandomSeed(lua_State* L) {
  if (lua_type(L, 1) != LUA_TNUMBER)
    RaiseRefusal(L,
                 "math.randomseed needs a seed: without one it reads the clock and runs stop being "
                 "reproducible (math.random is already seeded per robot)");
  // Lua's own checks, made here so that the call below cannot raise.
  ArgInteger(L, 1);
  const int arguments = lua_isnoneornil(L, 2) ? 1 : 2;
  if (arguments == 2) ArgInteger(L, 2);
  lua_settop(L, arguments);
  lua_pushvalue(L, lua_upvalueindex(1));  // the original math.randomseed
  lua_insert(L, 1);
  lua_call(L, arguments, LUA_MULTRET);
  return lua_gettop(L);
}

// collectgarbage([opt [, ...]]): only the options that cannot change how the
// collector runs for the other scripts of the state.
int SafeCollectGarbage(lua_State* L) {
  static const char* const kAllowed[] = {"collect", "count", "step", "isrunning", nullptr};
  ArgOption(L, 1, "collect", kAllowed);
  lua_pushvalue(L, lua_upvalueindex(1));  // the original collectgarbage
  lua_insert(L, 1);
  lua_call(L, lua_gettop(L) - 1, LUA_MULTRET);
  return lua_gettop(L);
}

namespace fs = std::filesystem;

// __index of a restricted library table: a missing field is refused by name.
int RefuseField(lua_State* L) {
  const char* library = lua_tostring(L, lua_upvalueindex(1));
  const char* field = lua_type(L, 2) == LUA_TSTRING ? lua_tostring(L, 2) : "?";
  Refuse(L, std::string(library) + "." + field);
}

// A table whose missing fields are refused; left on the stack.
void NewRestrictedTable(lua_State* L, const char* library, int fields) {
  lua_createtable(L, 0, fields);
  lua_createtable(L, 0, 1);
  lua_pushstring(L, library);
  lua_pushcclosure(L, (Guarded<RefuseField, "">), 1);
  lua_setfield(L, -2, "__index");
  lua_setmetatable(L, -2);
}

// Does `path` (canonical) lie inside `root` (canonical)?
bool IsInside(const fs::path& path, const fs::path& root) {
  auto p = path.begin();
  for (auto r = root.begin(); r != root.end(); ++r, ++p) {
    if (r->empty()) continue;  // a trailing separator
    if (p == path.end() || *p != *r) return false;
  }
  return true;
}

fs::path Canonical(const fs::path& path) {
  std::error_code ec;
  fs::path out = fs::weakly_canonical(path, ec);
  return ec ? path.lexically_normal() : out;
}

// What a run writes into its output folder, which scripts may not write:
// the runner's files (swarm/run: summary.json, metrics.csv; swarm/record:
// recording.swrec; --video without a FILE: video.mp4), a sweep's stderr.txt
// (swarm/sweep/worker.cc), the modules' (paint.png, mill.csv) and the
// folders they fill (graphs/, snapshots/), and the room the runner keeps
// aside for the final summary on a full disk (framework/output_file.cc:
// .swarmsim-reserve; a script emptying it would lose the summary). Beyond this list, every file the
// world's modules list as theirs (World::ListOutputs: a --video FILE inside
// the folder, the snapshots so far) is protected too.
constexpr std::string_view kRunOutputs[] = {"summary.json",      "metrics.csv",   "recording.swrec",
                                            "video.mp4",         "stderr.txt",    "paint.png",
                                            "mill.csv",          "graphs",        "snapshots",
                                            ".swarmsim-reserve", ".swarmsim-lock"};

// Is `name` the output `output`, or a name a writer may give it while it
// writes it aside (summary.json.tmp, .summary.json.1234)? A folder's name
// stands for everything in it.
bool IsOutputName(std::string_view name, std::string_view output) {
  if (name.size() < output.size()) return false;
  if (name == output) return true;
  if (name.substr(0, output.size()) == output && name[output.size()] == '.') return true;
  return name[0] == '.' && name.substr(1, output.size()) == output;
}

// Is `path` (canonical) one of the run's own outputs in `root` (canonical),
// or inside one, or a folder holding one?
bool IsRunOutput(const World& world, const fs::path& path, const fs::path& root) {
  const fs::path relative = path.lexically_relative(root);
  if (relative.empty() || *relative.begin() == "..") return false;
  const std::string first = relative.begin()->string();
  for (std::string_view output : kRunOutputs)
    if (IsOutputName(first, output)) return true;
  for (const OutputFile& file : world.ListOutputs()) {
    // Component by component: the listed file's last one by IsOutputName.
    const fs::path listed = fs::path(file.path).lexically_normal();
    auto l = listed.begin(), r = relative.begin();
    bool same = true;
    for (; same && l != listed.end() && !l->empty() && r != relative.end(); ++l, ++r) {
      const bool last = std::next(l) == listed.end() || std::next(l)->empty();
      same = last ? IsOutputName(r->string(), l->string()) : *l == *r;
    }
    if (same && l != listed.begin()) return true;
  }
  return false;
}

// The file `text` names, checked against the sandbox: relative paths are
// taken from the world's folder (reading) or the output folder (writing).
std::string CheckedPath(lua_State* L, const char* function, const std::string& text, bool write) {
  const WorldSettings& settings = Context(L).world->settings();
  for (const fs::path& part : fs::path(text))
    if (part == "..")
      RaiseRefusal(L, std::string(function) + ": '..' is not allowed in a path ('" + text +
                          "'); scripts are sandboxed (run with --trust-scripts to lift it)");
  fs::path root = write ? settings.output_directory : settings.directory;
  if (root.empty())
    RaiseError(L, std::string(function) + ": cannot write '" + text +
                      "': the run has no output folder (swarmsim run --out DIR)");
  root = Canonical(fs::absolute(root));
  const fs::path path = fs::path(text).is_absolute() ? fs::path(text) : root / text;
  // A symlink to nothing (yet): resolving stops at it, but opening it to
  // write creates its target, wherever that is. Refused, to wherever it points.
  std::error_code ec;
  if (fs::is_symlink(fs::symlink_status(path, ec)) && !fs::exists(path, ec))
    RaiseRefusal(L, std::string(function) + ": '" + text +
                        "' is a symlink to a file that does not exist (" +
                        fs::read_symlink(path, ec).string() +
                        "); scripts are sandboxed (run with --trust-scripts to lift it)");
  // Symlinks are resolved first: one inside the folder pointing out is refused.
  const fs::path resolved = Canonical(path);
  if (!IsInside(resolved, root))
    RaiseRefusal(L, std::string(function) + ": '" + text + "' is outside the " +
                        (write ? "run's output folder" : "world's folder") + " (" + root.string() +
                        "); scripts are sandboxed (run with --trust-scripts to lift it)");
  if (write && IsRunOutput(*Context(L).world, resolved, root))
    RaiseRefusal(L, std::string(function) + ": '" + resolved.lexically_relative(root).string() +
                        "' is one of the run's own outputs in the output folder (" + root.string() +
                        "); write to another name");
  return path.string();
}

// The file `text` names for a trusted script: like the sandbox, a relative
// path starts in the world's folder (reading) or the output folder
// (writing); an absolute one, or '..', goes anywhere.
std::string TrustedPath(lua_State* L, const char* function, const std::string& text, bool write) {
  if (text.empty() || fs::path(text).is_absolute()) return text;
  const WorldSettings& settings = Context(L).world->settings();
  const fs::path& root = write ? settings.output_directory : settings.directory;
  if (root.empty()) {
    if (write)
      RaiseError(L, std::string(function) + ": cannot write '" + text +
                        "': the run has no output folder (swarmsim run --out DIR)");
    return text;
  }
  return (root / text).string();
}

// The path io.open / io.lines hand to Lua's: checked (sandbox) or resolved (trusted).
template <bool kTrusted>
std::string ScriptPath(lua_State* L, const char* function, const std::string& text, bool write) {
  return kTrusted ? TrustedPath(L, function, text, write) : CheckedPath(L, function, text, write);
}

// io.open(path [, mode]): the original, on a checked (resolved) path.
template <bool kTrusted>
int OpenFile(lua_State* L) {
  const std::string text = ArgString(L, 1);
  const std::string mode = lua_isnoneornil(L, 2) ? "r" : ArgString(L, 2);
  const bool write = mode != "r" && mode != "rb";
  const std::string path = ScriptPath<kTrusted>(L, "io.open", text, write);
  lua_settop(L, 0);
  lua_pushvalue(L, lua_upvalueindex(1));
  lua_pushstring(L, path.c_str());
  lua_pushstring(L, mode.c_str());
  if (lua_pcall(L, 2, LUA_MULTRET, 0) != LUA_OK) throw LuaErrorOnStack{};
  return lua_gettop(L);
}

// io.lines(path, ...): reading only; standard input for trusted scripts only.
template <bool kTrusted>
int LinesOfFile(lua_State* L) {
  if (!lua_isnoneornil(L, 1)) {
    const std::string path = ScriptPath<kTrusted>(L, "io.lines", ArgString(L, 1), false);
    lua_pushstring(L, path.c_str());
    lua_replace(L, 1);
  } else if (!kTrusted) {
    Refuse(L, "io.lines() on standard input");
  }
  lua_pushvalue(L, lua_upvalueindex(1));
  lua_insert(L, 1);
  if (lua_pcall(L, lua_gettop(L) - 1, LUA_MULTRET, 0) != LUA_OK) throw LuaErrorOnStack{};
  return lua_gettop(L);
}

// Registry key of a state's table of required modules.
const char kModulesKey = 0;
const char kLoadingSentinel = 0;

// The folders require searches, in order: the world's folder, its scripts/
// folder, the scripts/ folder beside it.
std::array<fs::path, 3> ModuleFolders(lua_State* L) {
  const fs::path world = Canonical(fs::absolute(Context(L).world->settings().directory));
  return {world, world / "scripts", world.parent_path() / "scripts"};
}

// require(name): a Lua module (name.lua, dots for folders) from the world's
// folder, then its scripts/ folder, then the scripts/ folder beside it. Run
// once per robot in an environment of its own; its result is cached.
int SafeRequire(lua_State* L) {
  const std::string name = ArgString(L, 1);
  lua_settop(L, 1);
  lua_rawgetp(L, LUA_REGISTRYINDEX, &kModulesKey);  // 2: the cache
  if (lua_isnil(L, 2)) {
    lua_pop(L, 1);
    lua_newtable(L);
    lua_pushvalue(L, -1);
    lua_rawsetp(L, LUA_REGISTRYINDEX, &kModulesKey);
  }
  // One cache a robot: robots sharing a state (robots_per_lua_state) each
  // get their own module, as with a state each.
  const lua_Integer robot = Context(L).instance;
  if (lua_rawgeti(L, 2, robot) != LUA_TTABLE) {
    lua_pop(L, 1);
    lua_newtable(L);
    lua_pushvalue(L, -1);
    lua_rawseti(L, 2, robot);
  }
  lua_replace(L, 2);
  lua_getfield(L, 2, name.c_str());
  if (lua_touserdata(L, -1) == &kLoadingSentinel)
    RaiseError(L, "require: module '" + name + "' requires itself (a loop)");
  if (!lua_isnil(L, -1)) return 1;
  lua_pop(L, 1);
  if (name.empty() ||
      name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                             "0123456789_.-") != std::string::npos ||
      name.find("..") != std::string::npos || name.front() == '.')
    RaiseError(L, "require: '" + name +
                      "' is not a module name (letters, digits, '_', '-', and '.' for folders)");
  std::string relative = name;
  std::replace(relative.begin(), relative.end(), '.', '/');
  relative += ".lua";
  std::string searched;
  for (const fs::path& root : ModuleFolders(L)) {
    const fs::path candidate = root / relative;
    searched += "\n\t" + candidate.string();
    std::error_code ec;
    if (!fs::is_regular_file(candidate, ec)) continue;
    if (!IsInside(Canonical(candidate), Canonical(root))) {  // a symlink leading out
      searched += " (a symbolic link to " + Canonical(candidate).string() +
                  ", outside the folder: refused)";
      continue;
    }
    std::ifstream in(candidate, std::ios::binary);
    std::stringstream code;
    code << in.rdbuf();
    const std::string text = LuaFileText(code.str());
    // Named in messages as the scripts are: relative to the current folder.
    std::string chunkname = DisplayPath(candidate);
    chunkname.insert(chunkname.begin(), '@');
    if (luaL_loadbufferx(L, text.data(), text.size(), chunkname.c_str(), "t") != LUA_OK)
      throw LuaErrorOnStack{};
    // Its own environment: module globals do not leak into the scripts.
    lua_newtable(L);
    lua_createtable(L, 0, 1);
    lua_pushglobaltable(L);
    lua_setfield(L, -2, "__index");
    lua_setmetatable(L, -2);
    lua_setupvalue(L, -2, 1);
    lua_pushlightuserdata(L, const_cast<char*>(&kLoadingSentinel));
    lua_setfield(L, 2, name.c_str());
    lua_pushvalue(L, 1);
    lua_pushstring(L, candidate.c_str());
    // Protected: a module's error must not jump over this function's strings.
    if (lua_pcall(L, 2, 1, 0) != LUA_OK) throw LuaErrorOnStack{};
    if (lua_isnil(L, -1)) {
      lua_pop(L, 1);
      lua_pushboolean(L, 1);
    }
    lua_pushvalue(L, -1);
    lua_setfield(L, 2, name.c_str());
    return 1;
  }
  RaiseError(L, "require: module '" + name + "' not found; looked for:" + searched);
}

int RefuseFunction(lua_State* L) { Refuse(L, lua_tostring(L, lua_upvalueindex(1))); }

// coroutine.resume, coroutine.close and the functions coroutine.wrap makes:
// Lua's (upvalue 1), called protected. Once the running callback has failed
// (a refusal, a spent instruction budget, the memory limit: LuaContext::
// budget_exhausted) the resumer fails too. Count hooks are per Lua thread:
// the failure arms one on the failing thread and on the callback's root,
// but a coroutine between them (root -> co1 -> co2 -> refusal, each resume
// under pcall) would get control back unhooked and go on; here it fails
// instead, so no thread of the state runs Lua code again in that callback
// (a suspended coroutine can only run through these functions).
//
// While it runs, LuaContext::running names the coroutine (resume's and
// close's first argument, or the thread a wrap function holds as its
// upvalue), so that a refused allocation names the coroutine's line.
int CheckedCall(lua_State* L) {
  LuaContext& c = Context(L);
  if (c.budget_exhausted) FailCallback(L);
  lua_State* const resumer = c.running;
  lua_State* co = nullptr;
  if (lua_getupvalue(L, lua_upvalueindex(1), 1) != nullptr) {  // a wrap function's thread
    co = lua_tothread(L, -1);
    lua_pop(L, 1);
  } else {
    co = lua_tothread(L, 1);
  }
  lua_pushvalue(L, lua_upvalueindex(1));
  lua_insert(L, 1);
  // A coroutine runs as the robot resuming it: one made by another robot of
  // a shared state (handed over through a library table) would otherwise
  // keep its maker's context, which a removed robot no longer has.
  if (co != nullptr) {
    c.running = co;
    SetContext(co, &c);
  }
  const int status = lua_pcall(L, lua_gettop(L) - 1, LUA_MULTRET, 0);
  c.running = resumer;
  if (c.budget_exhausted) FailCallback(L);
  if (status != LUA_OK) return lua_error(L);  // the error as Lua raised it
  return lua_gettop(L);
}

// coroutine.wrap(f): Lua's generator, itself wrapped as CheckedCall.
int CheckedWrap(lua_State* L) {
  lua_pushvalue(L, lua_upvalueindex(1));  // Lua's coroutine.wrap
  lua_insert(L, 1);
  lua_call(L, lua_gettop(L) - 1, 1);
  lua_pushcclosure(L, CheckedCall, 1);
  return 1;
}

// The coroutine library at `table` with resume, wrap and close checked.
void CheckCoroutines(lua_State* L, int table) {
  WrapField(L, table, "resume", CheckedCall);
  WrapField(L, table, "close", CheckedCall);
  WrapField(L, table, "wrap", CheckedWrap);
}

// __index of the globals: builds the restricted libraries on first use and
// refuses the forbidden ones. Other names are nil as usual.
int SandboxGlobalIndex(lua_State* L) {
  if (lua_type(L, 2) != LUA_TSTRING) return 0;
  const std::string_view key = lua_tostring(L, 2);
  if (key == "io") {
    Context(L).may_finalize = true;
    luaL_requiref(L, LUA_IOLIBNAME, luaopen_io, 0);
    NewRestrictedTable(L, "io", 4);
    for (const char* kept : {"open", "lines", "type", "close"}) {
      lua_getfield(L, -2, kept);
      lua_setfield(L, -2, kept);
    }
    WrapField(L, -1, "open", Guarded<OpenFile<false>, "io.open">);
    WrapField(L, -1, "lines", Guarded<LinesOfFile<false>, "io.lines">);
    // Files are finalized by their metatable's __gc: a script must not reach
    // it (getmetatable(f).__gc = <a loop>) to replace it.
    luaL_getmetatable(L, LUA_FILEHANDLE);
    lua_pushliteral(L, "file");
    lua_setfield(L, -2, "__metatable");
    lua_pop(L, 1);
  } else if (key == "os") {
    luaL_requiref(L, LUA_OSLIBNAME, luaopen_os, 0);
    NewRestrictedTable(L, "os", 4);
    for (const char* kept : {"clock", "time", "date", "difftime"}) {
      lua_getfield(L, -2, kept);
      lua_setfield(L, -2, kept);
    }
  } else if (key == LUA_COLIBNAME) {
    luaL_requiref(L, LUA_COLIBNAME, luaopen_coroutine, 0);
    CheckCoroutines(L, -1);
  } else if (key == LUA_UTF8LIBNAME) {
    luaL_requiref(L, LUA_UTF8LIBNAME, luaopen_utf8, 0);
  } else if (key == "require") {
    lua_pushcfunction(L, (Guarded<SafeRequire, "require">));
  } else if (key == "package" || key == "debug") {
    NewRestrictedTable(L, key == "package" ? "package" : "debug", 0);
  } else if (key == "dofile" || key == "loadfile") {
    lua_pushvalue(L, 2);
    lua_pushcclosure(L, (Guarded<RefuseFunction, "">), 1);
  } else if (const LibraryEntry* entry = FindEntry(BaseLibrary(), key)) {
    return KeepEntry(L, *entry);  // pairs, tostring, ... (OpenSafeLibraries)
  } else {
    return 0;
  }
  lua_pushvalue(L, 2);
  lua_pushvalue(L, -2);
  lua_rawset(L, 1);
  return 1;
}

// Trusted scripts: Lua's full libraries, but found where sandboxed scripts
// find them: require searches the world's folders before Lua's path, and
// io.open / io.lines take relative paths from the world's folder (reading)
// or the output folder (writing).
void OpenTrusted(lua_State* L) {
  Context(L).may_finalize = true;
  luaL_openlibs(L);
  lua_getglobal(L, LUA_LOADLIBNAME);
  std::string path;
  for (const fs::path& root : ModuleFolders(L))
    path += (root / (LUA_PATH_MARK ".lua")).string() + LUA_PATH_SEP;
  lua_getfield(L, -1, "path");
  if (const char* lua_path = lua_tostring(L, -1)) path += lua_path;
  lua_pop(L, 1);
  lua_pushlstring(L, path.data(), path.size());
  lua_setfield(L, -2, "path");
  lua_pop(L, 1);
  lua_getglobal(L, LUA_IOLIBNAME);
  WrapField(L, -1, "open", Guarded<OpenFile<true>, "io.open">);
  WrapField(L, -1, "lines", Guarded<LinesOfFile<true>, "io.lines">);
  lua_pop(L, 1);
  lua_getglobal(L, LUA_COLIBNAME);
  CheckCoroutines(L, -1);
  lua_pop(L, 1);
}

}  // namespace

namespace {
// The safe standard libraries (base without file access or binary chunks,
// string, table, math; coroutine and utf8 on first use), each entry there
// on first use through the globals' metatable (SandboxGlobalIndex).
void OpenSafeLibraries(lua_State* L);
}  // namespace

void OpenSandbox(lua_State* L) {
  if (Context(L).world != nullptr && Context(L).world->settings().trust_scripts) {
    OpenTrusted(L);
    return;
  }
  OpenSafeLibraries(L);
  lua_pushglobaltable(L);
  lua_createtable(L, 0, 1);
  lua_pushcfunction(L, SandboxGlobalIndex);
  lua_setfield(L, -2, "__index");
  lua_setmetatable(L, -2);
  lua_pop(L, 1);
}

namespace {
void OpenSafeLibraries(lua_State* L) {
  // The base library's functions come on first use too (SandboxGlobalIndex
  // through BaseLibrary), and coroutine and utf8, which few controllers use:
  // the globals hold _G, _VERSION and the sandbox's own load, setmetatable
  // and collectgarbage. No dofile, loadfile (refused by name) or warn (it
  // writes to the process's stderr).
  lua_pushglobaltable(L);
  lua_pushvalue(L, -1);
  lua_setfield(L, -2, LUA_GNAME);
  lua_pushliteral(L, LUA_VERSION);
  lua_setfield(L, -2, "_VERSION");
  lua_pushcfunction(L, BaseFunction("load"));
  lua_pushcclosure(L, (Guarded<SafeLoad, "">), 1);
  lua_setfield(L, -2, "load");
  lua_pushcfunction(L, BaseFunction("collectgarbage"));
  lua_pushcclosure(L, (Guarded<SafeCollectGarbage, "collectgarbage">), 1);
  lua_setfield(L, -2, "collectgarbage");
  lua_pushcfunction(L, (Guarded<SafeSetMetatable, "setmetatable">));
  lua_setfield(L, -2, "setmetatable");
  lua_pop(L, 1);
  // Each library fetches its entries on first use (OpenLazy). string.dump
  // makes binary chunks, which nothing here can load: it is refused by
  // name. Debian builds Lua with LUA_COMPAT_MATHLIB: the functions 5.4
  // deprecated (cosh, pow, ...) are left out.
  static const LazyLibrary kString = ReadLibrary(LUA_STRLIBNAME, luaopen_string, {}, "dump");
  static const LazyLibrary kTable = ReadLibrary(LUA_TABLIBNAME, luaopen_table, {}, nullptr);
  static const LazyLibrary kMath =
      ReadLibrary(LUA_MATHLIBNAME, luaopen_math,
                  {"cosh", "sinh", "tanh", "pow", "frexp", "ldexp", "log10"}, nullptr);
  const LibraryExtras& extras = Extras();
  OpenLazy(L, kTable, 0);
  lua_pop(L, 1);
  // The strings' metatable, as luaopen_string makes it: their methods
  // ("abc"):upper() from the lazy table, arithmetic on numeric strings.
  OpenLazy(L, kString, 0);
  lua_createtable(L, 0, static_cast<int>(extras.string_metamethods.size()) + 1);
  for (const auto& [name, function] : extras.string_metamethods) {
    lua_pushcfunction(L, function);
    lua_setfield(L, -2, name.c_str());
  }
  lua_insert(L, -2);
  lua_setfield(L, -2, "__index");
  lua_pushliteral(L, "");
  lua_insert(L, -2);
  lua_setmetatable(L, -2);
  lua_pop(L, 1);
  // math.random and math.randomseed share the state's own generator (seeded
  // per robot by the caller, through the wrapped randomseed).
  OpenLazy(L, kMath, 2);
  // Zeroed until seeded (luaopen_math seeds it from the clock).
  std::memset(lua_newuserdatauv(L, extras.generator_bytes, 0), 0, extras.generator_bytes);
  lua_pushvalue(L, -1);
  lua_pushcclosure(L, extras.random, 1);
  lua_setfield(L, -3, "random");
  lua_pushcclosure(L, extras.randomseed, 1);
  lua_setfield(L, -2, "randomseed");
  WrapField(L, -1, "randomseed", Guarded<SafeRandomSeed, "math.randomseed">);
  lua_pop(L, 1);
}
}  // namespace

}  // namespace swarmsim
