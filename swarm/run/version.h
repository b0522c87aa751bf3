#pragma once
namespace swarmsim {
// The program's version, e.g. "0.1.0".
const char* Version();
}  // namespace swarmsim
