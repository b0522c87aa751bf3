-- Turns the mount (the narrow camera is noisy), recolours and switches the LEDs, rescales every other
-- robot at run time, and records what the cameras see, so that the blob
-- module's run-time paths reach the state hash.
local base, mount, inner, tip, omni, narrow
local step = 0

function sysCall_init()
  base = sim.getObject('.')
  mount = sim.getObject('./mount')
  inner = sim.getObject('./inner')
  tip = sim.getObject('./tip')
  omni = sim.getObject('./omni')
  narrow = sim.getObject('./narrow')
  sim.setJointTargetVelocity(mount, 0.5 + 0.2 * sim.getRobotIndex())
end

function sysCall_actuation()
  step = step + 1
  local i = sim.getRobotIndex()
  if step % 20 == 0 then
    sim.setLedColor(tip, {(step / 20 + i) % 2, 0.5, 1 - (step / 20) % 2})
  end
  sim.setLedOn(inner, (step + i) % 30 < 20)
  if step == 50 and i % 2 == 0 then sim.setObjectSizeFactor(base, 1.2) end
  local sum = 0
  for _, b in ipairs(sim.readBlobCamera(omni)) do sum = sum + b.bearing + b.distance end
  sim.recordMetric('omni', sum)
  local seen = sim.readBlobCamera(narrow)
  sim.recordMetric('narrow', #seen > 0 and seen[1].bearing + seen[1].distance or 0)
end
