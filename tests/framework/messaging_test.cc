// Delivery of messages and signals (framework/messaging.cc): each scope
// reaches exactly its receivers at the next step, in sender order, range
// messages with exact distance and bearing, whatever the thread count.
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

// A robot that sends what `send` says in step 0 and prints everything it receives.
std::string Receiver(const std::string& send) {
  return R"(
    function sysCall_actuation()
      if sim.getSimulationTime() == 0 then )" +
         send + R"( end
      while true do
        local data, sender, distance, bearing = sim.receiveMessage()
        if not data then break end
        print(data, sim.getObjectName(sim.getObjectParent(sender)),
              distance and string.format('%.2f %.2f', distance, bearing) or '-')
      end
    end
  )";
}

TEST(ScriptControlTest, MessageScopesReachExactlyTheirReceiversAtTheNextStep) {
  ScriptWorld w;
  const ObjectId a = w.AddRobot("a", Receiver("sim.sendGlobalMessage('g')"), 0, 0);
  // b's body script sends local + direct; its eye script receives.
  const ObjectId b = w.AddRobot("b", Receiver(R"(
      sim.sendLocalMessage('l')
      sim.sendDirectMessage(sim.getObject('/a/body'), 'd'))"),
                                1, 0, M_PI / 2);
  const ObjectId eye = w.scene().AddDummy("eye", b, {});
  w.scene().AttachScript(eye, Source("scripts/eye.lua", Receiver("")));
  w.AddRobot("c", Receiver("sim.sendRangeMessage('r', 1.5)"), 0, 1);
  (void)a;
  w.Steps(1);
  EXPECT_TRUE(w.log.empty());  // nothing delivered in the step it was sent
  w.Steps(1);
  // Sender-handle order (a's body, b's body, c's body); b faces +y, so a
  // (at -x from b) is at bearing +pi/2 in b's frame.
  const std::vector<std::string> expected = {
      "[a] d\tb\t1.00 0.00", "[a] r\tc\t1.00 1.57", "[b] g\ta\t1.00 1.57", "[b] r\tc\t1.41 0.79",
      "[b] g\ta\t1.00 1.57", "[b] l\tb\t0.00 0.00", "[b] r\tc\t1.41 0.79", "[c] g\ta\t1.00 -1.57"};
  EXPECT_EQ(w.log, expected);
  // Sent once, delivered once: the following steps, with no messages at all,
  // deliver nothing (the inboxes of the last round are emptied).
  w.log.clear();
  w.Steps(2);
  EXPECT_TRUE(w.log.empty()) << w.log.front();
}

// Distance and bearing arrive in full double precision: a receiver 1.9 m
// along +y from the sender (both facing +x) gets exactly 1.9 and -pi/2.
TEST(ScriptControlTest, RangeMessageDistanceAndBearingAreExact) {
  ScriptWorld w;
  w.AddRobot("s", "function sysCall_actuation() sim.sendRangeMessage('x', 2) end", 0, 0);
  w.AddRobot("r", R"(
    function sysCall_actuation()
      local data, sender, distance, bearing = sim.receiveMessage()
      if data then print(distance == 1.9, bearing == -math.pi / 2, distance) end
    end)",
             0, 1.9);
  w.Steps(2);
  EXPECT_EQ(w.log, std::vector<std::string>{"[r] true\ttrue\t1.9"});
}

TEST(ScriptControlTest, RangeMessagingIsTheSameAtAnyThreadCount) {
  auto run = [](int threads) {
    ScriptWorld w(threads);
    for (int r = 0; r < 300; ++r)
      w.AddRobot("bot#" + std::to_string(r), R"(
        function sysCall_actuation()
          local sum = 0
          while true do
            local data, sender, d, b = sim.receiveMessage()
            if not data then break end
            sum = sum * 1.0001 + sim.unpackFloats(data)[1] + d + b
          end
          sim.recordMetric('sum', sum)
          sim.sendRangeMessage(sim.packFloats({sim.random()}), 0.5)
        end
      )",
                 (r % 20) * 0.3, (r / 20) * 0.3);
    w.Steps(3);
    std::vector<double> v;
    for (const MetricSample& m : w.world().TakeMetrics()) v.push_back(m.value);
    return v;
  };
  const std::vector<double> one = run(1);
  EXPECT_EQ(one, run(2));
  EXPECT_EQ(one, run(4));
}

TEST(ScriptControlTest, SignalsAreVisibleFromTheNextStepAndTheLastRobotWins) {
  ScriptWorld w(2);
  for (int r = 0; r < 40; ++r)
    w.AddRobot("bot#" + std::to_string(r), R"(
      function sysCall_actuation()
        if sim.getRobotIndex() == 0 then print(sim.getSignal('who'), sim.getSignal('flag')) end
        sim.setSignal('who', sim.getRobotIndex())
        if sim.getSimulationTime() > 0.05 then sim.clearSignal('flag') else sim.setSignal('flag', true) end
      end
    )",
               r);
  w.Steps(3);
  EXPECT_EQ(w.log,
            (std::vector<std::string>{"[bot#0] nil\tnil", "[bot#0] 39\ttrue", "[bot#0] 39\tnil"}));
}

}  // namespace
}  // namespace swarmsim
