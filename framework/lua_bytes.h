// Bytes a script passes to a device (sim.setRangeAndBearingData,
// sim.sendIrMessage, ...): a string, or a table of integers 0..255 that is a
// sequence t[1]..t[n] with no other keys. A table with a hole or another key
// is refused, naming it ({1, nil, 3} sent one byte, {x = 1} none, without a
// word); it is never sized from #t.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

struct lua_State;

namespace swarmsim {

// The bytes of argument `arg`, at most `max`; `what` names them in errors
// ("data", "message"). Past `max`, throws swarmsim::Error(too_long(n)) with
// the count n of bytes given.
std::vector<uint8_t> ArgBytes(lua_State* L, int arg, size_t max, const char* what,
                              const std::function<std::string(size_t)>& too_long);

}  // namespace swarmsim
