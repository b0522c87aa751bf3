#include "swarm/cli/options.h"

#include <cctype>
#include <charconv>
#include <stdexcept>

#include "framework/error.h"
#include "framework/memory_forecast.h"

namespace swarmsim::cli {

CLI::Validator NumberCheck(bool allow_zero) {
  return CLI::Validator(
      [allow_zero](std::string& text) -> std::string {
        double value = 0;
        try {
          size_t used = 0;
          value = std::stod(text, &used);
          if (used != text.size()) throw std::invalid_argument(text);
        } catch (const std::exception&) {
          return "expected a number, got '" + text + "'";
        }
        if (allow_zero ? !(value >= 0) : !(value > 0))
          return std::string("must be ") + (allow_zero ? ">= 0" : "> 0") + ", got " + text;
        return "";
      },
      allow_zero ? "NUMBER >= 0" : "NUMBER > 0");
}

CLI::Validator WholeNumberCheck(int64_t min, int64_t max, const std::string& what) {
  const std::string range = std::to_string(min) + " to " + std::to_string(max);
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        int64_t value = 0;
        const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
        const bool whole =
            !text.empty() && end == text.data() + text.size() && ec != std::errc::invalid_argument;
        if (whole && ec == std::errc() && value >= min && value <= max) {
          text = std::to_string(value);
          return "";
        }
        if (what.empty()) return "expected a whole number from " + range + ", got '" + text + "'";
        if (!whole) return "expected a whole number of " + what + ", got '" + text + "'";
        if (text.starts_with('-') || (ec == std::errc() && value < min))
          return "must be >= " + std::to_string(min) + ", got " + text;
        return "must be at most " + std::to_string(max) + ", got " + text;
      },
      max < kIntMax ? std::to_string(min) + ".." + std::to_string(max)
                    : "NUMBER >= " + std::to_string(min));
}

CLI::Validator SeedCheck() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        uint64_t value = 0;
        const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
        if (text.empty() || !std::isdigit(static_cast<unsigned char>(text[0])) ||
            ec != std::errc() || end != text.data() + text.size())
          return "expected a whole number from 0 to 18446744073709551615 (2^64-1), got '" + text +
                 "'";
        text = std::to_string(value);
        return "";
      },
      "0..2^64-1");
}

CLI::Validator NonEmpty(const std::string& what) {
  return CLI::Validator(
      [what](std::string& text) -> std::string {
        return text.empty() ? "expected " + what + ", got an empty name" : "";
      },
      "");
}

CLI::Validator MemorySizeCheck() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        uint64_t bytes = 0;
        return ParseMemorySize(text, &bytes)
                   ? ""
                   : "expected a memory size such as 500M, 2G or 1.5GiB, got '" + text + "'";
      },
      "SIZE");
}

std::vector<std::filesystem::path> PluginDirectories() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return {};
  return {exe.parent_path() / "plugins", exe.parent_path().parent_path() / "lib/swarmsim/plugins"};
}

std::vector<std::pair<std::string, std::string>> ParseSets(const std::vector<std::string>& sets) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const std::string& s : sets) {
    const size_t eq = s.find('=');
    if (eq == std::string::npos || eq == 0)
      throw Error("--set expects name=value, got '" + s + "'");
    out.emplace_back(s.substr(0, eq), s.substr(eq + 1));
  }
  return out;
}

std::string CommandLine(int argc, char** argv) {
  std::string out;
  for (int i = 0; i < argc; ++i) out += (i ? " " : "") + std::string(argv[i]);
  return out;
}

}  // namespace swarmsim::cli
