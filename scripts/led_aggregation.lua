-- Aggregation by LED colour (worlds/led_aggregation.yaml): each robot
-- lights its LED in one of `colors` colours (by robot index) and reads its
-- omnidirectional blob camera every step. It steers toward the mean
-- direction of the LEDs of its own colour it sees and away from the LEDs
-- of other colours nearby, and turns away from what its proximity ring
-- senses; seeing none of its colour, it wanders (straight, with random
-- turns). Same-coloured robots end up in clusters: the world's metrics
-- same_color_neighbor_fraction and color_dispersion show it.
--
-- Parameters (sim.getParam): wheel_speed (m/s), wheel_radius (m), colors
-- (2 or 3), repel_distance (m): other colours closer than this push away.

local PALETTE = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}
local PROX_RANGE = 0.1  -- m, the proximity ring's range

local left_motor, right_motor, camera
local my_color
local speed       -- rad/s of a wheel at cruising speed
local repel
local sensors = {}
local cos_a, sin_a = {}, {}
local wander_turn = 0  -- steps left of a random turn, signed

function sysCall_init()
  left_motor = sim.getObject('./leftMotor')
  right_motor = sim.getObject('./rightMotor')
  camera = sim.getObject('./camera')
  speed = sim.getParam('wheel_speed', 0.1) / sim.getParam('wheel_radius', 0.029)
  repel = sim.getParam('repel_distance', 0.5)
  local colors = sim.getParam('colors', 3)
  my_color = PALETTE[sim.getRobotIndex() % colors + 1]
  sim.setLedColor(sim.getObject('./led'), my_color)
  for i = 0, 23 do
    sensors[i + 1] = sim.getObject('./prox[' .. i .. ']')
    cos_a[i + 1], sin_a[i + 1] = math.cos(2 * math.pi * i / 24), math.sin(2 * math.pi * i / 24)
  end
end

local function mine(c)
  return c[1] == my_color[1] and c[2] == my_color[2] and c[3] == my_color[3]
end

-- Wheel speeds that turn toward `angle` (rad, counter-clockwise from the
-- front) while driving at `forward` (0..1) of the cruising speed.
local function steer(angle, forward)
  local turn = math.max(-1, math.min(1, 2 * angle / math.pi))
  local base = forward * math.max(0, math.cos(angle))
  return speed * (base - turn), speed * (base + turn)
end

function sysCall_actuation()
  -- Attraction to my colour, repulsion from the others nearby.
  local ax, ay, mates, nearest = 0, 0, 0, math.huge
  local rx, ry = 0, 0
  for _, blob in ipairs(sim.readBlobCamera(camera)) do
    local c, s = math.cos(blob.bearing), math.sin(blob.bearing)
    if mine(blob.color) then
      ax, ay, mates = ax + c, ay + s, mates + 1
      nearest = math.min(nearest, blob.distance)
    elseif blob.distance < repel then
      local w = 1 - blob.distance / repel
      rx, ry = rx - w * c, ry - w * s
    end
  end
  -- Obstacles: away from what the ring sees.
  local ox, oy = 0, 0
  for i = 1, #sensors do
    local detected, distance = sim.readProximitySensor(sensors[i])
    if detected == 1 then
      local w = 1 - distance / PROX_RANGE
      ox, oy = ox - w * cos_a[i], oy - w * sin_a[i]
    end
  end
  local left, right
  if mates > 0 then
    -- Slow down among my own: a cluster settles instead of jostling.
    local forward = nearest < 0.3 and 0.3 or 1
    local x, y = ax / mates + 1.5 * rx + 2 * ox, ay / mates + 1.5 * ry + 2 * oy
    left, right = steer(math.atan(y, x), forward)
  elseif rx ~= 0 or ry ~= 0 or ox ~= 0 or oy ~= 0 then
    left, right = steer(math.atan(ry + 2 * oy, rx + 2 * ox), 1)
  else
    -- Wander: straight on, now and then a turn for a few steps.
    if wander_turn == 0 and sim.random() < 0.05 then
      wander_turn = (sim.random() < 0.5 and -1 or 1) * math.floor(2 + 8 * sim.random())
    end
    if wander_turn > 0 then
      left, right, wander_turn = 0, speed, wander_turn - 1
    elseif wander_turn < 0 then
      left, right, wander_turn = speed, 0, wander_turn + 1
    else
      left, right = speed, speed
    end
  end
  sim.setJointTargetVelocity(left_motor, left)
  sim.setJointTargetVelocity(right_motor, right)
end
