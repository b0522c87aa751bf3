-- The moving target of an imported URDF arm (worlds/urdf_arms.yaml): the
-- dummy 'goal' goes round a tilted circle in front of the arm, each robot at
-- its own phase and speed (sim.random: the robot's own stream), and the IK
-- group 'reach' makes the tool frame (tool0, a URDF link) follow it. The
-- distance from tool0 to the goal is recorded every step as 'tip_error' (m).

local CENTRE = {0.32, 0, 0.38}  -- m, in the arm's base frame
local RADIUS = 0.12             -- m
local root, goal, tip, phase, speed

function sysCall_init()
  root = sim.getObject('.')
  goal = sim.getObject('./goal')
  tip = sim.getObject('./tool0')
  phase = 2 * math.pi * sim.random()
  speed = 0.5 + 0.5 * sim.random()  -- rad/s
end

-- The error of the pose the last step reached (before the target moves again).
function sysCall_sensing()
  local p = sim.getObjectPosition(tip, root)
  local g = sim.getObjectPosition(goal, root)
  local dx, dy, dz = p[1] - g[1], p[2] - g[2], p[3] - g[3]
  sim.recordMetric('tip_error', math.sqrt(dx * dx + dy * dy + dz * dz))
end

function sysCall_actuation()
  local a = phase + speed * sim.getSimulationTime()
  sim.setObjectPosition(goal, {CENTRE[1] + 0.5 * RADIUS * math.sin(a),
                               CENTRE[2] + RADIUS * math.cos(a),
                               CENTRE[3] + RADIUS * math.sin(a)}, root)
end
