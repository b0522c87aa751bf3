-- The hexapod's body script (V-REP paper §4): generates the foot motion
-- sequence and sends it to the legs. Each step it appends the foot offset
-- (body frame) of a leg with no delay to a history, newest first, and sends
-- the history as a local message; leg k applies entry 1 + k * delay, so
-- the legs follow the same motion one after the other (a wave gait).
--
-- Parameters (sim.getParam): step_length (m), step_height (m), cycle_time
-- (s), heading_deg (walking direction in the body frame).

local history_x, history_y, history_z = {}, {}, {}
local delay        -- steps between two legs (inter-module delay)
local length       -- entries kept: the last leg's delay + 1
local dt, cycle, step_length, step_height, dir_x, dir_y
local SWING = 1 / 6  -- fraction of the cycle a foot is in the air

function sysCall_init()
  dt = sim.getTimeStep()
  cycle = sim.getParam('cycle_time', 1.2)
  step_length = sim.getParam('step_length', 0.08)
  step_height = sim.getParam('step_height', 0.03)
  local heading = math.rad(sim.getParam('heading_deg', 0))
  dir_x, dir_y = math.cos(heading), math.sin(heading)
  delay = math.max(1, math.floor(cycle * SWING / dt + 0.5))
  length = 5 * delay + 1
  for i = 1, length do history_x[i], history_y[i], history_z[i] = 0, 0, 0 end
end

-- Foot offset along the walking direction and up, at phase p in [0, 1):
-- swing forward through the air, then push back on the ground.
local function foot(p)
  if p < SWING then
    local s = p / SWING
    return step_length * (s - 0.5), step_height * math.sin(math.pi * s)
  end
  local s = (p - SWING) / (1 - SWING)
  return step_length * (0.5 - s), 0
end

function sysCall_actuation()
  local t = sim.getSimulationTime()
  local along, up = foot((t / cycle) % 1)
  table.insert(history_x, 1, along * dir_x)
  table.insert(history_y, 1, along * dir_y)
  table.insert(history_z, 1, up)
  history_x[length + 1], history_y[length + 1], history_z[length + 1] = nil, nil, nil
  -- One flat float array: delay, n, then the n x, y and z entries.
  local data = {delay, length}
  for i = 1, length do
    data[2 + i], data[2 + length + i], data[2 + 2 * length + i] = history_x[i], history_y[i], history_z[i]
  end
  sim.sendLocalMessage(sim.packFloats(data))
end
