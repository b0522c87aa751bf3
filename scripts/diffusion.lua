-- Foot-bot diffusion, after the ARGoS example controller: drive straight,
-- and turn away from whatever the 24 proximity sensors see.
--
-- Attached to the foot-bot's body. Parameters (sim.getParam): wheel_speed
-- (m/s), wheel_radius (m), go_straight_angle_deg, delta; slow_distance (m,
-- default 0: off): half speed while the look-ahead sensor ./front sees
-- something that close (worlds/models/clearbot.yaml's cone).

local RANGE = 0.1  -- m, the proximity sensors' range

-- The library functions of the step, as locals: a global (math.atan) is a
-- lookup in the script's environment, then in the shared globals, then in
-- the library, each a cache miss when a thousand robots take turns.
local atan, abs, sqrt = math.atan, math.abs, math.sqrt
local readProximitySensors = sim.readProximitySensors
local readProximitySensor = sim.readProximitySensor
local setJointTargetVelocity = sim.setJointTargetVelocity

local left_motor, right_motor
local sensors = {}       -- handles, ./prox[0] .. ./prox[23]
local distances = {}     -- their readings (m, -1: nothing), refilled every step
local cos_a, sin_a = {}, {}  -- direction of each sensor, counter-clockwise from the front
local wheel_speed        -- rad/s
local straight_angle     -- rad
local delta
local front, slow_distance  -- the look-ahead sensor, if slow_distance > 0

function sysCall_init()
  wheel_speed = sim.getParam('wheel_speed', 0.05) / sim.getParam('wheel_radius', 0.029)
  straight_angle = math.rad(sim.getParam('go_straight_angle_deg', 7.5))
  delta = sim.getParam('delta', 0.1)
  left_motor = sim.getObject('./leftMotor')
  right_motor = sim.getObject('./rightMotor')
  slow_distance = sim.getParam('slow_distance', 0)
  if slow_distance > 0 then front = sim.getObject('./front') end
  for i = 0, 23 do
    sensors[i + 1] = sim.getObject('./prox[' .. i .. ']')
    cos_a[i + 1], sin_a[i + 1] = math.cos(2 * math.pi * i / 24), math.sin(2 * math.pi * i / 24)
  end
end

function sysCall_actuation()
  -- Sum of the readings as vectors pointing at what each sensor sees.
  -- One call reads all 24 (sim.readProximitySensor(h) reads one).
  local x, y = 0, 0
  if readProximitySensors(sensors, distances) > 0 then
    for i = 1, #sensors do
      local distance = distances[i]
      if distance >= 0 then
        local value = 1 - distance / RANGE
        x, y = x + value * cos_a[i], y + value * sin_a[i]
      end
    end
  end
  local angle = atan(y, x)
  local left, right
  if abs(angle) <= straight_angle and sqrt(x * x + y * y) < delta then
    left, right = wheel_speed, wheel_speed  -- nothing ahead: straight on
  elseif angle > 0 then
    left, right = wheel_speed, 0            -- obstacle on the left: turn right
  else
    left, right = 0, wheel_speed            -- obstacle on the right: turn left
  end
  if front then
    local seen, ahead = readProximitySensor(front)
    if seen == 1 and ahead < slow_distance then left, right = left / 2, right / 2 end
  end
  setJointTargetVelocity(left_motor, left)
  setJointTargetVelocity(right_motor, right)
end
