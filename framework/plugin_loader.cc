#include "framework/plugin_loader.h"

#include <dlfcn.h>

#include "framework/error.h"
#include "framework/plugin_api.h"
#include "framework/registry.h"

namespace swarmsim {
namespace {

// What a plugin registers, gathered before it goes into the registry.
struct Registration {
  ModuleInfo info;
  std::vector<ScriptCommand> commands;
  std::string error;
};

int AddCommand(void* impl, const char* name, const char* description, SwarmsimCommand command,
               void* user_data) {
  auto* r = static_cast<Registration*>(impl);
  if (name == nullptr || command == nullptr) {
    r->error = "add_command needs a name and a function";
    return -1;
  }
  r->commands.push_back({name, description != nullptr ? description : "", command, user_data});
  return 0;
}

void SetInfo(void* impl, const char* name, const char* version, const char* description) {
  auto* r = static_cast<Registration*>(impl);
  if (name != nullptr) r->info.name = name;
  if (version != nullptr) r->info.version = version;
  if (description != nullptr) r->info.description = description;
}

}  // namespace

void LoadPlugin(const std::string& path, ModuleRegistry* registry) {
  // A bare name would be searched in the system's library path: say "./x.so".
  const std::string name = path.find('/') == std::string::npos ? "./" + path : path;
  void* library = dlopen(name.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (library == nullptr) {
    const char* message = dlerror();
    throw Error("cannot load plugin '" + path + "': " + (message ? message : "unknown error"));
  }
  using VersionFunction = int (*)();
  using RegisterFunction = int (*)(const SwarmsimRegistrar*);
  auto version = reinterpret_cast<VersionFunction>(dlsym(library, "swarmsim_plugin_abi_version"));
  auto do_register = reinterpret_cast<RegisterFunction>(dlsym(library, "swarmsim_plugin_register"));
  if (version == nullptr || do_register == nullptr)
    throw Error("plugin '" + path + "' is not a swarmsim plugin: it does not export " +
                (version == nullptr ? "swarmsim_plugin_abi_version" : "swarmsim_plugin_register") +
                " (see framework/plugin_api.h)");
  if (const int v = version(); v != SWARMSIM_PLUGIN_ABI_VERSION)
    throw Error("plugin '" + path + "' was built for plugin ABI version " + std::to_string(v) +
                ", this swarmsim has version " + std::to_string(SWARMSIM_PLUGIN_ABI_VERSION) +
                "; rebuild it against this framework/plugin_api.h");
  Registration r;
  r.info.name.assign(path);
  r.info.version.assign("unversioned");
  const SwarmsimRegistrar registrar{&r, AddCommand, SetInfo};
  if (do_register(&registrar) != 0 || !r.error.empty()) {
    std::string message = "plugin '" + path + "' failed to register";
    if (!r.error.empty()) message.append(": ").append(r.error);
    throw Error(message);
  }
  for (ScriptCommand& command : r.commands) {
    ModuleInfo info = r.info;
    info.name = r.info.name + ":" + command.name;
    info.description = command.description;
    try {
      registry->RegisterScriptCommand(info, std::move(command));
    } catch (const Error& e) {
      throw Error("plugin '" + path + "': " + e.what());
    }
  }
}

}  // namespace swarmsim
