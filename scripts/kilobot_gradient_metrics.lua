-- Main script of worlds/experiments/gradient_formation.yaml: the default
-- step, then how far the Kilobots' gradient (worlds/kilobot/gradient.c) has
-- formed. Each robot's value is read off its LED (value + 1 in base 4:
-- red ones, green fours, blue sixteens; dark: no value yet) and compared
-- with its hop count from robot 0 over the robots within IR range of each
-- other (the world parameter ir_range), a breadth-first search on their
-- current positions. Metrics every 32 steps (~1 s): gradient_known (the
-- fraction of robots with a value) and gradient_correct (the fraction of the
-- robots robot 0 reaches whose value is their hop count).

local robots, leds = {}, {}
local range
local step = 0

function sysCall_init()
  range = sim.getParam('ir_range')
  for _, robot in ipairs(sim.getRobots()) do
    robots[#robots + 1] = robot
    leds[#leds + 1] = sim.getObject('/' .. sim.getObjectName(robot) .. '/led')
  end
end

local function led_value(led)
  local c, on = sim.getLedColor(led)
  if not on then return nil end
  local code = math.floor(c[1] * 3 + 0.5) + 4 * math.floor(c[2] * 3 + 0.5)
      + 16 * math.floor(c[3] * 3 + 0.5)
  if code == 0 then return nil end
  return code - 1
end

local function hop_counts()
  local p = {}
  for i, robot in ipairs(robots) do p[i] = sim.getObjectPosition(robot) end
  local hops, queue, head = {[1] = 0}, {1}, 1
  while head <= #queue do
    local i = queue[head]
    head = head + 1
    for j = 1, #robots do
      if hops[j] == nil and (p[i][1] - p[j][1]) ^ 2 + (p[i][2] - p[j][2]) ^ 2 <= range ^ 2 then
        hops[j] = hops[i] + 1
        queue[#queue + 1] = j
      end
    end
  end
  return hops
end

function sysCall_step()
  sim.handleSensing()
  sim.handleChildScripts()
  sim.handleActuation()
  sim.handleDynamics()
  step = step + 1
  if step % 32 ~= 0 then return end
  local hops = hop_counts()
  local known, correct, reached = 0, 0, 0
  for i, led in ipairs(leds) do
    local v = led_value(led)
    if v ~= nil then known = known + 1 end
    if hops[i] ~= nil then
      reached = reached + 1
      if v == hops[i] then correct = correct + 1 end
    end
  end
  sim.recordMetric('gradient_known', known / #leds)
  sim.recordMetric('gradient_correct', correct / reached)
end
