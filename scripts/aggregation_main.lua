-- Main script of worlds/experiments/aggregation.yaml: the default step,
-- plus every `metric_every` steps (metrics.csv):
--   largest_cluster_fraction: the share of the robots in the largest
--     cluster, robots within `cluster_distance` (m, centre to centre) of
--     each other being in one cluster (1/robots: all apart; 1: one cluster);
--   clusters: how many clusters of two robots or more there are.

local robots, every, link, step = {}, 10, 0.13, 0

function sysCall_init()
  every = sim.getParam('metric_every', 10)
  link = sim.getParam('cluster_distance', 0.13)
  for i = 0, sim.getParam('robots') - 1 do
    robots[#robots + 1] = sim.getObject('/epuck#' .. i)
  end
end

local function record()
  local n = #robots
  local p, parent = {}, {}
  for i, h in ipairs(robots) do p[i], parent[i] = sim.getObjectPosition(h), i end
  local function root(i)
    while parent[i] ~= i do parent[i] = parent[parent[i]]; i = parent[i] end
    return i
  end
  for i = 1, n do
    for j = i + 1, n do
      local dx, dy = p[i][1] - p[j][1], p[i][2] - p[j][2]
      if dx * dx + dy * dy <= link * link then parent[root(i)] = root(j) end
    end
  end
  local size = {}
  for i = 1, n do local r = root(i); size[r] = (size[r] or 0) + 1 end
  local largest, clusters = 0, 0
  for _, s in pairs(size) do
    if s > largest then largest = s end
    if s >= 2 then clusters = clusters + 1 end
  end
  sim.recordMetric('largest_cluster_fraction', largest / n)
  sim.recordMetric('clusters', clusters)
end

function sysCall_step()
  if step == 0 then record() end
  sim.handleSensing()
  sim.handleChildScripts()
  sim.handleActuation()
  sim.handleDynamics()
  step = step + 1
  if step % every == 0 then record() end
end
