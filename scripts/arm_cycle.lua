-- A threaded pick-and-place cycle (sysCall_thread): the script reads like a
-- sequence of moves, each waiting until the mechanism gets there.
--   close the finger, hold, swing to the place angle, open, hold, swing back
-- Each finished cycle is recorded as sim.recordMetric('cycles', n). The start
-- is delayed by a random 0..1 s (sim.random: the robot's own stream) so the
-- copies work out of step. Parameters: shoulder_speed, finger_speed, hold.

local PICK, PLACE = 0, math.pi / 2  -- rad, shoulder angles
local OPEN, CLOSED = 0.04, 0        -- m, finger positions
local shoulder, finger, hold

function sysCall_init()
  shoulder = sim.getObject('./shoulder')
  finger = sim.getObject('./finger')
  hold = sim.getParam('hold')
end

-- Sets a joint's target and waits (one step at a time) until it is reached.
local function move(joint, target)
  sim.setJointTargetPosition(joint, target)
  sim.waitUntil(function() return math.abs(sim.getJointPosition(joint) - target) < 1e-6 end)
end

function sysCall_thread()
  sim.wait(sim.random())
  local cycles = 0
  while true do
    move(finger, CLOSED)
    sim.wait(hold)
    move(shoulder, PLACE)
    move(finger, OPEN)
    sim.wait(hold)
    move(shoulder, PICK)
    cycles = cycles + 1
    sim.recordMetric('cycles', cycles)
  end
end
