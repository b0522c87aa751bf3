-- Position-based visual servoing (worlds/visual_servo.yaml): each step the
-- overhead camera's filter chain (HSV threshold, then blobs) gives the
-- puck's centroid in the image; the script turns it into a point on the
-- table (the ray through that pixel meets the plane of the puck's top) and
-- moves the IK target toward a point HOVER above it, at most SPEED m/s, on a
-- path around the arm's base (radius, angle and height change together: a
-- straight line would pass over the shoulder's singular axis). The tool
-- keeps its start orientation.

local HOVER = 0.10  -- m above the puck's top
local SPEED = 0.5   -- m/s, the target's fastest
local TOP = 0.42    -- m, height of the puck's top (the table's 0.40 + 0.02)

local camera, target, tip, base
local orientation
local aim  -- where the target is being moved to, this step (world frame)

function sysCall_init()
  base = sim.getObject('.')
  target = sim.getObject('./target')
  tip = sim.getObject('./tip')
  camera = sim.getObject('/overhead')
  local pose = sim.getObjectPose(tip)
  orientation = {pose[4], pose[5], pose[6], pose[7]}
  aim = {pose[1], pose[2], pose[3]}
  sim.setObjectPose(target, pose)
end

-- Rotates v by the quaternion q = {x, y, z, w}.
local function rotate(q, v)
  local x, y, z, w = q[1], q[2], q[3], q[4]
  local tx = 2 * (y * v[3] - z * v[2])
  local ty = 2 * (z * v[1] - x * v[3])
  local tz = 2 * (x * v[2] - y * v[1])
  return {v[1] + w * tx + (y * tz - z * ty), v[2] + w * ty + (z * tx - x * tz),
          v[3] + w * tz + (x * ty - y * tx)}
end

-- The point on the plane z = TOP that the pixel (x, y) (from the image's
-- top-left corner) looks at. A vision sensor looks along its +x with +z up;
-- the image's right is its -y.
local function on_table(px, py)
  local res = sim.getVisionSensorRes(camera)
  local fov = sim.getObjectFloatParam(camera, sim.visionfloatparam_perspective_angle)  -- rad
  local f = (res[1] / 2) / math.tan(fov / 2)
  local ray = {1, -(px - res[1] / 2) / f, (res[2] / 2 - py) / f}
  local pose = sim.getObjectPose(camera)
  local d = rotate({pose[4], pose[5], pose[6], pose[7]}, ray)
  local s = (TOP - pose[3]) / d[3]
  return {pose[1] + s * d[1], pose[2] + s * d[2], TOP}
end

-- From `from` toward `to` by at most `step` m, in cylindrical coordinates
-- about the base's vertical axis.
function toward(from, to, step)
  local b = sim.getObjectPosition(base)
  local function cylindrical(p)
    local x, y = p[1] - b[1], p[2] - b[2]
    return math.sqrt(x * x + y * y), math.atan(y, x), p[3]
  end
  local r0, a0, z0 = cylindrical(from)
  local r1, a1, z1 = cylindrical(to)
  local da = (a1 - a0 + math.pi) % (2 * math.pi) - math.pi
  local dr, dz = r1 - r0, z1 - z0
  local length = math.sqrt(dr * dr + (r0 * da) ^ 2 + dz * dz)
  local s = length > step and step / length or 1
  local r, a = r0 + s * dr, a0 + s * da
  return {b[1] + r * math.cos(a), b[2] + r * math.sin(a), z0 + s * dz}
end

function sysCall_actuation()
  local blobs = sim.getVisionSensorBlobs(camera)
  if #blobs == 0 then return end  -- nothing blue in view: stay
  local puck = on_table(blobs[1].x, blobs[1].y)
  sim.recordMetric('puck_x', puck[1])
  sim.recordMetric('puck_y', puck[2])
  local goal = {puck[1], puck[2], puck[3] + HOVER}
  aim = toward(aim, goal, SPEED * sim.getTimeStep())
  sim.setObjectPose(target, {aim[1], aim[2], aim[3], orientation[1], orientation[2],
                             orientation[3], orientation[4]})
  local tool = sim.getObjectPosition(tip)
  sim.recordMetric('tool_error', math.sqrt((tool[1] - goal[1]) ^ 2 + (tool[2] - goal[2]) ^ 2 +
                                           (tool[3] - goal[3]) ^ 2))
end
