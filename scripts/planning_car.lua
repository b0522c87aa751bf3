-- A planning car (worlds/models/planning_car.yaml): asks its planning task
-- for a path from where it stands to a goal drawn from its random stream
-- (x from goal_min_x to goal_max_x, anywhere in y, heading east), and once
-- the plan is solved drives it kinematically at `speed`, putting the body on
-- sim.getPathPose of the plan's path (x along the path: the car's heading).
-- After a failed plan (a goal in collision, enclosed, or too tight for the
-- car to reach within the budget) it draws another goal, up to 20 plans.
-- metrics.csv, per car: `arrived` (0/1), `plans` (requests so far),
-- `driven` (m along the plan); the collision object adds `bump.colliding`.
local body, task, path
local s, length, speed = 0, 0, 0.8
local arrived, plans = 0, 0
local goal

local function drawGoal()
  local lo, hi = sim.getParam('goal_min_x'), sim.getParam('goal_max_x')
  goal = {lo + (hi - lo) * sim.random(), -9 + 18 * sim.random(), (sim.random() - 0.5) * math.pi}
end

local function plan()
  plans = plans + 1
  sim.planPath(task, goal)
end

function sysCall_init()
  body = sim.getObject('.')
  task = sim.getObject('./planner')
  speed = sim.getParam('speed')
  drawGoal()
  plan()
end

function sysCall_actuation()
  local status, reason, h, len = sim.readPlan(task)
  if status == 'solved' and arrived == 0 then
    path, length = h, len
    s = math.min(s + speed * sim.getTimeStep(), length)
    sim.setObjectPose(body, sim.getPathPose(path, s))
    if s >= length then arrived = 1 end
  elseif status == 'failed' and plans < 20 then
    drawGoal()  -- in collision, enclosed, or too tight for the car: another
    plan()
  end
  sim.recordMetric('arrived', arrived)
  sim.recordMetric('plans', plans)
  sim.recordMetric('driven', s)
end
