// The swarmsim plugin interface: the one header a plugin includes.
//
// A plugin is a shared library loaded from a world (`plugins: [path]`) or
// with `swarmsim run --plugin PATH`. It exports two C functions:
//
//   extern "C" int swarmsim_plugin_abi_version(void) { return SWARMSIM_PLUGIN_ABI_VERSION; }
//   extern "C" int swarmsim_plugin_register(const SwarmsimRegistrar* r) { ...; return 0; }
//
// and registers script commands through the registrar: a command `name`
// is called from Lua as sim.name(...). Arguments and results are numbers,
// strings and number arrays (SwarmsimValue); no Lua type crosses this
// interface. Everything here is plain C, so a plugin built with another
// compiler works as long as the ABI version matches; the version changes
// whenever a struct below does.
#ifndef SWARMSIM_PLUGIN_API_H_
#define SWARMSIM_PLUGIN_API_H_

#include <stddef.h>
#include <stdint.h>

#define SWARMSIM_PLUGIN_ABI_VERSION 1

#ifdef __cplusplus
extern "C" {
#endif

enum SwarmsimValueType { kSwarmsimNil = 0, kSwarmsimNumber = 1, kSwarmsimString = 2, kSwarmsimNumbers = 3 };

// One argument or result. Strings and arrays are not owned: arguments live
// for the call; results must stay valid until the command returns to
// swarmsim (e.g. static or per-thread storage of the plugin).
typedef struct SwarmsimValue {
  int type;               // SwarmsimValueType
  double number;          // kSwarmsimNumber
  const char* text;       // kSwarmsimString (UTF-8, not necessarily 0-terminated)
  const double* numbers;  // kSwarmsimNumbers
  size_t size;            // bytes of text, or count of numbers
} SwarmsimValue;

// A narrow, read-mostly view of the world the command runs in.
typedef struct SwarmsimWorldApi {
  double (*time)(void* world);  // s, simulation time
  // Position [x, y, z] (m, world frame) of an object; returns 0 if the handle is stale.
  int (*object_position)(void* world, int64_t object, double out[3]);
  // A number parameter as sim.getParam sees it for `robot`; returns 0 if none.
  int (*number_parameter)(void* world, int robot, const char* name, double* out);
} SwarmsimWorldApi;

// Who is calling: the robot and the script's object.
typedef struct SwarmsimCallContext {
  int robot;              // model instance index; -1 for scene and main scripts
  int64_t script_object;  // the calling script's object handle (as Lua sees it); 0 for the main script
  void* world;            // pass to the functions of `api`
  const SwarmsimWorldApi* api;
} SwarmsimCallContext;

// A script command. Fills results[0..max_results) and returns how many,
// or -1 after writing a message into `error` (at most error_size bytes, 0-terminated):
// the script then fails at the calling line with that message.
// Commands of different robots run concurrently: keep them thread-safe.
typedef int (*SwarmsimCommand)(const SwarmsimCallContext* context, const SwarmsimValue* args,
                               int arg_count, SwarmsimValue* results, int max_results,
                               char* error, size_t error_size, void* user_data);

typedef struct SwarmsimRegistrar {
  void* impl;
  // Registers sim.<name>; returns 0, or -1 if the name is taken or invalid.
  int (*add_command)(void* impl, const char* name, const char* description,
                     SwarmsimCommand command, void* user_data);
  // The plugin's name, version and one-line description (swarmsim modules).
  void (*set_info)(void* impl, const char* name, const char* version, const char* description);
} SwarmsimRegistrar;

// The two entry points a plugin exports.
int swarmsim_plugin_abi_version(void);
int swarmsim_plugin_register(const SwarmsimRegistrar* registrar);

#ifdef __cplusplus
}  // extern "C"
#endif

#endif  // SWARMSIM_PLUGIN_API_H_
