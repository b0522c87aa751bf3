-- Nest finding by ground sensors (worlds/ground_nest.yaml): wander (drive
-- straight, turn away from what the proximity ring sees as the diffusion
-- controller does, and now and then turn on the spot for a random while,
-- drawn from the robot's own stream sim.random(), so that straight paths
-- between walls do not repeat for ever) until the 4 motor ground sensors have all read the
-- black nest drawn on the floor for `settle_steps` steps in a row (so that
-- robots go on into the nest instead of walling its edge); then stop for
-- good and turn the LED red.
--
-- Parameters (sim.getParam): wheel_speed (m/s), wheel_radius (m), nest_grey
-- (a grey level: all 4 sensors below it is the nest), settle_steps.

local RANGE = 0.1  -- m, the proximity sensors' range

local atan, sqrt = math.atan, math.sqrt
local readProximitySensors = sim.readProximitySensors
local readGroundSensors = sim.readGroundSensors
local setJointTargetVelocity = sim.setJointTargetVelocity

local left_motor, right_motor, led
local prox, distances = {}, {}
local ground, greys = {}, {}
local cos_a, sin_a = {}, {}
local wheel_speed, nest_grey, settle_steps
local on_nest = 0  -- steps in a row with every ground sensor on the nest
local turn_steps, turn_left = 0, true  -- a random turn in progress
local home = false
local steps = 0

function sysCall_init()
  wheel_speed = sim.getParam('wheel_speed', 0.05) / sim.getParam('wheel_radius', 0.029)
  nest_grey = sim.getParam('nest_grey', 0.25)
  settle_steps = sim.getParam('settle_steps', 30)
  left_motor = sim.getObject('./leftMotor')
  right_motor = sim.getObject('./rightMotor')
  led = sim.getObject('./led')
  for i = 0, 23 do
    prox[i + 1] = sim.getObject('./prox[' .. i .. ']')
    cos_a[i + 1], sin_a[i + 1] = math.cos(2 * math.pi * i / 24), math.sin(2 * math.pi * i / 24)
  end
  for i = 0, 3 do ground[i + 1] = sim.getObject('./ground[' .. i .. ']') end
end

function sysCall_actuation()
  if not home then
    -- On the nest when every ground sensor reads it (one call reads the 4).
    readGroundSensors(ground, greys)
    local all_dark = true
    for i = 1, #greys do
      if greys[i] >= nest_grey then all_dark = false end
    end
    on_nest = all_dark and on_nest + 1 or 0
    home = on_nest >= settle_steps
    if home then
      sim.setLedColor(led, {1, 0, 0})
      sim.recordMetric('arrival_time', sim.getSimulationTime())
    end
  end
  if steps % 50 == 0 then sim.recordMetric('home', home and 1 or 0) end
  steps = steps + 1
  if home then
    setJointTargetVelocity(left_motor, 0)
    setJointTargetVelocity(right_motor, 0)
    return
  end
  -- A random turn: started with probability 0.005 a step, 5 to 25 steps long.
  if turn_steps == 0 and sim.random() < 0.005 then
    turn_steps = 5 + math.floor(sim.random() * 21)
    turn_left = sim.random() < 0.5
  end
  if turn_steps > 0 then
    turn_steps = turn_steps - 1
    setJointTargetVelocity(left_motor, turn_left and -wheel_speed or wheel_speed)
    setJointTargetVelocity(right_motor, turn_left and wheel_speed or -wheel_speed)
    return
  end
  local x, y = 0, 0
  if readProximitySensors(prox, distances) > 0 then
    for i = 1, #prox do
      local d = distances[i]
      if d >= 0 then
        local value = 1 - d / RANGE
        x, y = x + value * cos_a[i], y + value * sin_a[i]
      end
    end
  end
  local angle = atan(y, x)
  local left, right = wheel_speed, wheel_speed
  if not (math.abs(angle) <= math.rad(7.5) and sqrt(x * x + y * y) < 0.1) then
    if angle > 0 then right = 0 else left = 0 end
  end
  setJointTargetVelocity(left_motor, left)
  setJointTargetVelocity(right_motor, right)
end
