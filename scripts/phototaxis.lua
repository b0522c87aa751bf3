-- Phototaxis (worlds/phototaxis.yaml), after ARGoS's foot-bot phototaxis
-- example: steer toward the light the 8 light sensors read, and turn away
-- from what the proximity ring senses close by.
--
-- The light's direction is the sum of the sensors' axes weighted by their
-- readings (each reads intensity / d^2 falling with the angle off its
-- axis: modules/light). Every 10 steps the robot records its distance to
-- the object `/lamp` in the plane (metric light_distance), so metrics.csv
-- shows the swarm closing in.
--
-- Parameters (sim.getParam): wheel_speed (m/s), wheel_radius (m), delta
-- (proximity reading above which an obstacle counts as close).

local PROX_RANGE = 0.1  -- m, the proximity ring's range
local atan, abs, sqrt = math.atan, math.abs, math.sqrt
local readLightSensors = sim.readLightSensors
local readProximitySensors = sim.readProximitySensors
local setJointTargetVelocity = sim.setJointTargetVelocity

local left_motor, right_motor, lamp
local lights, light_values = {}, {}
local light_cos, light_sin = {}, {}
local prox, prox_values = {}, {}
local prox_cos, prox_sin = {}, {}
local speed, delta
local steps = 0

function sysCall_init()
  speed = sim.getParam('wheel_speed', 0.1) / sim.getParam('wheel_radius', 0.029)
  delta = sim.getParam('delta', 0.1)
  left_motor = sim.getObject('./leftMotor')
  right_motor = sim.getObject('./rightMotor')
  lamp = sim.getObject('/lamp')
  for i = 0, 7 do
    lights[i + 1] = sim.getObject('./light[' .. i .. ']')
    light_cos[i + 1], light_sin[i + 1] = math.cos(math.pi * i / 4), math.sin(math.pi * i / 4)
  end
  for i = 0, 23 do
    prox[i + 1] = sim.getObject('./prox[' .. i .. ']')
    prox_cos[i + 1], prox_sin[i + 1] = math.cos(math.pi * i / 12), math.sin(math.pi * i / 12)
  end
end

function sysCall_actuation()
  -- What is close: the readings as vectors toward what each sensor sees.
  local ox, oy = 0, 0
  if readProximitySensors(prox, prox_values) > 0 then
    for i = 1, #prox do
      local d = prox_values[i]
      if d >= 0 then
        local v = 1 - d / PROX_RANGE
        ox, oy = ox + v * prox_cos[i], oy + v * prox_sin[i]
      end
    end
  end
  -- Where the light is: the readings as vectors along the sensors' axes.
  readLightSensors(lights, light_values)
  local lx, ly = 0, 0
  for i = 1, #lights do
    lx, ly = lx + light_values[i] * light_cos[i], ly + light_values[i] * light_sin[i]
  end
  local left, right
  if sqrt(ox * ox + oy * oy) >= delta and abs(atan(oy, ox)) < math.pi / 2 then
    -- Something ahead: turn away from it on the spot.
    if atan(oy, ox) > 0 then left, right = speed, -speed else left, right = -speed, speed end
  elseif lx == 0 and ly == 0 then
    left, right = speed, speed  -- no light seen (in a shadow): straight on
  else
    -- Toward the light: turn in proportion to its bearing, slower when it
    -- is to the side, on the spot when it is behind.
    local bearing = atan(ly, lx)
    local turn = bearing / (math.pi / 2)
    if turn > 1 then turn = 1 elseif turn < -1 then turn = -1 end
    left, right = speed * (1 - 2 * turn), speed * (1 + 2 * turn)
    if left > speed then left = speed elseif left < -speed then left = -speed end
    if right > speed then right = speed elseif right < -speed then right = -speed end
  end
  setJointTargetVelocity(left_motor, left)
  setJointTargetVelocity(right_motor, right)
  if steps % 10 == 0 then
    local p = sim.getObjectPosition(sim.getObject('.'))
    local q = sim.getObjectPosition(lamp)
    sim.recordMetric('light_distance', sqrt((p[1] - q[1]) ^ 2 + (p[2] - q[2]) ^ 2))
  end
  steps = steps + 1
end
