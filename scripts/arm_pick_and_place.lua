-- UR5 pick-and-place (hybrid simulation, paper §2). The script moves the IK
-- target through waypoints (the IK group 'grasp' makes the tool follow it,
-- kinematically); the box rides with the tool while grasped (kinematic) and
-- is switched to dynamic when released, so it falls onto the table.
-- Waypoints are in the arm base's frame; the tool keeps its start orientation.

local base, target, tip, box, task
local start            -- tool position at start
local orientation      -- tool orientation (quaternion x, y, z, w) kept throughout
local grasp_offset     -- box position in the tool frame while carried
local PICK = {0.45, 0.25, 0.05}   -- tool position that grasps the box (box top)
local PLACE = {0.45, -0.25, 0.10} -- tool position at release (box 5 cm above the table)
local UP = 0.15
local segments         -- {from, to, duration, event}
local segment, segment_start

local function lerp(a, b, s)
  return {a[1] + (b[1] - a[1]) * s, a[2] + (b[2] - a[2]) * s, a[3] + (b[3] - a[3]) * s}
end

function sysCall_init()
  base = sim.getObject('.')
  target = sim.getObject('./target')
  tip = sim.getObject('./tip')
  box = sim.getObject('/box')     -- a scene object of the world file
  task = sim.getObject('./task')  -- the model's graph of the task state
  local pose = sim.getObjectPose(tip, base)
  start = {pose[1], pose[2], pose[3]}
  orientation = {pose[4], pose[5], pose[6], pose[7]}
  local above_pick = {PICK[1], PICK[2], PICK[3] + UP}
  local above_place = {PLACE[1], PLACE[2], PLACE[3] + UP}
  segments = {
    {start, above_pick, 2.0},
    {above_pick, PICK, 1.0, 'grasp'},
    {PICK, above_pick, 1.0},
    {above_pick, above_place, 2.0},
    {above_place, PLACE, 1.0, 'release'},
    {PLACE, above_place, 1.0},
  }
  segment, segment_start = 1, 0
  sim.setObjectPose(target, {start[1], start[2], start[3], orientation[1], orientation[2],
                             orientation[3], orientation[4]}, base)
end

-- p in the tool frame (a pose {x, y, z, qx, qy, qz, qw}) -> p_T.
local function rotate_inverse(q, v)
  -- rotate v by the conjugate of q
  local x, y, z, w = -q[1], -q[2], -q[3], q[4]
  local tx = 2 * (y * v[3] - z * v[2])
  local ty = 2 * (z * v[1] - x * v[3])
  local tz = 2 * (x * v[2] - y * v[1])
  return {v[1] + w * tx + (y * tz - z * ty), v[2] + w * ty + (z * tx - x * tz),
          v[3] + w * tz + (x * ty - y * tx)}
end

function sysCall_actuation()
  local t = sim.getSimulationTime()
  local seg = segments[segment]
  if seg then
    local s = math.min(1, (t - segment_start) / seg[3])
    local p = lerp(seg[1], seg[2], s)
    sim.setObjectPose(target, {p[1], p[2], p[3], orientation[1], orientation[2], orientation[3],
                               orientation[4]}, base)
    if s >= 1 then
      if seg[4] == 'grasp' then
        -- The box's position in the tool frame, kept while carried.
        local tool = sim.getObjectPose(tip)
        local b = sim.getObjectPosition(box)
        grasp_offset = rotate_inverse({tool[4], tool[5], tool[6], tool[7]},
                                      {b[1] - tool[1], b[2] - tool[2], b[3] - tool[3]})
      elseif seg[4] == 'release' then
        grasp_offset = nil
        sim.setObjectDynamic(box, true)
      end
      segment, segment_start = segment + 1, t
    end
  end
  if grasp_offset then
    -- Carried: the box follows the tool (kinematically), orientation unchanged.
    sim.setObjectPosition(box, grasp_offset, tip)
  end
  sim.setGraphStreamValue(task, 'segment', math.min(segment, #segments + 1))
  sim.setGraphStreamValue(task, 'carried', grasp_offset and 1 or 0)
end
