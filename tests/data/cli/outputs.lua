local slow = sim.getParam('slow') == 1
function sysCall_actuation()
  if slow then
    if sim.getRobotIndex() == 0 then
      for i = 1, 20000000 do end  -- tens of ms a step: a few rows a second on any machine
      sim.recordMetric('t', sim.getSimulationTime())
    end
    return
  end
  sim.recordMetric('a,b"c', sim.getSimulationTime())
  sim.recordMetric('undefined', 0 / 0)
  if sim.getRobotIndex() == 1 and sim.getSimulationTime() > 0.25 then
    error('robot one gives up')  -- line 13
  end
end
