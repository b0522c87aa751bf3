// sim.* messages, signals and packing (framework/lua_api_messages.cc):
// pack/unpack round trips and their limits, string signals, and messages
// charged to their sender's memory until delivered.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/world.h"
#include "tests/framework/error_of.h"
#include "tests/framework/fakes.h"
#include "tests/framework/script_world.h"

namespace swarmsim {
namespace {

using namespace script_test;  // script_world.h

using testing::ErrorOf;

TEST(ScriptControlTest, PackAndUnpackRoundTrip) {
  ScriptWorld w;
  w.AddRobot("bot#0", R"(
    local f = sim.unpackFloats(sim.packFloats({1.5, -2}))
    local d = sim.unpackDoubles(sim.packDoubles({0.1}))
    local i = sim.unpackInt32s(sim.packInt32s({-7, 2147483647}))
    local t = sim.unpackTable(sim.packTable({1, 'two', x = {y = true}, [3] = 0.25}))
    print(#sim.packFloats({1, 2, 3}), f[1], f[2], d[1], i[1], i[2], t[1], t[2], t.x.y, t[3])
    print(pcall(sim.unpackTable, 'garbage'))
  )");
  w.world().Start();
  ASSERT_EQ(w.log.size(), 2u);
  EXPECT_EQ(w.log[0], "[bot#0] 12\t1.5\t-2.0\t0.1\t-7\t2147483647\t1\ttwo\ttrue\t0.25");
  EXPECT_CONTAINS(w.log[1], "not a packed table");
}

// Nested tables take Lua stack space per level: packing one used to write
// past the stack and corrupt the heap. Deep tables and cycles are Lua errors
// naming sim.packTable, which pcall catches; 32 levels still pack.
TEST(ScriptControlTest, PackTableOfDeepOrCyclicTablesIsACleanError) {
  ScriptWorld w;
  w.AddRobot("bot#0", R"(
    local function chain(n)
      local root = {}
      local t = root
      for i = 2, n do t.k = {i = i}; t = t.k end
      return root
    end
    function sysCall_actuation()
      local d = chain(21)
      for i = 1, 50 do sim.sendGlobalMessage(sim.packTable(d)) end
      for i = 1, 50 do
        local ok, e = pcall(sim.packTable, chain(33 + i))
        assert(not ok and e:find('nested more than 32 levels'), e)
      end
      local cycle = {}
      cycle.self = {up = cycle}
      local ok, e = pcall(sim.packTable, cycle)
      print(ok, e)
      local t = sim.unpackTable(sim.packTable(chain(32)))
      local depth = 1
      while t.k do t = t.k; depth = depth + 1 end
      print(depth, t.i)
      -- A table as a key takes its stack slots too.
      local keyed = {}
      local t = keyed
      for i = 1, 31 do local k = {}; t[k] = true; t = k end
      print(#sim.packTable(keyed) > 0, pcall(sim.packTable, {[chain(32)] = 1}))
    end
  )");
  w.Steps(2);
  ASSERT_EQ(w.log.size(), 6u);
  EXPECT_CONTAINS(
      w.log[0],
      "[bot#0] false\tsim.packTable: the table is nested more than 32 levels deep (or has "
      "a cycle)");
  EXPECT_EQ(w.log[1], "[bot#0] 32\t32");
  EXPECT_CONTAINS(
      w.log[2], "[bot#0] true\tfalse\tsim.packTable: the table is nested more than 32 levels deep");
}

// A packed string nested deeper than packTable makes is refused, not unpacked.
TEST(ScriptControlTest, UnpackTableRefusesStringsNestedTooDeeply) {
  ScriptWorld w;
  w.AddRobot("bot#0", R"(
    local function nested(n)  -- n tables, each {[1] = <the next>}
      local s = string.pack('<c1I4', 't', 0)
      for i = 2, n do s = string.pack('<c1I4c1i8', 't', 1, 'i', 1) .. s end
      return s
    end
    local t = sim.unpackTable(nested(32))
    local depth = 1
    while t[1] do t = t[1]; depth = depth + 1 end
    print(depth, pcall(sim.unpackTable, nested(33)))
    print(pcall(sim.unpackTable, nested(1000)))
  )");
  w.world().Start();
  ASSERT_EQ(w.log.size(), 2u);
  EXPECT_CONTAINS(w.log[0],
                  "[bot#0] 32\tfalse\tsim.unpackTable: the packed table is nested more than 32 "
                  "levels deep");
  EXPECT_CONTAINS(w.log[1], "nested more than 32 levels deep");
}

TEST(ScriptControlTest, StringSignalsKeepEveryByte) {
  ScriptWorld w;
  w.AddRobot("bot#0", R"(
    function sysCall_actuation()
      local v = sim.getSignal('blob')
      if v then print(#v, v == 'a\0b\0' .. sim.packInt32s({7})) end
      sim.setSignal('blob', 'a\0b\0' .. sim.packInt32s({7}))
    end
  )");
  w.Steps(2);
  EXPECT_EQ(w.log, (std::vector<std::string>{"[bot#0] 8\ttrue"}));
}

// A message is charged to its sender's memory account, with its Lua memory
// (simulation.script_memory_mb), from the step it is sent until the next
// step's messages are delivered: 20 robots sending 100 MiB each per step
// used to exhaust the host's memory. Here the robot holds ~1 MiB of Lua
// memory: two 1 MiB messages fit its 4 MiB in a step; the next step, while
// they are delivered, none does; the step after, two again.
TEST(ScriptControlTest, MessagesAreChargedToTheSendersMemoryUntilDelivered) {
  WorldSettings settings;
  settings.script_memory_limit = 4 << 20;
  ScriptWorld w(1, settings);
  w.AddRobot("bot#0", R"(
    function sysCall_actuation()
      local n = 0
      while sim.receiveMessage() do n = n + 1 end
      local m = string.rep('x', 1 << 20)
      local sent, ok, e = 0, true, nil
      while ok and sent < 10 do
        ok, e = pcall(sim.sendRangeMessage, m, 5)
        if ok then sent = sent + 1 end
      end
      print(n, sent, e)
      ok, e = pcall(sim.sendGlobalMessage, m)  -- the same count for every scope
      print(ok, e)
    end
  )");
  w.AddRobot("bot#1", "", 1, 0);
  const ObjectId listener = w.scene().FindObject("/bot#1/body");
  w.scene().AttachScript(listener, Source("scripts/listener.lua", R"(
    function sysCall_actuation()
      local n = 0
      while sim.receiveMessage() do n = n + 1 end
      if n > 0 then print('received', n) end
    end
  )"));
  w.Steps(3);
  const std::string limit =
      "the message would take the scripts past 4 MiB (1 MiB of Lua memory and 2 MiB of data the "
      "sim.* calls keep for them: signals, custom data, messages, prints, metrics; "
      "simulation.script_memory_mb; raise it if the data is real)";
  ASSERT_EQ(w.log.size(), 7u);
  EXPECT_EQ(w.log[0], "[bot#0] 0\t2\tsim.sendRangeMessage: " + limit);
  EXPECT_EQ(w.log[1], "[bot#0] false\tsim.sendGlobalMessage: " + limit);
  EXPECT_EQ(w.log[2], "[bot#0] 0\t0\tsim.sendRangeMessage: " + limit);
  EXPECT_EQ(w.log[4], "[bot#1] received\t2");
  EXPECT_EQ(w.log[5], "[bot#0] 0\t2\tsim.sendRangeMessage: " + limit);
  // 0: no limit.
  settings.script_memory_limit = 0;
  ScriptWorld u(1, settings);
  u.AddRobot("bot#0", R"(
    function sysCall_actuation()
      local m = string.rep('x', 1 << 20)
      for i = 1, 20 do sim.sendGlobalMessage(m) end
    end
  )");
  EXPECT_EQ(ErrorOf([&] { u.Steps(2); }), "");
}

}  // namespace
}  // namespace swarmsim
