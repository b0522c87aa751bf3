// What CLI11 rejects, said in this program's words: the nearest known option
// or command for a typo, and the repeat-the-option hint for `--set a=1 b=2`.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace swarmsim::cli {

// `--set a=1 b=2`: each --set (sweep --param) takes one value, so b=2 was left
// over or taken for the world file. Returns the message, or "" when `args`
// (argv without the program) have no such value; an existing file is a world.
std::string SecondValueOfRepeatable(const std::vector<std::string>& args);

// `bench --robots 1000,,2` (or `1000,`, `,2`): a comma list with an empty
// entry, which CLI11 would drop without a word. Returns the message naming
// the option and the list, or "" when no list option (--robots, --threads,
// --jobs, --configs) of `args` has one.
std::string EmptyListEntry(const std::vector<std::string>& args);

// What CLI11 rejected, in this program's words: an unknown option or command
// with the nearest known one, a second value after --set, else CLI11's own
// message (PlainOptionError). `args` is argv without the program.
std::string ParseErrorMessage(CLI::App& app, const std::vector<std::string>& args,
                              const CLI::ParseError& error);

// CLI11's message about one option, in plain words where it has a known
// form: "--steps: At Most 1 required but received 2" -> "--steps given 2
// times; it takes one value (give it once)"; "--steps: 1 required
// INT:NUMBER >= 0 missing" -> "--steps needs a value (INT:NUMBER >= 0)".
// Any other message as it is.
std::string PlainOptionError(const std::string& what);

}  // namespace swarmsim::cli
