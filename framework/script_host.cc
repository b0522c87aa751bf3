// PLACEHOLDER until the Lua host lands: runs no scripts.
#include "framework/script_host.h"
namespace swarmsim {
struct ScriptHost::Impl {};
ScriptHost::ScriptHost(World*) {}
ScriptHost::~ScriptHost() = default;
void ScriptHost::Start() {}
void ScriptHost::RunInstance(int) {}
void ScriptHost::RunSceneScripts() {}
void ScriptHost::Stop() {}
size_t ScriptHost::MemoryBytes() const { return 0; }
}  // namespace swarmsim
