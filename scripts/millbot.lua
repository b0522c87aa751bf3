-- A millbot (worlds/models/millbot.yaml): the slide pushes the mill `depth`
-- m forward at `speed` m/s (the joint's max_velocity); once there, the
-- mill is switched off and the slide draws back. Records `milled`, the
-- volume its mill has removed so far (m^3, sim.readMill), every step.
local slide, mill
local depth

function sysCall_init()
  slide = sim.getObject('./slide')
  mill = sim.getObject('./mill')
  depth = sim.getParam('depth', 0.25)
  sim.setJointTargetPosition(slide, depth)
end

function sysCall_actuation()
  local _, total = sim.readMill(mill)
  sim.recordMetric('milled', total)
  if sim.getJointPosition(slide) >= depth - 1e-9 then
    sim.setMillEnabled(mill, false)
    sim.setJointTargetPosition(slide, 0)
  end
end
