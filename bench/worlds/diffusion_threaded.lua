-- Benchmark: scripts/diffusion.lua as a threaded script (sysCall_thread,
-- one sim.step() per control step), doing exactly the same work per step.
-- Compared with worlds/diffusion.yaml.
--
-- Attached to the foot-bot's body. Parameters (sim.getParam): wheel_speed
-- (m/s), wheel_radius (m), go_straight_angle_deg, delta.

local RANGE = 0.1  -- m, the proximity sensors' range

local left_motor, right_motor
local sensors = {}       -- handles, ./prox[0] .. ./prox[23]
local cos_a, sin_a = {}, {}  -- direction of each sensor, counter-clockwise from the front
local wheel_speed        -- rad/s
local straight_angle     -- rad
local delta

function sysCall_init()
  wheel_speed = sim.getParam('wheel_speed', 0.05) / sim.getParam('wheel_radius', 0.029)
  straight_angle = math.rad(sim.getParam('go_straight_angle_deg', 7.5))
  delta = sim.getParam('delta', 0.1)
  left_motor = sim.getObject('./leftMotor')
  right_motor = sim.getObject('./rightMotor')
  for i = 0, 23 do
    sensors[i + 1] = sim.getObject('./prox[' .. i .. ']')
    cos_a[i + 1], sin_a[i + 1] = math.cos(2 * math.pi * i / 24), math.sin(2 * math.pi * i / 24)
  end
end

function sysCall_thread()
  while true do
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
    sim.setJointTargetVelocity(left_motor, left)
    sim.setJointTargetVelocity(right_motor, right)
    sim.step()
  end
end
