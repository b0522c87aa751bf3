// A Lua file's text as the stand-alone `lua` reads it (luaL_loadfilex): a
// UTF-8 byte-order mark (some Windows editors write one) is dropped, and a
// first line starting with '#' (`#!/usr/bin/env lua`) is emptied, its
// newline kept so that messages give the file's own line numbers. Scripts
// and the modules `require` loads are read from a string, where Lua itself
// skips neither: "unexpected symbol near '<\239>'".
#pragma once

#include <string>

namespace swarmsim {

inline std::string LuaFileText(std::string text) {
  if (text.starts_with("\xEF\xBB\xBF")) text.erase(0, 3);
  if (text.starts_with('#'))
    text.erase(0, text.find('\n') == std::string::npos ? text.size() : text.find('\n'));
  return text;
}

}  // namespace swarmsim
