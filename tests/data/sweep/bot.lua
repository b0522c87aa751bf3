-- A tiny robot for sweep tests: drives straight; can fail or be slow on purpose.
function sysCall_init()
  left = sim.getObject('./leftMotor')
  right = sim.getObject('./rightMotor')
end

function sysCall_actuation()
  local w = sim.getParam('speed') / 0.02
  sim.setJointTargetVelocity(left, w)
  sim.setJointTargetVelocity(right, w)
  local fail_at = sim.getParam('fail_at')
  if fail_at >= 0 and sim.getSimulationTime() >= fail_at then
    error('planned failure')  -- line 13
  end
  local x = 0
  for i = 1, sim.getParam('spin') do x = x + i end  -- busy work: a slow run
  sim.recordMetric('x', sim.getObjectPosition(sim.getObject('.'))[1])
end
