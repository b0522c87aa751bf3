-- Seed: errors of every shape, in callbacks and in the main chunk.
local t = setmetatable({}, {__tostring = function(self) return tostring(self) end,
                            __index = function(_, k) error(k) end})
function sysCall_init()
  print(pcall(error))
  print(pcall(error, {}))
  print(pcall(error, nil))
  print(pcall(math.max, nil, 1))
  print(pcall(print, t))
  print(pcall(function() return t.x end))
  print(pcall(string.rep, 'x', -1))
  print(select('#', pcall(coroutine.yield)))
end
function sysCall_actuation()
  error(('e'):rep(100))
end
