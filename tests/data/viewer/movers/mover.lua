-- Slides the robot along +x at its `speed` and records its x.
function sysCall_actuation()
  local self = sim.getObject('.')
  local p = sim.getObjectPosition(self)
  p[1] = p[1] + sim.getParam('speed', 1) * sim.getTimeStep()
  sim.setObjectPosition(self, p)
  sim.recordMetric('x', p[1])
end
