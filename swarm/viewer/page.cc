// The page served and the page exported: index.html with its script tags.
#include "swarm/viewer/page.h"

#include <cctype>
#include <fstream>

#include "framework/error.h"
#include "framework/output_file.h"
#include "swarm/viewer/assets.h"

namespace swarmsim::viewer {
namespace {

constexpr std::string_view kScriptsMark = "<!--SWARMSIM_SCRIPTS-->";

// The page's options as a script that runs before the page's own.
std::string OptionsScript(const PageOptions& options) {
  if (options.mesh_budget < 0) return "";
  return "<script>window.swarmsimMeshBudget = " + std::to_string(options.mesh_budget) +
         ";</script>\n";
}

std::string WithScripts(std::string_view scripts) {
  std::string html(PageHtml());
  const size_t mark = html.find(kScriptsMark);
  if (mark == std::string::npos)
    throw InternalError("viewer page: no " + std::string(kScriptsMark));
  html.replace(mark, kScriptsMark.size(), scripts);
  return html;
}

std::string Base64(std::string_view bytes) {
  static constexpr char kDigits[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v = uint32_t(uint8_t(bytes[i])) << 16 | uint32_t(uint8_t(bytes[i + 1])) << 8 |
                       uint8_t(bytes[i + 2]);
    out += kDigits[v >> 18];
    out += kDigits[(v >> 12) & 63];
    out += kDigits[(v >> 6) & 63];
    out += kDigits[v & 63];
  }
  if (i < bytes.size()) {
    const bool two = i + 1 < bytes.size();
    const uint32_t v =
        uint32_t(uint8_t(bytes[i])) << 16 | (two ? uint32_t(uint8_t(bytes[i + 1])) << 8 : 0);
    out += kDigits[v >> 18];
    out += kDigits[(v >> 12) & 63];
    out += two ? kDigits[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

// A script's text made safe inside <script>...</script>: no "</script"
// (only in strings or regular expressions, where "<\/" means the same).
std::string InlineScript(std::string_view script) {
  std::string out(script);
  for (size_t at = out.find("</"); at != std::string::npos; at = out.find("</", at + 1)) {
    std::string word = out.substr(at + 2, 6);
    for (char& c : word) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (word == "script") out.replace(at, 2, "<\\/");
  }
  return out;
}

}  // namespace

std::string ServedPage(const PageOptions& options) {
  return WithScripts(OptionsScript(options) + "<script src=\"viewer.js\"></script>");
}

std::string ExportedPage(std::string_view recording, const PageOptions& options) {
  return WithScripts(OptionsScript(options) +
                     "<script id=\"swarmsim-recording\" type=\"application/octet-stream\">" +
                     Base64(recording) + "</script>\n<script>" + InlineScript(PageScript()) +
                     "</script>");
}

void ExportFolder(const std::filesystem::path& folder, uint64_t size,
                  const std::filesystem::path& html_file, const PageOptions& options) {
  const std::filesystem::path recording_file = folder / kRecordingFile;
  std::ifstream in(recording_file, std::ios::binary);
  std::string bytes(size, '\0');
  if (!in.read(bytes.data(), static_cast<std::streamsize>(size)))
    throw Error("cannot read '" + recording_file.string() + "'");
  WriteFileAtomically(html_file, ExportedPage(bytes, options));  // whole or not at all
}

}  // namespace swarmsim::viewer
