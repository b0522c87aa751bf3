-- Main script of the firefly world: the default step, plus the swarm's
-- phase spread, 1 - |mean(exp(2 pi i phase))| (0: all in phase, ~1: spread
-- out), read from the robots' signals at step 0 (the random initial phases,
-- before any robot has run) and then every `metric_every` steps.

local robots, every, step = 0, 10, 0

function sysCall_init()
  robots = sim.getParam('robots')
  every = sim.getParam('metric_every', 10)
end

local function record()
  local c, s, n = 0, 0, 0
  for i = 0, robots - 1 do
    local phase = sim.getSignal('phase_' .. i)
    if phase then
      c, s, n = c + math.cos(2 * math.pi * phase), s + math.sin(2 * math.pi * phase), n + 1
    end
  end
  if n > 0 then sim.recordMetric('phase_spread', 1 - math.sqrt(c * c + s * s) / n) end
end

function sysCall_step()
  if step == 0 then record() end
  sim.handleSensing()
  sim.handleChildScripts()
  sim.handleActuation()
  sim.handleDynamics()
  step = step + 1
  if step % every == 0 then record() end
end
