-- Aggregation by range-and-bearing (worlds/rab_aggregation.yaml): every
-- step each robot sends, in the first byte of its board's payload, how many
-- robots it heard, and drives toward the robot that heard the most (ties:
-- the nearest), so that robots flow toward the densest spot they can hear
-- and stay there. Among many neighbours it slows down and stops; hearing
-- no one it wanders (straight, with random turns); it turns away from what
-- its proximity ring senses.
--
-- Parameters (sim.getParam): wheel_speed (m/s), wheel_radius (m), listen
-- (false: ignore the board, a random walk).

local PROX_RANGE = 0.1  -- m, the proximity ring's range
local STOP_DISTANCE = 0.3  -- m: a robot this close ahead, among 3 or more, stops it

local left_motor, right_motor, rab
local speed       -- rad/s of a wheel at cruising speed
local listen
local sensors = {}
local cos_a, sin_a = {}, {}
local wander_turn = 0  -- steps left of a random turn, signed

function sysCall_init()
  left_motor = sim.getObject('./leftMotor')
  right_motor = sim.getObject('./rightMotor')
  rab = sim.getObject('./rab')
  speed = sim.getParam('wheel_speed', 0.1) / sim.getParam('wheel_radius', 0.029)
  listen = sim.getParam('listen', true)
  for i = 0, 23 do
    sensors[i + 1] = sim.getObject('./prox[' .. i .. ']')
    cos_a[i + 1], sin_a[i + 1] = math.cos(2 * math.pi * i / 24), math.sin(2 * math.pi * i / 24)
  end
end

-- Wheel speeds that turn toward `angle` (rad, counter-clockwise from the
-- front) while driving at `forward` (0..1) of the cruising speed.
local function steer(angle, forward)
  local turn = math.max(-1, math.min(1, 2 * angle / math.pi))
  local base = forward * math.max(0, math.cos(angle))
  return speed * (base - turn), speed * (base + turn)
end

function sysCall_actuation()
  local heard = sim.readRangeAndBearing(rab)
  -- Tell the others how many robots I hear (one byte; the rest stays 0).
  sim.setRangeAndBearingData(rab, {math.min(#heard, 255)})
  -- The robot that hears the most, and how crowded it is right here.
  local best, close = nil, 0
  for _, m in ipairs(heard) do
    local count = string.byte(m.data, 1)
    if best == nil or count > best.count or (count == best.count and m.range < best.range) then
      best = {count = count, range = m.range, bearing = m.bearing}
    end
    if m.range < 0.5 then close = close + 1 end
  end
  -- Obstacles: away from what the ring sees.
  local ox, oy, near_front = 0, 0, math.huge
  for i = 1, #sensors do
    local detected, distance = sim.readProximitySensor(sensors[i])
    if detected == 1 then
      local w = 1 - distance / PROX_RANGE
      ox, oy = ox - w * cos_a[i], oy - w * sin_a[i]
      if cos_a[i] > 0.7 then near_front = math.min(near_front, distance) end
    end
  end
  local left, right
  if listen and best ~= nil and close >= 3 and near_front < PROX_RANGE then
    left, right = 0, 0  -- in a crowd, something just ahead: stay
  elseif listen and best ~= nil and best.count >= #heard then
    -- Toward the robot that hears at least as many as I do; slower when crowded.
    local forward = close >= 3 and 0.3 or 1
    local x, y = math.cos(best.bearing) + 2 * ox, math.sin(best.bearing) + 2 * oy
    left, right = steer(math.atan(y, x), forward)
  elseif listen and best ~= nil and close >= 3 then
    left, right = 0, 0  -- I hear more than anyone around me: a cluster's centre
  elseif ox ~= 0 or oy ~= 0 then
    left, right = steer(math.atan(oy, ox), 1)
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
