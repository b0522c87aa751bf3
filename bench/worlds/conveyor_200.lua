-- Main script of bench/worlds/conveyor_200.yaml: the default step; on the
-- first one, 199 copies of the crate, so that four rows of 50 crates, 16 cm
-- apart, lie on the belt's two straights (y = -1.5 +- 0.1, -1.5 +- 0.3
-- and the same at y = 1.5).

local placed = false

function sysCall_step()
  sim.handleSensing()
  sim.handleChildScripts()
  sim.handleActuation()
  sim.handleDynamics()
  if not placed then
    local crate = sim.getObject('/crate#0')
    local first = true
    for _, y in ipairs({-1.8, -1.6, -1.4, -1.2, 1.2, 1.4, 1.6, 1.8}) do
      for k = 0, 24 do
        if first then
          first = false  -- the crate itself
        else
          sim.copyModel(crate, {-3.92 + 0.32 * k + (y > 0 and 0.16 or 0), y, 0})
        end
      end
    end
    placed = true
  end
end
