// The page's files as bytes inside the program (.incbin: no generated source,
// no compile cost; CMakeLists.txt gives the paths and makes this object
// depend on the files).
#include "swarm/viewer/assets.h"

#include <cstddef>

#define SWARMSIM_INCBIN(name, file)                                       \
  __asm__(".section .rodata\n.global " #name "_begin\n.balign 16\n" #name \
          "_begin:\n"                                                     \
          ".incbin \"" file "\"\n.global " #name "_end\n" #name "_end:\n.byte 0\n.previous\n")

SWARMSIM_INCBIN(swarmsim_viewer_html, SWARMSIM_VIEWER_HTML);
SWARMSIM_INCBIN(swarmsim_viewer_script, SWARMSIM_VIEWER_BUNDLE);

extern "C" const char swarmsim_viewer_html_begin[], swarmsim_viewer_html_end[];
extern "C" const char swarmsim_viewer_script_begin[], swarmsim_viewer_script_end[];

namespace swarmsim::viewer {

std::string_view PageHtml() {
  return {swarmsim_viewer_html_begin,
          static_cast<size_t>(swarmsim_viewer_html_end - swarmsim_viewer_html_begin)};
}

std::string_view PageScript() {
  return {swarmsim_viewer_script_begin,
          static_cast<size_t>(swarmsim_viewer_script_end - swarmsim_viewer_script_begin)};
}

}  // namespace swarmsim::viewer
