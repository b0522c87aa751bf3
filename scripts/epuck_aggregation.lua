-- e-puck aggregation (worlds/experiments/aggregation.yaml), after the
-- probabilistic aggregation of Jeanson et al. (2005) and Correll & Martinoli
-- (2011): a robot random-walks (straight, with a random turn now and then,
-- turning away from what its front IR sensors read); when its
-- range-and-bearing board hears another robot within JOIN_RANGE it stops,
-- and a stopped robot leaves with a probability that falls with the number
-- of robots around it (LEAVE / n^2 per step), so bigger clusters hold their
-- robots longer and grow. A stopped robot says so in its board's first byte,
-- and a walker that hears one within ATTRACT_RANGE steers toward the
-- nearest (the cue of cue-based aggregation). With `aggregate: false` (the
-- control) it only random-walks.
--
-- Parameters (sim.getParam): wheel_speed (m/s), wheel_radius (m),
-- ir_threshold (raw IR value), aggregate (true/false).

local JOIN_RANGE = 0.12    -- m, board to board (e-pucks 5 cm apart or less)
local LEAVE = 0.002        -- per-step probability of leaving with one neighbour
local TURN_PROBABILITY = 0.05  -- per step, while walking: start a random turn
local ESCAPE_STEPS = 30    -- after leaving, steps of walking that ignore the others
local ATTRACT_RANGE = 0.4  -- m: a walker steers toward a stopped robot this close

local BEARINGS_DEG = {-17.2, -45.9, -90, -151.5, 151.2, 90, 45.8, 17.1}

local left_motor, right_motor, rab
local sensors, values, sin_a = {}, {}, {}
local speed, threshold, aggregate
local staying = false
local turn_steps, turn_sign = 0, 1
local escape = 0

function sysCall_init()
  speed = sim.getParam('wheel_speed', 0.1) / sim.getParam('wheel_radius', 0.0205)
  threshold = sim.getParam('ir_threshold', 300)
  aggregate = sim.getParam('aggregate', true)
  left_motor = sim.getObject('./leftMotor')
  right_motor = sim.getObject('./rightMotor')
  rab = sim.getObject('./rab')
  for i = 0, 7 do
    sensors[i + 1] = sim.getObject('./ir[' .. i .. ']')
    sin_a[i + 1] = math.sin(math.rad(BEARINGS_DEG[i + 1]))
  end
end

function sysCall_actuation()
  -- Robots close by, by the board, and the nearest stopped one.
  local near, cue = 0, nil
  for _, m in ipairs(sim.readRangeAndBearing(rab)) do
    if m.range <= JOIN_RANGE then near = near + 1 end
    if cue == nil and string.byte(m.data, 1) == 1 and m.range <= ATTRACT_RANGE then cue = m end
  end
  sim.setRangeAndBearingData(rab, {staying and 1 or 0})
  if escape > 0 then escape = escape - 1 end
  if staying then
    if near == 0 or math.random() < LEAVE / (near * near) then
      staying, escape = false, ESCAPE_STEPS
      turn_steps, turn_sign = math.random(5, 15), (math.random() < 0.5) and -1 or 1
    else
      sim.setJointTargetVelocity(left_motor, 0)
      sim.setJointTargetVelocity(right_motor, 0)
      return
    end
  elseif aggregate and escape == 0 and near > 0 then
    staying = true
    sim.setRangeAndBearingData(rab, {1})
    sim.setJointTargetVelocity(left_motor, 0)
    sim.setJointTargetVelocity(right_motor, 0)
    return
  end
  -- Random walk with obstacle avoidance.
  sim.readProximityValues(sensors, values)
  local front = math.max(values[1], values[2], values[7], values[8])
  local left, right = speed, speed
  if front > threshold then
    local y = 0
    for i = 1, 8 do y = y + values[i] * sin_a[i] end
    turn_sign = y > 0 and -1 or 1   -- away from the side that reads more
    left, right = -turn_sign * speed, turn_sign * speed
    turn_steps = 0
  elseif aggregate and escape == 0 and cue ~= nil then
    -- Toward the stopped robot: turn in proportion to its bearing.
    local turn = math.max(-1, math.min(1, 2 * cue.bearing / math.pi))
    left, right = speed * (1 - turn), speed * (1 + turn)
    turn_steps = 0
  elseif turn_steps > 0 then
    turn_steps = turn_steps - 1
    left, right = -turn_sign * speed, turn_sign * speed
  elseif math.random() < TURN_PROBABILITY then
    turn_steps, turn_sign = math.random(2, 10), (math.random() < 0.5) and -1 or 1
  end
  sim.setJointTargetVelocity(left_motor, left)
  sim.setJointTargetVelocity(right_motor, right)
end
