-- A foot-bot that diffuses (scripts/diffusion.lua's rule, in short) and
-- fails at random: each step, with probability failure_rate * time step
-- (world parameter failure_rate, per second), drawn from the robot's own
-- random stream, it removes itself. The removal is queued and applied after
-- the control phase; its sysCall_cleanup runs then.

local RANGE = 0.1  -- m, the proximity sensors' range

local me
local left_motor, right_motor
local sensors = {}
local cos_a, sin_a = {}, {}
local wheel_speed  -- rad/s
local failure_probability

function sysCall_init()
  me = sim.getObject(':')
  wheel_speed = sim.getParam('wheel_speed', 0.05) / sim.getParam('wheel_radius', 0.029)
  failure_probability = sim.getParam('failure_rate', 0.02) * sim.getTimeStep()
  left_motor = sim.getObject('./leftMotor')
  right_motor = sim.getObject('./rightMotor')
  for i = 0, 23 do
    sensors[i + 1] = sim.getObject('./prox[' .. i .. ']')
    cos_a[i + 1], sin_a[i + 1] = math.cos(2 * math.pi * i / 24), math.sin(2 * math.pi * i / 24)
  end
end

function sysCall_actuation()
  if sim.random() < failure_probability then
    sim.removeModel(me)
    return
  end
  -- Turn away from the side the proximity readings point at.
  local x, y = 0, 0
  for i = 1, #sensors do
    local detected, distance = sim.readProximitySensor(sensors[i])
    if detected == 1 then
      local value = 1 - distance / RANGE
      x, y = x + value * cos_a[i], y + value * sin_a[i]
    end
  end
  local left, right = wheel_speed, wheel_speed
  if x * x + y * y > 0.01 then
    if y > 0 then right = 0 else left = 0 end
  end
  sim.setJointTargetVelocity(left_motor, left)
  sim.setJointTargetVelocity(right_motor, right)
end
