-- A robot whose sysCall_init takes a while (about 2 ms): a world of
-- thousands of them takes seconds to start.
function sysCall_init()
  local sum = 0
  for i = 1, 200000 do sum = sum + i end
  assert(sum > 0)
end
