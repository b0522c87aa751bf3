-- A hop-count gradient over IR messages (worlds/ir_gradient.yaml), the
-- Kilobot's classic "gradient" example: the seed robot (parameter
-- seed_robot) has value 0; every other robot takes the least value it hears
-- plus one. Each robot that has a value tells it to its neighbours every
-- 0.5 s (16 steps of 1/32 s, kilolib's message rate), starting at a random
-- phase; a message that did not go out (the channel was busy: carrier
-- sense) is queued again at the next step. On a standing swarm every value
-- settles at the robot's number of hops from the seed. The LED shows the
-- value (0 red, 1 green, 2 blue, 3 red, ...; off while unknown) and each
-- change is printed ("hops 3").

local PERIOD = 16  -- steps between two messages of a robot (0.5 s at 1/32 s)
local COLORS = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}

local ir, led
local is_seed
local hops        -- hops from the seed; nil while unknown
local countdown   -- steps until the next message
local pending = false  -- a message was queued last step

local function show()
  if hops == nil then
    sim.setLedColor(led, {0, 0, 0})
  else
    sim.setLedColor(led, COLORS[hops % 3 + 1])
    print('hops ' .. hops)
  end
end

function sysCall_init()
  ir = sim.getObject('./ir')
  led = sim.getObject('./led')
  is_seed = sim.getRobotIndex() == sim.getParam('seed_robot', 0)
  if is_seed then hops = 0 end
  countdown = 1 + math.floor(sim.random() * PERIOD)
  show()
end

function sysCall_actuation()
  -- What arrived in this step's sense phase.
  for _, m in ipairs(sim.readIrMessages(ir)) do
    local heard = string.byte(m.data, 1) + 1
    if not is_seed and (hops == nil or heard < hops) then
      hops = heard
      show()
    end
  end
  -- Last step's message did not go out: try again now.
  if pending and not sim.getIrSent(ir) then countdown = 0 end
  pending = false
  countdown = countdown - 1
  if countdown <= 0 and hops ~= nil then
    sim.sendIrMessage(ir, string.char(math.min(hops, 255)))
    pending = true
    countdown = PERIOD
  end
end
