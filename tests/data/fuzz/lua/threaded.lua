-- Seed: a threaded script (sysCall_thread) with nested coroutines and pcall.
function sysCall_thread()
  local motor = sim.getObject('./leftMotor')
  sim.setThreadSwitchTiming(1)
  local co = coroutine.create(function(a)
    local inner = coroutine.wrap(function() coroutine.yield(a + 1) end)
    coroutine.yield(inner())
    return pcall(error, {code = 1})
  end)
  print(coroutine.resume(co, 1))
  print(coroutine.resume(co))
  for i = 1, 3 do
    sim.setJointTargetVelocity(motor, i)
    sim.step()
  end
  while true do sim.switchThread() end
end
