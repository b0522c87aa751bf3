-- Flocking by range-limited messages (Reynolds' boids on diff-drive robots).
-- Each step a robot broadcasts its heading (sim.packFloats) to the robots
-- within comm_range, and steers toward the sum, in its own frame, of
--   alignment:  the neighbours' mean heading (relative to its own),
--   cohesion:   a pull toward neighbours farther than `separation`,
--   separation: a push away from those nearer (distance and bearing come
--               with each message: sim.receiveMessage),
--   avoidance:  a push away from what the proximity ring sees.
-- Parameters (models/flocker.yaml): speed, wheel_radius, comm_range,
-- separation, alignment_gain, cohesion_gain, turn_gain.

local HALF_AXLE = 0.07  -- m, wheel to body centre
local self, left_motor, right_motor
local sensors, cos_a, sin_a = {}, {}, {}
local speed, wheel_radius, range, separation, k_align, k_cohesion, k_turn

function sysCall_init()
  speed = sim.getParam('speed')
  wheel_radius = sim.getParam('wheel_radius')
  range = sim.getParam('comm_range')
  separation = sim.getParam('separation')
  k_align = sim.getParam('alignment_gain')
  k_cohesion = sim.getParam('cohesion_gain')
  k_turn = sim.getParam('turn_gain')
  self = sim.getObject('.')
  left_motor = sim.getObject('./leftMotor')
  right_motor = sim.getObject('./rightMotor')
  for i = 0, 7 do
    sensors[i + 1] = sim.getObject('./prox[' .. i .. ']')
    cos_a[i + 1], sin_a[i + 1] = math.cos(math.pi * i / 4), math.sin(math.pi * i / 4)
  end
end

function sysCall_actuation()
  local yaw = sim.getObjectOrientation(self)[3]
  -- Neighbours heard (sent last step), in this robot's frame.
  local ax, ay, cx, cy, n = 0, 0, 0, 0, 0
  while true do
    local data, _, distance, bearing = sim.receiveMessage()
    if not data then break end
    local heading = sim.unpackFloats(data)[1]
    ax, ay = ax + math.cos(heading - yaw), ay + math.sin(heading - yaw)
    local w
    if distance < separation then
      w = -3 * (separation - distance) / separation
    else
      w = k_cohesion * (distance - separation) / range
    end
    cx, cy = cx + w * math.cos(bearing), cy + w * math.sin(bearing)
    n = n + 1
  end
  local x, y = 1, 0  -- keep going
  if n > 0 then
    x, y = x + k_align * ax / n + cx / n, y + k_align * ay / n + cy / n
  end
  -- Whatever the proximity ring sees pushes away.
  for i = 1, #sensors do
    local detected, distance = sim.readProximitySensor(sensors[i])
    if detected == 1 then
      local push = 3 * (1 - distance / 0.15)
      x, y = x - push * cos_a[i], y - push * sin_a[i]
    end
  end
  local error = math.atan(y, x)
  local omega = math.max(-2, math.min(2, k_turn * error))  -- rad/s, CCW
  local v = speed * math.max(0.2, math.cos(error))
  sim.setJointTargetVelocity(left_motor, (v - omega * HALF_AXLE) / wheel_radius)
  sim.setJointTargetVelocity(right_motor, (v + omega * HALF_AXLE) / wheel_radius)
  sim.sendRangeMessage(sim.packFloats({yaw}), range)
end
