-- A plugin sensor type in use: the example plugin's `light` sensors
-- (modules/plugins/example) read {intensity, distance} of the light at the
-- world parameters light_x/y/z in the sense phase; sim.readPluginSensor
-- gives the reading (nil before the first sense). The puck moves up the
-- gradient its four eyes see. Metrics: `intensity` (mean of the eyes) and
-- `reading_error`, the largest difference from the reading computed here.

local self, eyes, light, power

function sysCall_init()
  self = sim.getObject('.')
  eyes = {}
  for _, name in ipairs({'front', 'back', 'left', 'right'}) do
    eyes[name] = sim.getObject('./' .. name)
  end
  light = {sim.getParam('light_x', 0), sim.getParam('light_y', 0), sim.getParam('light_z', 1)}
  power = sim.getParam('light_power', 1)
  sim.recordMetric('unsensed', sim.readPluginSensor(eyes.front) == nil and 1 or 0)
end

local function expected(h)
  local p = sim.getObjectPosition(h)
  local d = math.sqrt((p[1] - light[1]) ^ 2 + (p[2] - light[2]) ^ 2 + (p[3] - light[3]) ^ 2)
  return power / (1 + d * d), d
end

function sysCall_actuation()
  local reading, error, mean = {}, 0, 0
  for name, h in pairs(eyes) do
    local r = sim.readPluginSensor(h)
    local intensity, distance = expected(h)
    error = math.max(error, math.abs(r[1] - intensity), math.abs(r[2] - distance))
    reading[name] = r[1]
    mean = mean + r[1] / 4
  end
  sim.recordMetric('reading_error', error)
  sim.recordMetric('intensity', mean)
  -- Up the gradient, in world coordinates (whatever the puck's heading).
  local f, b = sim.getObjectPosition(eyes.front), sim.getObjectPosition(eyes.back)
  local l, r = sim.getObjectPosition(eyes.left), sim.getObjectPosition(eyes.right)
  local gx = (f[1] - b[1]) * (reading.front - reading.back) + (l[1] - r[1]) * (reading.left - reading.right)
  local gy = (f[2] - b[2]) * (reading.front - reading.back) + (l[2] - r[2]) * (reading.left - reading.right)
  local n = math.sqrt(gx * gx + gy * gy)
  if n > 0 then
    local step = sim.getParam('speed', 0.05) * sim.getTimeStep()
    local p = sim.getObjectPosition(self)
    sim.setObjectPosition(self, {p[1] + step * gx / n, p[2] + step * gy / n, p[3]})
  end
end
