#include "swarm/cli/parse_error.h"

#include <algorithm>
#include <filesystem>
#include <span>
#include <string_view>

#include "framework/suggest.h"

namespace swarmsim::cli {
namespace {

// `name`'s nearest among `candidates` when it is close enough to be a typo
// (the world loader's rule, framework/suggest.h), else "".
std::string Nearest(std::string_view name, std::span<const std::string> candidates) {
  const std::string* nearest = NearestName(name, candidates);
  return nearest != nullptr ? *nearest : std::string();
}

std::string Join(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& item : items) out += (out.empty() ? "" : ", ") + item;
  return out;
}

// "--stpes" -> "error: unknown option '--stpes' for 'run' (did you mean
// '--steps'?)", against the options `app` shows in its help.
std::string UnknownOption(const CLI::App& app, const std::string& arg) {
  const std::string given = arg.substr(0, arg.find('='));  // --stpes=5
  std::vector<std::string> names;                          // without the dashes
  for (const CLI::Option* option : app.get_options()) {
    if (option->get_group().empty()) continue;  // internal (bench --child)
    for (const std::string& name : option->get_lnames()) names.push_back(name);
  }
  const size_t dashes = std::min(given.find_first_not_of('-'), given.size());
  const std::string nearest = Nearest(given.substr(dashes), names);
  const bool top = app.get_parent() == nullptr;
  return "error: unknown option '" + given + "'" + (top ? "" : " for '" + app.get_name() + "'") +
         (nearest.empty() ? "" : " (did you mean '--" + nearest + "'?)") + "\nRun 'swarmsim " +
         (top ? "" : app.get_name() + " ") + "--help' for the options.\n";
}

}  // namespace

std::string SecondValueOfRepeatable(const std::vector<std::string>& args) {
  for (size_t i = 0; i < args.size(); ++i) {
    // --set a=1 b=2, or --set=a=1 b=2
    const std::string option = args[i].substr(0, args[i].find('='));
    if (option != "--set" && option != "--param") continue;
    const bool joined = option.size() < args[i].size();
    const size_t at = i + (joined ? 1 : 2);
    if (at >= args.size()) break;
    const std::string value = joined ? args[i].substr(option.size() + 1) : args[i + 1];
    const std::string& extra = args[at];
    std::error_code ec;
    if (extra.starts_with('-') || extra.find('=') == std::string::npos ||
        std::filesystem::exists(extra, ec))
      continue;
    const std::string form = option == "--set" ? "NAME=VALUE" : "NAME=SPEC";
    return "error: unexpected '" + extra + "' after " + option + " " + value + ": each " + option +
           " takes one " + form + "; repeat " + option + " for more: " + option + " " + value +
           " " + option + " " + extra + "\n";
  }
  return "";
}

std::string EmptyListEntry(const std::vector<std::string>& args) {
  const auto options_end = std::find(args.begin(), args.end(), "--");
  for (auto it = args.begin(); it != options_end; ++it) {
    const std::string option = it->substr(0, it->find('='));
    if (option != "--robots" && option != "--threads" && option != "--jobs" &&
        option != "--configs")
      continue;
    const bool joined = option.size() < it->size();
    if (!joined && std::next(it) == options_end) break;
    const std::string value = joined ? it->substr(option.size() + 1) : *std::next(it);
    if (value.empty() || value.starts_with(',') || value.ends_with(',') ||
        value.find(",,") != std::string::npos) {
      std::string cleaned;
      size_t start = 0;
      for (size_t comma; start <= value.size(); start = comma + 1) {
        comma = std::min(value.find(',', start), value.size());
        if (comma > start)
          cleaned += (cleaned.empty() ? "" : ",") + value.substr(start, comma - start);
      }
      return "error: " + option + " '" + value + "': an empty entry in the list" +
             (cleaned.empty() ? " (give one or more values, e.g. " + option + " 1000,10000)"
                              : " (did you mean " + option + " " + cleaned + "?)") +
             "\n";
    }
  }
  return "";
}

std::string ParseErrorMessage(CLI::App& app, const std::vector<std::string>& args,
                              const CLI::ParseError& error) {
  std::vector<std::string> commands;
  for (const CLI::App* command : app.get_subcommands([](CLI::App*) { return true; }))
    commands.push_back(command->get_name());
  const std::string command_list = "commands: " + Join(commands) + " (swarmsim --help)\n";
  const std::vector<CLI::App*> parsed = app.get_subcommands();
  CLI::App* command = parsed.empty() ? nullptr : parsed.front();

  // What no option took ("--" ends the options): first the program's own (an
  // unknown option, or an unknown command before any command), then the command's.
  std::vector<std::string> left_over;
  const auto options_end = std::find(args.begin(), args.end(), "--");
  const auto is_option = [&](const std::string& arg) {
    return arg.starts_with('-') && arg != "-" &&
           std::find(args.begin(), options_end, arg) != options_end;
  };
  const auto command_at = std::find(args.begin(), args.end(), command ? command->get_name() : "");
  for (const std::string& arg : app.remaining()) {
    if (arg == "--") continue;
    if (is_option(arg)) return UnknownOption(app, arg);
    if (command && std::find(command_at, args.end(), arg) != args.end()) {
      left_over.push_back(arg);  // after `run ... --`
      continue;
    }
    const std::string nearest = Nearest(arg, commands);
    return "error: unknown command '" + arg + "'" +
           (nearest.empty() ? "" : " (did you mean '" + nearest + "'?)") + "\n" + command_list;
  }
  if (!command) return "error: no command given\n" + command_list;
  for (const std::string& arg : command->remaining()) {
    if (arg == "--") continue;
    if (is_option(arg)) return UnknownOption(*command, arg);
    left_over.push_back(arg);
  }
  if (std::string message = SecondValueOfRepeatable(args); !message.empty()) return message;
  const std::string help = "Run 'swarmsim " + command->get_name() + " --help' for the options.\n";
  if (!left_over.empty())
    return "error: unexpected argument '" + left_over.front() + "' for '" + command->get_name() +
           "'\n" + help;
  return "error: " + PlainOptionError(error.what()) + "\n" + help;
}

std::string PlainOptionError(const std::string& what) {
  // CLI11's "--steps: At Most 1 required but received 2".
  const size_t colon = what.find(": ");
  if (colon == std::string::npos || !what.starts_with('-')) return what;
  const std::string option = what.substr(0, colon);
  const std::string_view rest = std::string_view(what).substr(colon + 2);
  constexpr std::string_view kAtMostOne = "At Most 1 required but received ";
  if (rest.starts_with(kAtMostOne))
    return option + " given " + std::string(rest.substr(kAtMostOne.size())) +
           " times; it takes one value (give it once)";
  // "--steps: 1 required INT:NUMBER >= 0 missing" (the option ended the line).
  constexpr std::string_view kOneRequired = "1 required ";
  constexpr std::string_view kMissing = " missing";
  if (rest.starts_with(kOneRequired) && rest.ends_with(kMissing)) {
    const std::string_view type =
        rest.substr(kOneRequired.size(), rest.size() - kOneRequired.size() - kMissing.size());
    return option + " needs a value (" + std::string(type) + ")";
  }
  return what;
}

}  // namespace swarmsim::cli
