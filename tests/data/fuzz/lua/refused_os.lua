-- Seed: a call the sandbox refuses, inside a coroutine under pcall.
function sysCall_init()
  local co = coroutine.wrap(function() print(pcall(function() return os.execute('true') end)) end)
  print(pcall(co))
  sim.recordMetric('after', 1)
end
