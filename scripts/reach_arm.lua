-- The reaching arm's base (worlds/models/reach_arm.yaml): records, every
-- step, `target_error` (m, from the arm's tip to its target), `clearance`
-- (m, the links' minimum distance to the post, from the distance object
-- measured after the last step) and `min_clearance`, the least so far.
local tip, target, links_to_post
local min_clearance = math.huge

function sysCall_init()
  tip = sim.getObject(':/tip')
  target = sim.getObject(':/target')
  links_to_post = sim.getObject(':/links_to_post')
end

function sysCall_sensing()
  local t, g = sim.getObjectPosition(tip), sim.getObjectPosition(target)
  local dx, dy, dz = t[1] - g[1], t[2] - g[2], t[3] - g[3]
  sim.recordMetric('target_error', math.sqrt(dx * dx + dy * dy + dz * dz))
  local d = sim.readDistance(links_to_post) or math.huge
  min_clearance = math.min(min_clearance, d)
  sim.recordMetric('clearance', d)
  sim.recordMetric('min_clearance', min_clearance)
end
