// A plugin built against the ABI 3 header, before object types and the
// record phase (tests the message an old plugin gets).
extern "C" int swarmsim_plugin_abi_version(void) { return 3; }
extern "C" int swarmsim_plugin_register(const void*) { return 0; }
