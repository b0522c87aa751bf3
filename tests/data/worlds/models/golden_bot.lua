-- Drives the joints, toggles the paint nozzle and rescales the robot at run
-- time, so that every type's run-time path reaches the state hash.
local pen, eye, cell, base
local step = 0

function sysCall_init()
  base = sim.getObject('.')
  pen = sim.getObject('./pen')
  eye = sim.getObject('./eye')
  cell = sim.getObject('./load_cell')
end

function sysCall_actuation()
  step = step + 1
  local detected, distance = sim.readProximitySensor(eye)
  local state, force = sim.readForceSensor(cell)
  sim.setPaintNozzle(pen, step % 20 < 10, {0.1, 0.1 * (step % 7), 0.5})
  if step == 50 and sim.getRobotIndex() % 2 == 0 then sim.setObjectSizeFactor(base, 1.2) end
  sim.recordMetric('seen', detected == 1 and distance or -1)
  sim.recordMetric('force', state & 1 ~= 0 and force[3] or 0)
end
