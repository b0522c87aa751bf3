#include "framework/csv.h"

namespace swarmsim {

std::string CsvField(std::string_view text) {
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
  std::string quoted = "\"";
  for (const char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  return quoted + '"';
}

void WriteCsvField(std::ostream& out, std::string_view text) {
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) {
    out << text;
    return;
  }
  out << '"';
  for (size_t at = 0;;) {
    const size_t quote = text.find('"', at);
    out << text.substr(at, quote == std::string_view::npos ? quote : quote + 1 - at);
    if (quote == std::string_view::npos) break;
    out << '"';  // doubled
    at = quote + 1;
  }
  out << '"';
}

bool ReadCsvRecord(std::istream& in, std::vector<std::string>* fields) {
  fields->assign(1, std::string());
  bool quoted = false;
  for (int c; (c = in.get()) != std::char_traits<char>::eof();) {
    if (quoted) {
      if (c != '"') {
        fields->back() += static_cast<char>(c);
      } else if (in.peek() == '"') {
        fields->back() += '"';
        in.get();
      } else {
        quoted = false;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields->emplace_back();
    } else if (c == '\n') {
      if (!fields->back().empty() && fields->back().back() == '\r') fields->back().pop_back();
      return true;
    } else {
      fields->back() += static_cast<char>(c);
    }
  }
  return false;  // no line break: torn, or nothing left
}

}  // namespace swarmsim
