-- Main script of worlds/experiments/foraging.yaml: the default step, then the
-- "loop functions" of ARGoS's foraging example. Items (/item0 ...) lie on
-- the floor outside the nest; a robot that drives within `pick_radius` of
-- one while carrying nothing takes it (the message 'pick'), and the item
-- reappears at a random spot (the scene's random stream: the same at any
-- thread count). Robots tell of their drops on the nest by their signal
-- 'drops<handle>'. Metrics: items_delivered (total), carrying (robots
-- carrying now), every 10 steps.

local items = {}
local carrying, drops_seen = {}, {}
local delivered, step = 0, 0
local pick_radius, x_min, x_max, half

local function place(item)
  local x = x_min + (x_max - x_min) * sim.random()
  local y = (2 * sim.random() - 1) * half
  sim.setObjectPosition(item, {x, y, 0.01})
end

function sysCall_init()
  pick_radius = sim.getParam('pick_radius', 0.12)
  half = sim.getParam('side') / 2 - 0.2
  x_min, x_max = sim.getParam('items_from_x'), half
  for i = 0, sim.getParam('items') - 1 do
    items[#items + 1] = sim.getObject('/item' .. i)
    place(items[#items])
  end
end

function sysCall_step()
  sim.handleSensing()
  sim.handleChildScripts()
  -- Drops the robots signalled in this pass.
  for _, robot in ipairs(sim.getRobots()) do
    local drops = sim.getSignal('drops' .. robot) or 0
    local seen = drops_seen[robot] or 0
    if drops > seen then
      delivered = delivered + (drops - seen)
      drops_seen[robot] = drops
      carrying[robot] = false
    end
  end
  -- Items taken by robots over them.
  for _, robot in ipairs(sim.getRobots()) do
    if not carrying[robot] then
      local p = sim.getObjectPosition(robot)
      for _, item in ipairs(items) do
        local q = sim.getObjectPosition(item)
        if (p[1] - q[1]) ^ 2 + (p[2] - q[2]) ^ 2 < pick_radius ^ 2 then
          carrying[robot] = true
          sim.sendDirectMessage(robot, 'pick')
          place(item)
          break
        end
      end
    end
  end
  sim.handleActuation()
  sim.handleDynamics()
  step = step + 1
  if step % 10 == 0 then
    local n = 0
    for _, c in pairs(carrying) do if c then n = n + 1 end end
    sim.recordMetric('items_delivered', delivered)
    sim.recordMetric('carrying', n)
  end
end
