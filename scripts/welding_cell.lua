-- A welding cell's table (worlds/models/welding_cell.yaml): records, every
-- step, `seam_s`, the torch's arc length along the seam (m, wraps to 0 each
-- lap), `laps` so far, and `torch_error`, the distance (m) between the
-- torch and the point 5 cm above the seam (times the cell's size factor)
-- where sim.getPathPose puts it.
local seam, torch
local length, height
local laps, last_s = 0, 0

function sysCall_init()
  seam = sim.getObject('./seam')
  torch = sim.getObject('./seam/torch')
  length = sim.getPathLength(seam)
  height = 0.05 * sim.getObjectSizeFactor(seam)
end

function sysCall_sensing()
  local s = sim.getPathPosition(seam)
  if s < last_s then laps = laps + 1 end
  last_s = s
  local p = sim.getPathPose(seam, s)
  local t = sim.getObjectPosition(torch)
  -- The seam frame's z, rotated by the pose's quaternion (qx, qy, qz, qw).
  local qx, qy, qz, qw = p[4], p[5], p[6], p[7]
  local zx = 2 * (qx * qz + qw * qy)
  local zy = 2 * (qy * qz - qw * qx)
  local zz = 1 - 2 * (qx * qx + qy * qy)
  local h = height
  local dx, dy, dz = t[1] - (p[1] + h * zx), t[2] - (p[2] + h * zy), t[3] - (p[3] + h * zz)
  sim.recordMetric('seam_s', s)
  sim.recordMetric('laps', laps + s / length)
  sim.recordMetric('torch_error', math.sqrt(dx * dx + dy * dy + dz * dz))
end
