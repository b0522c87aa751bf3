-- Lowers the mills into the block, switches one off and back on, and
-- rescales every other robot at run time, so that the mill module's
-- run-time paths reach the state hash.
local base, slide, saw
local step = 0

function sysCall_init()
  base = sim.getObject('.')
  slide = sim.getObject('./slide')
  saw = sim.getObject('./saw')
  sim.setJointTargetPosition(slide, 0.1)
end

function sysCall_actuation()
  step = step + 1
  sim.setMillEnabled(saw, step < 60 or step > 90)
  if step == 50 and sim.getRobotIndex() % 2 == 0 then sim.setObjectSizeFactor(base, 1.2) end
  local removed, total = sim.readMill(saw)
  local left = sim.readCuttable(sim.getObject('./stock'))
  sim.recordMetric('saw', total)
  sim.recordMetric('left', left)
end
