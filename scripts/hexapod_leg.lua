-- A hexapod leg's script (V-REP paper §4): applies the body's foot motion
-- sequence with this leg's delay by moving the foot target; the leg's IK
-- group (automatic, joint-target mode) makes the foot tip follow it. The
-- six leg scripts are this one file; the delay comes from the leg's name
-- (leg0 .. leg5).

local base, target, module_pos
local foot_original

function sysCall_init()
  local self = sim.getObject('.')
  base = sim.getObject(':')                -- the hexapod's body (model root)
  target = sim.getObject('./footTarget')
  module_pos = tonumber(string.match(sim.getObjectName(self), '%d+'))
  foot_original = sim.getObjectPosition(sim.getObject('./footTip'), base)
end

function sysCall_actuation()
  -- The latest sequence from the body script (sent last step).
  local data
  while true do
    local d = sim.receiveMessage()
    if d == nil then break end
    data = d
  end
  if data == nil then return end
  -- delay, n, then n x, n y and n z entries (hexapod_body.lua), newest first.
  local m = sim.unpackFloats(data)
  local delay, n = m[1], m[2]
  local i = 2 + module_pos * delay + 1
  sim.setObjectPosition(target, {foot_original[1] + m[i], foot_original[2] + m[i + n],
                                 foot_original[3] + m[i + 2 * n]}, base)
end
