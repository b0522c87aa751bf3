function sysCall_actuation()
  if sim.getSimulationTime() > 0.45 then
    local speed = nil
    return speed * 2   -- line 4: arithmetic on nil
  end
end
