-- Prints the beacon this script is attached to, as the example plugin's
-- sim.readBeacon reads it ({radius, strength}; the radius scales with the
-- post's model).
function sysCall_init()
  local beacon = sim.readBeacon(sim.getObject('.'))
  print(string.format('beacon radius %.2f m, strength %g', beacon[1], beacon[2]))
end
