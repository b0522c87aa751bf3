-- e-puck diffusion (worlds/epuck_diffusion.yaml, models/epuck.yaml): drive
-- straight; when a front IR sensor's raw value passes ir_threshold, turn on
-- the spot away from the side that reads more (the sum of the 8 values
-- above the curve's far end, as vectors toward what each sensor faces).
--
-- Attached to the e-puck's body. Parameters (sim.getParam): wheel_speed
-- (m/s), wheel_radius (m), ir_threshold (raw value).

local atan = math.atan
local readProximityValues = sim.readProximityValues
local setJointTargetVelocity = sim.setJointTargetVelocity

-- The sensors' bearings (deg, counter-clockwise from the front), IR0 .. IR7
-- as worlds/models/epuck.yaml places them.
local BEARINGS_DEG = {-17.2, -45.9, -90, -151.5, 151.2, 90, 45.8, 17.1}
local FAR = 67.19  -- the response curve's far end: what a sensor reads when it sees nothing

local left_motor, right_motor
local sensors = {}       -- ./ir[0] .. ./ir[7]
local values = {}        -- their raw values, refilled every step
local cos_a, sin_a = {}, {}
local speed              -- rad/s
local threshold

function sysCall_init()
  speed = sim.getParam('wheel_speed', 0.1) / sim.getParam('wheel_radius', 0.0205)
  threshold = sim.getParam('ir_threshold', 300)
  left_motor = sim.getObject('./leftMotor')
  right_motor = sim.getObject('./rightMotor')
  for i = 0, 7 do
    sensors[i + 1] = sim.getObject('./ir[' .. i .. ']')
    local a = math.rad(BEARINGS_DEG[i + 1])
    cos_a[i + 1], sin_a[i + 1] = math.cos(a), math.sin(a)
  end
end

function sysCall_actuation()
  readProximityValues(sensors, values)
  -- The front four (IR0, IR1, IR6, IR7) decide whether something is ahead.
  local front = values[1]
  if values[2] > front then front = values[2] end
  if values[7] > front then front = values[7] end
  if values[8] > front then front = values[8] end
  local left, right = speed, speed
  if front > threshold then
    local y = 0
    for i = 1, 8 do y = y + (values[i] - FAR) * sin_a[i] end
    if y > 0 then
      left, right = speed, -speed   -- more on the left: turn right
    else
      left, right = -speed, speed   -- more on the right (or straight ahead): turn left
    end
  end
  setJointTargetVelocity(left_motor, left)
  setJointTargetVelocity(right_motor, right)
end
