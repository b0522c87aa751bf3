-- Main script of worlds/experiments/best_of_n.yaml: the default step, then
-- the swarm's opinions read off the Kilobots' LEDs (worlds/kilobot/best_of_n.c
-- shows option A red, option B blue). Metrics every 32 steps (~1 s):
-- opinion_a and opinion_b, the fractions of robots holding each option.

local leds = {}
local step = 0

function sysCall_init()
  for _, robot in ipairs(sim.getRobots()) do
    leds[#leds + 1] = sim.getObject('/' .. sim.getObjectName(robot) .. '/led')
  end
end

function sysCall_step()
  sim.handleSensing()
  sim.handleChildScripts()
  sim.handleActuation()
  sim.handleDynamics()
  step = step + 1
  if step % 32 ~= 0 then return end
  local a, b = 0, 0
  for _, led in ipairs(leds) do
    local color, on = sim.getLedColor(led)
    if on and color[1] > color[3] then a = a + 1 end
    if on and color[3] > color[1] then b = b + 1 end
  end
  sim.recordMetric('opinion_a', a / #leds)
  sim.recordMetric('opinion_b', b / #leds)
end
