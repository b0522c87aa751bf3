-- Foot-bot diffusion with a look-ahead cone (worlds/clearance.yaml): drive
-- straight, slow down while the front cone sensor sees something within
-- SLOW_DISTANCE, and turn away from whatever the 24 ring sensors see.
--
-- Attached to the foot-bot's body. Parameters (sim.getParam): wheel_speed
-- (m/s), wheel_radius (m), go_straight_angle_deg, delta.

local RANGE = 0.1  -- m, the proximity sensors' range
local SLOW_DISTANCE = 0.25  -- m: closer than this ahead, half speed

local left_motor, right_motor
local sensors = {}       -- handles, ./prox[0] .. ./prox[23]
local cos_a, sin_a = {}, {}  -- direction of each sensor, counter-clockwise from the front
local wheel_speed        -- rad/s
local straight_angle     -- rad
local delta
local front              -- the cone sensor

function sysCall_init()
  wheel_speed = sim.getParam('wheel_speed', 0.05) / sim.getParam('wheel_radius', 0.029)
  straight_angle = math.rad(sim.getParam('go_straight_angle_deg', 7.5))
  delta = sim.getParam('delta', 0.1)
  left_motor = sim.getObject('./leftMotor')
  right_motor = sim.getObject('./rightMotor')
  front = sim.getObject('./front')
  for i = 0, 23 do
    sensors[i + 1] = sim.getObject('./prox[' .. i .. ']')
    cos_a[i + 1], sin_a[i + 1] = math.cos(2 * math.pi * i / 24), math.sin(2 * math.pi * i / 24)
  end
end

function sysCall_actuation()
  -- Sum of the readings as vectors pointing at what each sensor sees.
  local x, y = 0, 0
  for i = 1, #sensors do
    local detected, distance = sim.readProximitySensor(sensors[i])
    if detected == 1 then
      local value = 1 - distance / RANGE
      x, y = x + value * cos_a[i], y + value * sin_a[i]
    end
  end
  local angle = math.atan(y, x)
  local left, right
  if math.abs(angle) <= straight_angle and math.sqrt(x * x + y * y) < delta then
    left, right = wheel_speed, wheel_speed  -- nothing ahead: straight on
  elseif angle > 0 then
    left, right = wheel_speed, 0            -- obstacle on the left: turn right
  else
    left, right = 0, wheel_speed            -- obstacle on the right: turn left
  end
  local seen, ahead = sim.readProximitySensor(front)
  if seen == 1 and ahead < SLOW_DISTANCE then left, right = left / 2, right / 2 end
  sim.setJointTargetVelocity(left_motor, left)
  sim.setJointTargetVelocity(right_motor, right)
end
