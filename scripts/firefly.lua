-- Firefly synchronisation (Mirollo & Strogatz 1990): each robot's phase
-- grows from 0 to 1 over `period` seconds; at 1 it flashes -- a range-limited
-- message -- and restarts. A flash seen advances the phase by `coupling`
-- times itself, so robots late in their cycle are pulled to flash together.
-- The phase is published as a signal for the main script's spread metric.

local period, coupling, flash_range, dt
local phase
local signal_name

function sysCall_init()
  period = sim.getParam('period', 1.0)
  coupling = sim.getParam('coupling', 0.2)
  flash_range = sim.getParam('flash_range', 1.0)
  dt = sim.getTimeStep()
  phase = sim.random()
  signal_name = 'phase_' .. sim.getRobotIndex()
end

function sysCall_actuation()
  -- Flashes seen (sent last step): each pulls the phase forward.
  local seen = 0
  while sim.receiveMessage() do seen = seen + 1 end
  -- A robot that has just flashed ignores flashes (refractory) so the
  -- group's flashes do not retrigger it.
  if phase > 0.1 then phase = phase * (1 + coupling) ^ seen end
  phase = phase + dt / period
  if phase >= 1 then
    sim.sendRangeMessage('', flash_range)
    phase = 0
  end
  sim.setSignal(signal_name, phase)
end
