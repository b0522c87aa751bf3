-- Dims the world's lamp step by step and switches it off for a while, and
-- switches the other lamp on, so that the light module's run-time paths
-- reach the state hash.
local step = 0
function sysCall_actuation()
  step = step + 1
  local me = sim.getObject('.')
  sim.setLightSourceIntensity(me, 1 + (step % 7) / 3)
  sim.setLightSourceOn(me, step % 40 < 30)
  if step == 60 then sim.setLightSourceOn(sim.getObject('/dim'), true) end
end
