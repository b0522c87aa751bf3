-- A forager (worlds/experiments/foraging.yaml: the complete foot-bot of
-- models/footbot.yaml, its beacon, 24 light and 4 motor ground sensors), after ARGoS's
-- foot-bot foraging example. Two states:
--   exploring (LED green): drive straight, turning now and then at random,
--     and away from the light while on the nest, so that the robots spread
--     over the arena where the items lie;
--   carrying (LED yellow): steer toward the light (the lamp hangs over the
--     nest) by the 8 light sensors, and drop the item as soon as the motor
--     ground sensors read the nest (black: grey level below 0.2).
-- Both turn away from whatever the proximity ring senses close by.
-- The world's main script (scripts/foraging_main.lua, the "loop functions")
-- hands an item to a robot that drives over one, with the message 'pick';
-- the robot tells it of each drop by its signal 'drops<handle>' (a count).

local PROX_RANGE = 0.1  -- m
local NEST_GREY = 0.2   -- a ground reading below this is the nest
local atan, abs, sqrt = math.atan, math.abs, math.sqrt

local left_motor, right_motor, led, me
local lights, light_values, light_cos, light_sin = {}, {}, {}, {}
local prox, prox_values, prox_cos, prox_sin = {}, {}, {}, {}
local ground, ground_values = {}, {}
local speed, delta
local carrying, drops = false, 0
local turn_left = 0  -- steps left in a random turn (negative: to the right)

function sysCall_init()
  speed = sim.getParam('wheel_speed', 0.1) / sim.getParam('wheel_radius', 0.029)
  delta = sim.getParam('delta', 0.1)
  me = sim.getObject(':')
  left_motor = sim.getObject('./leftMotor')
  right_motor = sim.getObject('./rightMotor')
  led = sim.getObject('./beacon')
  sim.setLedOn(led, true)
  -- The complete foot-bot's 24 light sensors, from 7.5 deg every 15 deg.
  for i = 0, 23 do
    lights[i + 1] = sim.getObject('./light[' .. i .. ']')
    local a = math.rad(7.5 + 15 * i)
    light_cos[i + 1], light_sin[i + 1] = math.cos(a), math.sin(a)
  end
  for i = 0, 23 do
    prox[i + 1] = sim.getObject('./prox[' .. i .. ']')
    prox_cos[i + 1], prox_sin[i + 1] = math.cos(math.pi * i / 12), math.sin(math.pi * i / 12)
  end
  for i = 0, 3 do ground[i + 1] = sim.getObject('./motor_ground[' .. i .. ']') end
end

local function on_nest()
  sim.readGroundSensors(ground, ground_values)
  for i = 1, #ground do
    if ground_values[i] < NEST_GREY then return true end
  end
  return false
end

-- Wheel speeds that steer toward bearing b (rad, 0 ahead, + to the left).
local function steer(b)
  local turn = b / (math.pi / 2)
  if turn > 1 then turn = 1 elseif turn < -1 then turn = -1 end
  local l, r = speed * (1 - 2 * turn), speed * (1 + 2 * turn)
  if l > speed then l = speed elseif l < -speed then l = -speed end
  if r > speed then r = speed elseif r < -speed then r = -speed end
  return l, r
end

function sysCall_actuation()
  while true do
    local data = sim.receiveMessage()
    if data == nil then break end
    if data == 'pick' then carrying = true end
  end
  local nest = on_nest()
  if carrying and nest then
    carrying = false
    drops = drops + 1
    sim.setSignal('drops' .. me, drops)
  end
  sim.setLedColor(led, carrying and {1, 0.8, 0} or {0, 1, 0})
  -- What is close: the readings as vectors toward what each sensor sees.
  local ox, oy = 0, 0
  if sim.readProximitySensors(prox, prox_values) > 0 then
    for i = 1, #prox do
      local d = prox_values[i]
      if d >= 0 then
        local v = 1 - d / PROX_RANGE
        ox, oy = ox + v * prox_cos[i], oy + v * prox_sin[i]
      end
    end
  end
  -- Where the light is: the readings as vectors along the sensors' axes.
  sim.readLightSensors(lights, light_values)
  local lx, ly = 0, 0
  for i = 1, #lights do
    lx, ly = lx + light_values[i] * light_cos[i], ly + light_values[i] * light_sin[i]
  end
  local left, right
  if sqrt(ox * ox + oy * oy) >= delta and abs(atan(oy, ox)) < math.pi / 2 then
    if atan(oy, ox) > 0 then left, right = speed, -speed else left, right = -speed, speed end
  elseif carrying and (lx ~= 0 or ly ~= 0) then
    left, right = steer(atan(ly, lx))
  else
    if turn_left == 0 and sim.random() < 0.02 then
      turn_left = math.floor(5 + 10 * sim.random()) * (sim.random() < 0.5 and 1 or -1)
    end
    if turn_left > 0 then
      left, right, turn_left = -speed, speed, turn_left - 1
    elseif turn_left < 0 then
      left, right, turn_left = speed, -speed, turn_left + 1
    elseif nest and (lx ~= 0 or ly ~= 0) then
      left, right = steer(atan(-ly, -lx))  -- out of the nest, away from the light
    else
      left, right = speed, speed
    end
  end
  sim.setJointTargetVelocity(left_motor, left)
  sim.setJointTargetVelocity(right_motor, right)
end
