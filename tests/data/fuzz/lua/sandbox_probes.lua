-- Seed: what the sandbox allows, and its limits, each under pcall.
local probes = {
  function() return io.open('fuzz.lua'):read('a') end,
  function() return require('os') end,
  function() return string.dump(print) end,
  function() return debug and debug.getinfo(1) end,
  function() return loadfile('fuzz.lua') end,
  function() return collectgarbage('count') end,
  function() return setmetatable({}, {__gc = function() end}) end,
  function() return ('x'):rep(100):find('.-.-b') end,
  function() local t = {} for i = 1, 1e4 do t[i] = i end return #t end,
  function() return coroutine.wrap(function() coroutine.yield(1) end)() end,
  function() return string.format('%q %5.2f %s', 'a\0b', 1 / 0, {}) end,
  function() return utf8.char(0x10FFFF, 0) end,
  function() return math.tointeger(2 ^ 63), math.random(0) end,
}
function sysCall_init()
  for i, probe in ipairs(probes) do
    local ok, err = pcall(probe)
    print(i, ok, err)
  end
end
function sysCall_actuation()
  sim.recordMetric('t', sim.getSimulationTime())
end
