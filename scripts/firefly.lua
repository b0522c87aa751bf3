-- Firefly synchronisation, a pulse-coupled oscillator (Mirollo & Strogatz
-- 1990): each robot's phase grows from 0 to 1 over `period` seconds; at 1 it
-- flashes -- a range-limited message -- and restarts at 0.
-- A flash is seen one step after it is sent, when the flasher has just
-- restarted, so a robot's phase then tells where it stands:
-- * in the second half of its cycle it is behind the flasher, and each
--   flash seen advances its phase by `coupling` times itself (robots late in
--   their cycle are pulled most); in the first half it is ahead of the
--   flasher (or has just flashed with it) and ignores the flash;
-- * a robot that reaches 1 in a step where it saw a flash (pushed there by
--   it) flashes too, passing the flash on, but a step after the flasher, so
--   it restarts where the flasher is now, at dt/period, not at 0. (With 0,
--   each robot a flash wave reaches stays a step behind the one it saw,
--   cycle after cycle, and the spread stalls at 0.1-0.4.)
-- The phase is published as a signal for the main script's spread metric.

local period, coupling, flash_range, dt
local phase
local signal_name

function sysCall_init()
  period = sim.getParam('period', 1.0)
  coupling = sim.getParam('coupling', 0.2)
  flash_range = sim.getParam('flash_range', 1.5)
  dt = sim.getTimeStep()
  phase = sim.random()
  signal_name = 'phase_' .. sim.getRobotIndex()
  sim.setSignal(signal_name, phase)  -- the main script's sample at step 0
end

function sysCall_actuation()
  -- Flashes seen (sent last step).
  local seen = 0
  while sim.receiveMessage() do seen = seen + 1 end
  if phase > 0.5 then phase = phase * (1 + coupling) ^ seen end
  phase = phase + dt / period
  if phase >= 1 then
    sim.sendRangeMessage('', flash_range)
    if seen > 0 then phase = dt / period else phase = 0 end
  end
  sim.setSignal(signal_name, phase)
end
