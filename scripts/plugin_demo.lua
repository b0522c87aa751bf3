-- The paper's plugin example (V-REP §3.3): a threaded script hands the
-- low-level driving to a plugin command, sim.robotMoveAndAvoidObstacles
-- (modules/plugins/example), and only sequences legs: drive and avoid for
-- `leg` seconds, pause one second, again. After each leg it records how far
-- the robot is from where it started (metric `distance`, m).

local self, start

function sysCall_init()
  self = sim.getObject('.')
  start = sim.getObjectPosition(self)
end

function sysCall_thread()
  local leg = sim.getParam('leg', 5)
  while true do
    sim.robotMoveAndAvoidObstacles(leg)
    sim.waitUntil(function() return not sim.robotIsMoving() end)
    local p = sim.getObjectPosition(self)
    sim.recordMetric('distance', math.sqrt((p[1] - start[1]) ^ 2 + (p[2] - start[2]) ^ 2))
    sim.wait(1)
  end
end
