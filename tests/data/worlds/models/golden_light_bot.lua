-- Turns the mount, switches the robot's own lamp, rescales every other
-- robot at run time, and records what the sensors read, so that the light
-- module's run-time paths reach the state hash.
local base, mount, glow, narrow, wide
local ring, values = {}, {}
local step = 0

function sysCall_init()
  base = sim.getObject('.')
  mount = sim.getObject('./mount')
  glow = sim.getObject('./glow')
  narrow = sim.getObject('./narrow')
  wide = sim.getObject('./wide')
  for i = 0, 5 do ring[i + 1] = sim.getObject('./ring[' .. i .. ']') end
  sim.setJointTargetVelocity(mount, 0.5 + 0.2 * sim.getRobotIndex())
end

function sysCall_actuation()
  step = step + 1
  local i = sim.getRobotIndex()
  sim.setLightSourceOn(glow, (step + i) % 30 < 20)
  if step == 50 and i % 2 == 0 then sim.setObjectSizeFactor(base, 1.2) end
  local sum = 0
  for _, v in ipairs(sim.readLightSensors(ring, values)) do sum = sum + v end
  sim.recordMetric('ring', sum)
  sim.recordMetric('narrow', sim.readLightSensor(narrow))
  sim.recordMetric('wide', sim.readLightSensor(wide))
end
