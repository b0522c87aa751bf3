#include "swarm/loader/yaml.h"

#include <yaml-cpp/depthguard.h>

#include <algorithm>
#include <cctype>
#include <memory>
#include <string>
#include <unordered_set>
#include <vector>

#include "framework/error.h"
#include "framework/regular_file.h"

namespace swarmsim::loader {

namespace fs = std::filesystem;

std::string ReadFileOrThrow(const fs::path& path, std::string_view kind, const std::string& where,
                            const std::string& text) {
  const std::string prefix = where.empty() ? "" : where + ": ";
  const std::string looked =
      DisplayPath(path) != text ? " (looked for " + DisplayPath(path) + ")" : "";
  std::error_code ec;
  if (!fs::exists(path, ec)) {
    // A loop of symbolic links "exists" no more than a missing file.
    if (ec == std::make_error_condition(std::errc::too_many_symbolic_link_levels))
      throw Error(prefix + std::string(kind) + " '" + text + "' is a loop of symbolic links" +
                  looked);
    // A file named by another: where it was looked for, in full, and how
    // (a world copied into a folder of its own lost the models beside it).
    std::string tried = looked;
    if (!where.empty() && !fs::path(text).is_absolute()) {
      std::error_code abs_error;
      const fs::path full = fs::absolute(path, abs_error).lexically_normal();
      tried = " (looked for " + (abs_error ? DisplayPath(path) : full.string()) +
              "; a path in a file is relative to that file's folder)";
    }
    throw Error(prefix + std::string(kind) + " '" + text + "' not found" + tried);
  }
  if (fs::is_directory(path, ec))
    throw Error(prefix + std::string(kind) + " '" + text + "' is a directory, not a file" + looked);
  // Not a device or a pipe (which could be read forever), and of a sane size.
  if (!fs::is_regular_file(path, ec))
    throw Error(prefix + std::string(kind) + " '" + text + "' is not a regular file" + looked);
  constexpr uintmax_t kMaxBytes = 64 << 20;
  if (const uintmax_t size = fs::file_size(path, ec); !ec && size > kMaxBytes)
    throw Error(prefix + std::string(kind) + " '" + text + "' is too large (" +
                std::to_string(size >> 20) + " MiB; the limit is 64 MiB)" + looked);
  // Opened as a regular file only (RegularFile): a FIFO put in its place
  // after the checks above is refused, not waited on.
  std::string why;
  const std::unique_ptr<RegularFile> file = RegularFile::Open(path, &why);
  const int64_t size = file ? file->CurrentSize() : -1;
  std::string bytes(size > 0 && static_cast<uintmax_t>(size) <= kMaxBytes ? size : 0, '\0');
  if (!file || size < 0 || static_cast<uintmax_t>(size) > kMaxBytes ||
      !file->ReadAt(0, bytes.data(), bytes.size(), &why))
    throw Error(prefix + "cannot read " + std::string(kind) + " '" + text + "'" + looked +
                (why.empty() ? "" : ": " + why));
  return bytes;
}

// Whether the indentation of line `line` (0-based) of `text` holds a tab,
// which YAML forbids and yaml-cpp reports in its own terms.
static bool TabInIndentation(std::string_view text, int line) {
  size_t start = 0;
  for (int i = 0; i < line; ++i) {
    start = text.find('\n', start);
    if (start == std::string_view::npos) return false;
    ++start;
  }
  for (size_t i = start; i < text.size() && (text[i] == ' ' || text[i] == '\t'); ++i)
    if (text[i] == '\t') return true;
  return false;
}

// A quoted scalar whose closing quote is missing ("robots: 'abc"): yaml-cpp
// reads the lines below into it, less indented ones too, which YAML
// forbids: the rest of the file became one string and the run went on
// without its arena and models. Fails at the quote when the scalar runs on
// into a line indented no deeper than the one it opened on. Each node once
// (an alias repeats its node's position: a billion-laughs file is walked
// in linear time).
static void CheckQuotes(const YamlFile& file, std::string_view text, const YAML::Node& node,
                        std::unordered_set<size_t>* seen) {
  if (!node.IsDefined() || node.IsNull()) return;
  const YAML::Mark mark = node.Mark();
  if (mark.is_null() || mark.pos < 0) return;
  const size_t pos = static_cast<size_t>(mark.pos);
  // (A collection may begin where its first element does: keyed by kind too.)
  if (!node.IsScalar() && !seen->insert(2 * pos + (node.IsMap() ? 1 : 0)).second) return;
  if (node.IsMap()) {
    for (const auto& kv : node) {
      CheckQuotes(file, text, kv.first, seen);
      CheckQuotes(file, text, kv.second, seen);
    }
    return;
  }
  if (node.IsSequence()) {
    for (const auto& item : node) CheckQuotes(file, text, item, seen);
    return;
  }
  if (pos >= text.size() || (text[pos] != '\'' && text[pos] != '"')) return;
  const char quote = text[pos];
  const size_t line_start =
      text.rfind('\n', pos) == std::string_view::npos ? 0 : text.rfind('\n', pos) + 1;
  size_t indent = 0;
  while (line_start + indent < pos && text[line_start + indent] == ' ') ++indent;
  for (size_t i = pos + 1; i < text.size(); ++i) {
    const char c = text[i];
    if (c == quote) {
      if (quote == '\'' && i + 1 < text.size() && text[i + 1] == '\'') {  // '' is a quote
        ++i;
        continue;
      }
      return;  // closed
    }
    if (quote == '"' && c == '\\') {
      ++i;
      continue;
    }
    if (c != '\n') continue;
    size_t j = i + 1, spaces = 0;
    while (j < text.size() && text[j] == ' ') ++j, ++spaces;
    if (j < text.size() && text[j] != '\n' && text[j] != '\r' && spaces <= indent) {
      const auto line =
          1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(j), '\n');
      const size_t end = text.find('\n', j);
      std::string next(text.substr(
          j, std::min<size_t>(end == std::string_view::npos ? text.size() - j : end - j, 40)));
      for (char& ch : next)
        if (static_cast<unsigned char>(ch) < 0x20) ch = '?';
      file.Fail(mark, std::string("the value quoted with ") + (quote == '"' ? "\"" : "'") +
                          " here runs on into line " + std::to_string(line) + " ('" + next +
                          "'), which is indented no deeper than its own: is its closing " + quote +
                          " missing?");
    }
  }
}

YamlFile YamlFile::Load(const fs::path& path, std::string_view kind,
                        const std::string& referenced_by, const std::string& reference_text) {
  YamlFile file;
  file.path_ = path;
  file.name_ = DisplayPath(path);
  const std::string text = ReadFileOrThrow(path, kind, referenced_by, reference_text);
  // A NUL byte: yaml-cpp reads it as the end of a line and reports something
  // else on the next one.
  if (const size_t nul = text.find('\0'); nul != std::string::npos) {
    YAML::Mark mark;
    const size_t newline = text.rfind('\n', nul);  // the one before it (text[nul] is none)
    mark.line = static_cast<int>(std::count(text.begin(), text.begin() + nul, '\n'));
    mark.column = static_cast<int>(newline == std::string::npos ? nul : nul - newline - 1);
    // A mesh named where a model file goes (`model: cube.stl`).
    std::string ext = path.extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    const bool mesh = ext == ".stl" || ext == ".obj" || ext == ".dae" || ext == ".ply";
    file.Fail(mark, "a NUL byte (\\0) in the file: a " + std::string(kind) + " is text" +
                        (mesh ? std::string(" (a mesh is a shape's: {type: shape, shape: mesh, "
                                            "mesh: ") +
                                    path.filename().string() + "}, in a model file's objects)"
                              : " (was it saved by a program that pads with zeros?)"));
  }
  try {
    // Every document: a second one (after ---) was never read, its keys
    // unchecked.
    std::vector<YAML::Node> documents = YAML::LoadAll(text);
    for (size_t d = 1; d < documents.size(); ++d)
      if (documents[d].IsDefined() && !documents[d].IsNull())
        file.Fail(documents[d].Mark(),
                  "a second YAML document (after ---): a " + std::string(kind) +
                      " is one document; join the two, or put this one in a file of its own");
    if (!documents.empty()) file.root_ = documents.front();
    std::unordered_set<size_t> seen;
    CheckQuotes(file, text, file.root_, &seen);
  } catch (const YAML::DeepRecursion& e) {
    // Its message is "bad file".
    file.Fail(e.mark,
              "YAML nested too deep here (lists or mappings within each other hundreds of "
              "levels down): more than yaml-cpp reads");
  } catch (const YAML::ParserException& e) {
    const std::string hint =
        TabInIndentation(text, e.mark.line) ? " (YAML does not allow tabs for indentation)" : "";
    file.Fail(e.mark, "YAML syntax error: " + e.msg + hint);
  } catch (const YAML::Exception& e) {
    file.Fail(e.mark, std::string("cannot read YAML: ") + e.what());
  }
  return file;
}

std::string YamlFile::Where(const YAML::Mark& mark) const {
  if (mark.is_null() || mark.line < 0 || mark.column < 0) return name_;
  return name_ + ":" + std::to_string(mark.line + 1) + ":" + std::to_string(mark.column + 1);
}

void YamlFile::Fail(const YAML::Mark& mark, const std::string& message) const {
  throw Error(Where(mark) + ": " + message);
}

std::string Describe(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "nothing";
  if (node.IsSequence()) return "a list";
  if (node.IsMap()) return "a mapping";
  std::string text = node.Scalar();
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  // Keep the message one printable line.
  for (char& c : text)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  return "\"" + text + "\"";
}

static YAML::Mark MarkOf(const YAML::Node& value, const YAML::Mark& fallback) {
  if (!value.IsDefined() || value.IsNull()) return fallback;
  const YAML::Mark m = value.Mark();
  return m.is_null() ? fallback : m;
}

Fields::Fields(const YamlFile& file, const Field& mapping, std::string what)
    : file_(file), what_(std::move(what)), mark_(mapping.mark) {
  if (!mapping.node.IsMap())
    file.Fail(mapping.mark,
              what_ + " must be a mapping of keys to values (got " + Describe(mapping.node) + ")");
  for (const auto& kv : mapping.node) {
    const YAML::Mark key_mark = kv.first.Mark();
    if (!kv.first.IsScalar() || kv.first.Scalar().empty())
      file.Fail(MarkOf(kv.first, mark_),
                "keys in " + what_ + " must be plain names (got " + Describe(kv.first) + ")");
    const std::string key = kv.first.Scalar();
    for (const Field& f : fields_)
      if (f.name == key)
        file.Fail(key_mark, "duplicate key '" + key + "' in " + what_ + " (first given at " +
                                file.Where(f.key_mark) + ")");
    fields_.push_back({key, kv.second, MarkOf(kv.second, key_mark), key_mark});
  }
}

Fields Fields::Single(const YamlFile& file, Field only, std::string what) {
  Fields fields(file, std::move(what), only.mark);
  fields.fields_.push_back(std::move(only));
  return fields;
}

void Fields::Expect(std::span<const std::string> known) const {
  for (const Field& f : fields_) {
    if (std::find(known.begin(), known.end(), f.name) != known.end()) continue;
    file_.Fail(f.key_mark, "unknown key '" + f.name + "' in " + what_ + Suggest(f.name, known));
  }
}

void Fields::Expect(std::initializer_list<std::string_view> known) const {
  std::vector<std::string> names(known.begin(), known.end());
  Expect(std::span<const std::string>(names));
}

bool Fields::Has(std::string_view key) const {
  for (const Field& f : fields_)
    if (f.name == key) return true;
  return false;
}

Field Fields::Get(std::string_view key) const {
  for (const Field& f : fields_)
    if (f.name == key) return f;
  return {std::string(key), YAML::Node(), mark_, mark_};
}

Field Fields::Require(std::string_view key) const {
  Field f = Get(key);
  if (!f.present()) file_.Fail(f.mark, "'" + std::string(key) + "' is required in " + what_);
  return f;
}

std::vector<std::string> Fields::keys() const {
  std::vector<std::string> out;
  for (const Field& f : fields_) out.push_back(f.name);
  return out;
}

std::vector<Field> ListElements(const YamlFile& file, const Field& list, std::string_view what) {
  std::vector<Field> out;
  if (!list.present()) return out;
  if (!list.node.IsSequence())
    file.Fail(list.mark, "'" + list.name + "' must be a list of " + std::string(what) + " (got " +
                             Describe(list.node) + ")");
  size_t i = 0;
  for (const YAML::Node& element : list.node) {
    out.push_back({list.name + "[" + std::to_string(i) + "]", element, MarkOf(element, list.mark),
                   MarkOf(element, list.mark)});
    ++i;
  }
  return out;
}

}  // namespace swarmsim::loader
