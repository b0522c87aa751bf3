-- The UR5 at the end of worlds/conveyor.yaml's belt (hybrid simulation,
-- paper §2). The script moves the IK target (the group 'grasp' makes the
-- tool follow it, kinematically) in a loop: wait above the belt's end until
-- a crate lies at the stop, go down, grasp it (the crate turns kinematic
-- and rides with the tool), lift it, carry it over the side table, put it
-- down at the next free place and release it (dynamic again: it drops the
-- last 2 cm), and come back. metrics.csv: boxes_picked, boxes_delivered.
-- Positions are in the arm base's frame (the base stands at [0, 0, 0.4],
-- unrotated).

local base, target, tip
local orientation        -- tool orientation (quaternion x, y, z, w) kept throughout
local PICK = {0.45, 0.25, 0.06}  -- the tool on the top of a crate at the stop
local PLACES = {{0.35, -0.28}, {0.45, -0.28}, {0.55, -0.28},
                {0.35, -0.42}, {0.45, -0.42}, {0.55, -0.42}}
local PLACE_Z = 0.08     -- the tool at release: the crate 2 cm above the table
local UP = 0.15
local moves = {}         -- queue of {from, to, duration, event}
local move_start
local carried, grasp_offset
local picked, delivered = 0, 0

local function lerp(a, b, s)
  return {a[1] + (b[1] - a[1]) * s, a[2] + (b[2] - a[2]) * s, a[3] + (b[3] - a[3]) * s}
end

local function set_target(p)
  sim.setObjectPose(target, {p[1], p[2], p[3], orientation[1], orientation[2], orientation[3],
                             orientation[4]}, base)
end

-- The crate lying at the stop (another robot's root), or nil.
local function crate_at_stop()
  local me = sim.getObject('.')
  for _, robot in ipairs(sim.getRobots()) do
    if robot ~= me then
      local p = sim.getObjectPosition(robot, base)
      if math.abs(p[1] - PICK[1]) < 0.03 and math.abs(p[2] - PICK[2]) < 0.03 and
         math.abs(p[3] - (PICK[3] - 0.03)) < 0.01 then
        return robot
      end
    end
  end
end

local ABOVE_PICK = {PICK[1], PICK[2], PICK[3] + UP}

function sysCall_init()
  base = sim.getObject('.')
  target = sim.getObject('./target')
  tip = sim.getObject('./tip')
  local pose = sim.getObjectPose(tip, base)
  orientation = {pose[4], pose[5], pose[6], pose[7]}
  moves = {{{pose[1], pose[2], pose[3]}, ABOVE_PICK, 2.0}}
  move_start = 0
  set_target({pose[1], pose[2], pose[3]})
end

-- A pick-and-place cycle from above the pick point, putting the crate at
-- place k.
local function plan_cycle(k)
  local place = {PLACES[k][1], PLACES[k][2], PLACE_Z}
  local above_place = {place[1], place[2], place[3] + UP}
  moves = {
    {ABOVE_PICK, PICK, 0.8, 'grasp'},
    {PICK, ABOVE_PICK, 0.8},
    {ABOVE_PICK, above_place, 1.5},
    {above_place, place, 0.8, 'release'},
    {place, above_place, 0.6},
    {above_place, ABOVE_PICK, 1.5},
  }
end

function sysCall_actuation()
  local t = sim.getSimulationTime()
  local move = moves[1]
  if move then
    local s = math.min(1, (t - move_start) / move[3])
    set_target(lerp(move[1], move[2], s))
    if s >= 1 then
      if move[4] == 'grasp' then
        -- The crate's position in the tool frame, kept while carried.
        grasp_offset = sim.getObjectPosition(carried, tip)
        sim.setObjectDynamic(carried, false)
        picked = picked + 1
      elseif move[4] == 'release' then
        sim.setObjectDynamic(carried, true)
        carried, grasp_offset = nil, nil
        delivered = delivered + 1
      end
      table.remove(moves, 1)
      move_start = t
    end
  elseif delivered < #PLACES then
    -- Idle above the belt's end: pick the crate at the stop, if there is one.
    carried = crate_at_stop()
    if carried then
      plan_cycle(delivered + 1)
      move_start = t
    end
  end
  if grasp_offset then
    -- Carried: the crate follows the tool (kinematically), orientation unchanged.
    sim.setObjectPosition(carried, grasp_offset, tip)
  end
  sim.recordMetric('boxes_picked', picked)
  sim.recordMetric('boxes_delivered', delivered)
end
