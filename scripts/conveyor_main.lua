-- Main script of worlds/conveyor.yaml: the default step, then a crate
-- dropped at the belt's start every `spawn_period` seconds (a copy of the
-- crate waiting on the shelf, 10 cm above the belt), `boxes` in all.
-- metrics.csv: boxes_spawned.

local template
local boxes, period = 6, 5
local spawned = 0
local DROP = {0.45, 1.55}  -- x, y over the belt's start

function sysCall_init()
  boxes = sim.getParam('boxes')
  period = sim.getParam('spawn_period')
  template = sim.getObject('/crate#1')
end

function sysCall_step()
  sim.handleSensing()
  sim.handleChildScripts()
  sim.handleActuation()
  sim.handleDynamics()
  -- Copies are made when sysCall_step returns (sim.copyModel queues them).
  if spawned < boxes and sim.getSimulationTime() >= spawned * period then
    sim.copyModel(template, {DROP[1], DROP[2], 0})
    spawned = spawned + 1
  end
  sim.recordMetric('boxes_spawned', spawned)
end
