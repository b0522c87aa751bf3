function sysCall_init()
  left = sim.getObject('./leftMotor')
  right = sim.getObject('./rightMotor')
end

function sysCall_actuation()
  local w = sim.getParam('speed') / 0.02
  sim.setJointTargetVelocity(left, w)
  sim.setJointTargetVelocity(right, w)
  sim.recordMetric('x', sim.getObjectPosition(sim.getObject('.'))[1])
end
