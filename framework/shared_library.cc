#include "framework/shared_library.h"

#include <dlfcn.h>

#include <cstdlib>
#include <system_error>

#include "framework/error.h"

namespace swarmsim {

void* OpenSharedLibrary(const std::string& path, std::string* why) {
  dlerror();  // clear an earlier error
  void* library = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (library == nullptr && why != nullptr) {
    const char* message = dlerror();
    *why = message != nullptr ? message : "unknown error";
  }
  return library;
}

void* FindSymbol(void* library, const char* name) { return dlsym(library, name); }

std::filesystem::path ProgramFolder() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::filesystem::path() : exe.parent_path();
}

std::filesystem::path FolderOfCodeAt(const void* address) {
  Dl_info info{};
  if (dladdr(address, &info) == 0 || info.dli_fname == nullptr || info.dli_fname[0] == '\0')
    return {};
  std::error_code ec;
  const std::filesystem::path file = std::filesystem::canonical(info.dli_fname, ec);
  return ec ? std::filesystem::path() : file.parent_path();
}

std::vector<std::filesystem::path> CandidatesOf(const OwnLibrary& library) {
  const char* variable = std::getenv(library.variable.c_str());
  if (variable != nullptr && *variable != '\0') return {variable};
  std::vector<std::filesystem::path> candidates;
  const auto add = [&](const std::filesystem::path& file) {
    if (file.empty()) return;
    const std::filesystem::path normal = file.lexically_normal();
    for (const std::filesystem::path& c : candidates)
      if (c == normal) return;
    candidates.push_back(normal);
  };
  if (const std::filesystem::path program = ProgramFolder(); !program.empty()) {
    add(program / library.file_name);
    add(program / "lib" / library.file_name);
  }
  if (const std::filesystem::path code =
          FolderOfCodeAt(reinterpret_cast<const void*>(&CandidatesOf));
      !code.empty())
    add(code / library.file_name);
  add(library.built_at);
  return candidates;
}

const void* LoadOwnLibrary(const OwnLibrary& library,
                           const std::vector<std::filesystem::path>& candidates) {
  std::string tried;
  for (const std::filesystem::path& candidate : candidates) {
    std::string why;
    if (void* handle = OpenSharedLibrary(candidate.string(), &why)) {
      using Entry = const void* (*)();
      const auto entry = reinterpret_cast<Entry>(FindSymbol(handle, library.entry.c_str()));
      const void* table = entry != nullptr ? entry() : nullptr;
      // Every table starts with its version (an int).
      const int version = table != nullptr ? *static_cast<const int*>(table) : 0;
      if (table != nullptr && version == library.version) return table;
      why = entry == nullptr ? "not " + library.file_name + ": it does not export " + library.entry
                             : "from another swarmsim build (version " + std::to_string(version) +
                                   ", this one needs " + std::to_string(library.version) + ")";
    }
    // dlerror() names the file too: once is enough.
    if (const std::string self = candidate.string() + ": "; why.starts_with(self))
      why.erase(0, self.size());
    tried.append("\n  ").append(candidate.string()).append(": ").append(why);
  }
  throw Error(library.needed_for + ", and it could not be loaded; tried:" +
              (tried.empty() ? std::string(" nothing") : tried) + "\n(" + library.variable +
              " names its file)");
}

LazyOwnLibrary::LazyOwnLibrary(const OwnLibrary& library) {
  try {
    table_ = LoadOwnLibrary(library, CandidatesOf(library));
  } catch (const Error& e) {
    error_ = e.what();
  }
}

const void* LazyOwnLibrary::Get() const {
  if (table_ == nullptr) throw Error(error_);
  return table_;
}

}  // namespace swarmsim
