-- Main script of the respawn world: the default step, then the population
-- kept at `robots`. The robots' removals (their own sim.removeModel calls)
-- are applied by sim.handleActuation(); then each missing robot is replaced
-- by a copy of a live one (drawn with the scene's random stream) placed at a
-- free spot of the arena, at a random heading. Those copies are applied when
-- sysCall_step returns, before the record phase: their sysCall_init runs
-- then, their first sysCall_actuation in the next step.

local target, every, half, step = 100, 10, 1, 0
local alive, failed, spawned = 0, 0, 0  -- robots after the last step's copies; totals
local CLEARANCE = 0.25  -- m between a new robot's centre and any other's

function sysCall_init()
  target = sim.getParam('robots')
  every = sim.getParam('metric_every', 10)
  half = math.sqrt(target / sim.getParam('density')) / 2 - 0.15
  alive = #sim.getRobots()
end

-- A spot at least CLEARANCE from every robot in `robots` and every spot
-- already taken this step (20 tries), or nil.
local function free_spot(robots, taken)
  for _ = 1, 20 do
    local x, y = (2 * sim.random() - 1) * half, (2 * sim.random() - 1) * half
    local ok = true
    for _, p in ipairs(taken) do
      if (p[1] - x) ^ 2 + (p[2] - y) ^ 2 < CLEARANCE ^ 2 then ok = false break end
    end
    for i = 1, #robots do
      if not ok then break end
      local p = sim.getObjectPosition(robots[i])
      if (p[1] - x) ^ 2 + (p[2] - y) ^ 2 < CLEARANCE ^ 2 then ok = false end
    end
    if ok then return x, y end
  end
end

local function respawn()
  local robots = sim.getRobots()
  failed = failed + alive - #robots  -- removed by sim.handleActuation()
  local taken = {}
  for _ = #robots + 1, target do
    if #robots == 0 then break end  -- nothing left to copy
    local source = robots[1 + math.floor(sim.random() * #robots)]
    local x, y = free_spot(robots, taken)
    if x then
      sim.copyModel(source, {x, y, (2 * sim.random() - 1) * math.pi})
      taken[#taken + 1] = {x, y}
      spawned = spawned + 1
    end
  end
  return #robots + #taken
end

function sysCall_step()
  sim.handleSensing()
  sim.handleChildScripts()
  sim.handleActuation()
  sim.handleDynamics()
  alive = respawn()
  step = step + 1
  if step % every == 0 then
    sim.recordMetric('robots_alive', alive)
    sim.recordMetric('robots_failed', failed)
    sim.recordMetric('robots_spawned', spawned)
  end
end
