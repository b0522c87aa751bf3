// The viewer page, embedded into the program at build time (CMakeLists.txt):
// index.html and the bundled script (the page's modules, three.js, fzstd).
#pragma once

#include <string_view>

namespace swarmsim::viewer {

// web/index.html: the page; its <!--SWARMSIM_SCRIPTS--> line is where the
// server puts <script src="viewer.js"> and an export the inline scripts.
std::string_view PageHtml();
// The bundled, minified script (an IIFE; no imports left).
std::string_view PageScript();

}  // namespace swarmsim::viewer
