-- Main script of the flocking world: the default step, plus two swarm
-- metrics every `metric_every` steps (metrics.csv):
--   alignment: |mean of the robots' heading unit vectors| (0: headings
--              spread out, 1: all robots head the same way);
--   cohesion:  mean distance (m) from each robot to the swarm's centroid.

local robots, every, step = {}, 10, 0

function sysCall_init()
  every = sim.getParam('metric_every', 10)
  for i = 0, sim.getParam('robots') - 1 do
    robots[#robots + 1] = sim.getObject('/flocker#' .. i)
  end
end

local function record()
  local c, s, mx, my = 0, 0, 0, 0
  local p = {}
  for i, h in ipairs(robots) do
    local yaw = sim.getObjectOrientation(h)[3]
    c, s = c + math.cos(yaw), s + math.sin(yaw)
    p[i] = sim.getObjectPosition(h)
    mx, my = mx + p[i][1], my + p[i][2]
  end
  local n = #robots
  mx, my = mx / n, my / n
  local spread = 0
  for i = 1, n do spread = spread + math.sqrt((p[i][1] - mx) ^ 2 + (p[i][2] - my) ^ 2) end
  sim.recordMetric('alignment', math.sqrt(c * c + s * s) / n)
  sim.recordMetric('cohesion', spread / n)
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
