// Opening shared libraries at run time (dlopen): plugins, and swarmsim's own
// modules that keep a heavy dependency out of the program until something
// uses it (modules/rendering/video's libav module). One place that says
// which files were tried and why each failed.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace swarmsim {

// dlopen(path, RTLD_NOW | RTLD_LOCAL); the library stays loaded for the life
// of the process. A path without '/' is searched in the system's library
// path. On failure, returns null and sets *why (if given) to dlerror()'s text.
void* OpenSharedLibrary(const std::string& path, std::string* why);

// dlsym(library, name), null if it has no such symbol.
void* FindSymbol(void* library, const char* name);

// The folder of the running program (/proc/self/exe's), empty if unknown.
std::filesystem::path ProgramFolder();

// The folder of the shared object (or program) holding `address`, a function
// or object of the caller's (dladdr): for code loaded into another program,
// such as the Python binding in python3. Empty if unknown.
std::filesystem::path FolderOfCodeAt(const void* address);

// One of swarmsim's own libraries that is opened on first use. It exports
// one function, `entry`, returning a pointer to a table whose first member
// is an int: the version of the table's layout.
struct OwnLibrary {
  std::string file_name;   // "libswarmsim_libav.so"
  std::string built_at;    // where the build that made the caller put it
  std::string variable;    // the environment variable that names its file instead
  std::string entry;       // "swarmsim_libav_module"
  int version = 0;         // the table version the caller was built with
  std::string needed_for;  // "videos need swarmsim's libav module (...)", for the message
};

// Where `library` is looked for, in order: $variable alone when set (and not
// empty); else beside the running program and in a lib/ folder there (a
// moved build or an install), beside the shared object holding this code
// (the Python binding, run by python3), and where the build put it.
std::vector<std::filesystem::path> CandidatesOf(const OwnLibrary& library);

// The table of the first of `candidates` that opens, exports library.entry
// and has library.version; the library stays loaded for the life of the
// process. Throws swarmsim::Error naming each path tried and why it failed
// (dlerror()'s text, a missing entry, another version).
const void* LoadOwnLibrary(const OwnLibrary& library,
                           const std::vector<std::filesystem::path>& candidates);

// `library`, opened once per process by the first use and kept, a failure
// too: every Get() throws the first attempt's message. As a function-local
// static: `static const LazyOwnLibrary ompl(OmplLibrary()); ompl.Get()`.
class LazyOwnLibrary {
 public:
  explicit LazyOwnLibrary(const OwnLibrary& library);  // loads; never throws
  // The library's table. Throws swarmsim::Error if it did not load.
  const void* Get() const;

 private:
  const void* table_ = nullptr;
  std::string error_;
};

}  // namespace swarmsim
