-- Recursion through a C function (string.gsub calling this Lua function,
-- which calls gsub again): Lua stops it after 200 C levels with "C stack
-- overflow", an error of the script's.
function sysCall_init()
  local function again(s) return (s:gsub(".", again)) end
  again("abc")
end
